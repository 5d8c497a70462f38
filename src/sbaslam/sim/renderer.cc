#include "sbaslam/sim/renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sbaslam::sim {

ViewCamera ViewCamera::scaled(double factor) const {
  ViewCamera c;
  // Pixel centres sit at integer coordinates, so the principal point scales about -0.5.
  c.fx = fx * factor;
  c.fy = fy * factor;
  c.cx = (cx + 0.5) * factor - 0.5;
  c.cy = (cy + 0.5) * factor - 0.5;
  c.width = static_cast<int>(std::lround(width * factor));
  c.height = static_cast<int>(std::lround(height * factor));
  return c;
}

namespace {

constexpr int kMaxVertices = 8;

// A quad ready for rasterisation: camera-frame geometry and its clipped image polygon.
struct PreparedQuad {
  const Quad* quad = nullptr;
  Vec3 o, u, v, n;  // camera frame
  double h = 0.0;   // plane offset: n . X = h
  float brightness = 1.0f;
  std::array<Vec2, kMaxVertices> polygon;
  int vertex_count = 0;
  double min_z = 0.0;
};

// Sutherland-Hodgman clipping of a convex polygon against z >= near.
int clip_near(const std::array<Vec3, 4>& in, std::array<Vec3, kMaxVertices>& out) {
  int count = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec3& a = in[static_cast<std::size_t>(i)];
    const Vec3& b = in[static_cast<std::size_t>((i + 1) % 4)];
    const bool a_in = a.z() >= kNearPlane, b_in = b.z() >= kNearPlane;
    if (a_in) out[static_cast<std::size_t>(count++)] = a;
    if (a_in != b_in) {
      const double t = (kNearPlane - a.z()) / (b.z() - a.z());
      out[static_cast<std::size_t>(count++)] = a + t * (b - a);
    }
  }
  return count;
}

bool prepare(const Quad& quad, const SE3& T_cw, float brightness, const ViewCamera& cam,
             PreparedQuad& p) {
  p.quad = &quad;
  p.o = T_cw * quad.origin;
  p.u = T_cw.so3() * quad.axis_u;
  p.v = T_cw.so3() * quad.axis_v;
  p.n = p.v.cross(p.u);  // front normal
  p.h = p.n.dot(p.o);
  // The camera (origin) must be in front of the face: n . (0 - o) > 0, i.e. h < 0.
  if (std::abs(p.h) < 1e-9 || (!quad.two_sided && p.h >= 0.0)) return false;
  const Vec3 du = p.u * quad.size_u, dv = p.v * quad.size_v;
  const std::array<Vec3, 4> corners = {p.o, p.o + du, p.o + du + dv, p.o + dv};
  if (corners[0].z() < kNearPlane && corners[1].z() < kNearPlane && corners[2].z() < kNearPlane &&
      corners[3].z() < kNearPlane)
    return false;
  std::array<Vec3, kMaxVertices> clipped;
  p.vertex_count = clip_near(corners, clipped);
  if (p.vertex_count < 3) return false;
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  p.min_z = 1e300;
  for (int i = 0; i < p.vertex_count; ++i) {
    const Vec3& c = clipped[static_cast<std::size_t>(i)];
    const Vec2 px(cam.fx * c.x() / c.z() + cam.cx, cam.fy * c.y() / c.z() + cam.cy);
    p.polygon[static_cast<std::size_t>(i)] = px;
    xmin = std::min(xmin, px.x());
    xmax = std::max(xmax, px.x());
    ymin = std::min(ymin, px.y());
    ymax = std::max(ymax, px.y());
    p.min_z = std::min(p.min_z, c.z());
  }
  if (xmax < 0.0 || ymax < 0.0 || xmin > cam.width - 1 || ymin > cam.height - 1) return false;
  p.brightness = brightness;
  return true;
}

// Horizontal extent of a convex polygon on the scanline y; false when it misses the line.
bool scanline_span(const PreparedQuad& p, double y, double& x_left, double& x_right) {
  x_left = 1e300;
  x_right = -1e300;
  for (int i = 0; i < p.vertex_count; ++i) {
    const Vec2& a = p.polygon[static_cast<std::size_t>(i)];
    const Vec2& b = p.polygon[static_cast<std::size_t>((i + 1) % p.vertex_count)];
    if ((y < a.y() && y < b.y()) || (y > a.y() && y > b.y())) continue;
    double x;
    if (a.y() == b.y()) {
      x_left = std::min({x_left, a.x(), b.x()});
      x_right = std::max({x_right, a.x(), b.x()});
      continue;
    }
    x = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    x_left = std::min(x_left, x);
    x_right = std::max(x_right, x);
  }
  return x_left <= x_right;
}

struct Buffers {
  float* radiance;
  float* inv_depth;
  std::uint8_t* label;
};

void rasterise(const PreparedQuad& p, const World& world, const ViewCamera& cam, Buffers& buf) {
  const Quad& q = *p.quad;
  const Texture& tex = world.textures[static_cast<std::size_t>(q.texture)];
  // Ray through pixel (x, y): d = ((x - cx)/fx, (y - cy)/fy, 1). For a vector a, a . d is
  // a_x' x + a_y' y + a_0 with the coefficients below.
  auto linear = [&](const Vec3& a, double scale, double& ax, double& ay, double& a0) {
    ax = scale * a.x() / cam.fx;
    ay = scale * a.y() / cam.fy;
    a0 = scale * (a.z() - a.x() * cam.cx / cam.fx - a.y() * cam.cy / cam.fy);
  };
  double iz_x, iz_y, iz_0, ud_x, ud_y, ud_0, vd_x, vd_y, vd_0;
  linear(p.n, 1.0 / p.h, iz_x, iz_y, iz_0);  // inverse depth = n.d / h
  linear(p.u, 1.0, ud_x, ud_y, ud_0);
  linear(p.v, 1.0, vd_x, vd_y, vd_0);
  const double uo = p.u.dot(p.o), vo = p.v.dot(p.o);
  const double su = q.texels_per_metre_u, sv = q.texels_per_metre_v;
  const float gain = p.brightness * (1.0f / 255.0f);

  double ymin = 1e300, ymax = -1e300;
  for (int i = 0; i < p.vertex_count; ++i) {
    ymin = std::min(ymin, p.polygon[static_cast<std::size_t>(i)].y());
    ymax = std::max(ymax, p.polygon[static_cast<std::size_t>(i)].y());
  }
  const int y0 = std::max(0, static_cast<int>(std::ceil(ymin)));
  const int y1 = std::min(cam.height - 1, static_cast<int>(std::floor(ymax)));
  for (int y = y0; y <= y1; ++y) {
    double xl, xr;
    if (!scanline_span(p, y, xl, xr)) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(xl - 1e-7)));
    const int x1 = std::min(cam.width - 1, static_cast<int>(std::floor(xr + 1e-7)));
    const double iz_row = iz_y * y + iz_0, ud_row = ud_y * y + ud_0, vd_row = vd_y * y + vd_0;
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width);
    for (int x = x0; x <= x1; ++x) {
      const double inv_z = iz_row + iz_x * x;
      const std::size_t i = row + static_cast<std::size_t>(x);
      if (inv_z <= 0.0 || inv_z <= buf.inv_depth[i]) continue;
      const double ud = ud_row + ud_x * x, vd = vd_row + vd_x * x;
      const double z = 1.0 / inv_z;
      const double s = ud * z - uo, t = vd * z - vo;
      // Footprint of the pixel on the texture, from the derivatives of s and t.
      const double z2 = z * z;
      const double sx = (ud_x * inv_z - ud * iz_x) * z2 * su;
      const double tx = (vd_x * inv_z - vd * iz_x) * z2 * sv;
      const double sy = (ud_y * inv_z - ud * iz_y) * z2 * su;
      const double ty = (vd_y * inv_z - vd * iz_y) * z2 * sv;
      const double rho2 = std::max(sx * sx + tx * tx, sy * sy + ty * ty);
      const float lod = 0.5f * fast_log2(static_cast<float>(rho2) + 1e-20f);
      const float texel = tex.sample(s * su + q.texel_offset_u, t * sv + q.texel_offset_v, lod);
      buf.inv_depth[i] = static_cast<float>(inv_z);
      buf.radiance[i] = texel * gain;
      buf.label[i] = q.label;
    }
  }
}

void fill_background(const World& world, const ViewCamera& cam, const SE3& T_wc, Buffers& buf) {
  const Lighting& L = world.lighting;
  const Mat3 R = T_wc.rotation();
  for (int y = 0; y < cam.height; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width);
    for (int x = 0; x < cam.width; ++x) {
      const std::size_t i = row + static_cast<std::size_t>(x);
      if (buf.inv_depth[i] > 0.0f) continue;
      float value = 0.0f;
      if (L.sky) {
        const Vec3 d = R * Vec3((x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1.0);
        const double elevation = std::clamp(d.z() / d.norm(), 0.0, 1.0);
        value = static_cast<float>(L.sky_horizon + (L.sky_zenith - L.sky_horizon) * elevation);
      }
      buf.radiance[i] = value;
      buf.label[i] = label::kSky;
    }
  }
}

}  // namespace

void render_view(const World& world, const ViewCamera& cam, const SE3& T_world_camera, double time,
                 ViewLayers& layers) {
  const cv::Size size(cam.width, cam.height);
  layers.radiance.create(size, CV_32F);
  layers.label.create(size, CV_8U);
  cv::Mat inv_depth(size, CV_32F, cv::Scalar(0.0f));
  Buffers buf{layers.radiance.ptr<float>(), inv_depth.ptr<float>(),
              layers.label.ptr<std::uint8_t>()};

  const SE3 T_cw = T_world_camera.inverse();
  std::vector<PreparedQuad> prepared;
  prepared.reserve(world.quads.size() / 4 + 64);
  PreparedQuad p;
  for (const Quad& q : world.quads)
    if (prepare(q, T_cw, world.shade(q, q.front_normal()), cam, p)) prepared.push_back(p);
  for (const MovingObject& obj : world.objects) {
    const SE3 T_wo = obj.pose_at(time);
    const SE3 T_co = T_cw * T_wo;
    for (const Quad& q : obj.quads)
      if (prepare(q, T_co, world.shade(q, T_wo.so3() * q.front_normal()), cam, p))
        prepared.push_back(p);
  }
  // Nearest first, background last; ties keep the world's order so that the result never
  // depends on the sort.
  std::stable_sort(prepared.begin(), prepared.end(),
                   [](const PreparedQuad& a, const PreparedQuad& b) {
                     if (a.quad->background != b.quad->background) return b.quad->background;
                     return a.min_z < b.min_z;
                   });
  for (const PreparedQuad& pq : prepared) rasterise(pq, world, cam, buf);
  fill_background(world, cam, T_world_camera, buf);

  layers.depth.create(size, CV_32F);
  const float* src = inv_depth.ptr<float>();
  float* dst = layers.depth.ptr<float>();
  for (std::size_t i = 0; i < static_cast<std::size_t>(size.area()); ++i)
    dst[i] = src[i] > 0.0f ? 1.0f / src[i] : 0.0f;
}

}  // namespace sbaslam::sim
