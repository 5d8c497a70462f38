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
  std::int32_t* owner;  // index of the prepared quad seen at the pixel, -1 for none
};

// A linear function of the pixel coordinates: for a vector a and the ray d through pixel
// (px, py), a . d = x px + y py + c.
struct LinearForm {
  double x = 0.0, y = 0.0, c = 0.0;
  double row(int y_pixel) const { return y * y_pixel + c; }
};

struct QuadForms {
  LinearForm iz, ud, vd;  // inverse depth n.d / h; u.d; v.d
  double uo = 0.0, vo = 0.0;
};

QuadForms quad_forms(const PreparedQuad& p, const ViewCamera& cam) {
  // Ray through pixel (x, y): d = ((x - cx)/fx, (y - cy)/fy, 1).
  auto linear = [&](const Vec3& a, double scale) {
    LinearForm f;
    f.x = scale * a.x() / cam.fx;
    f.y = scale * a.y() / cam.fy;
    f.c = scale * (a.z() - a.x() * cam.cx / cam.fx - a.y() * cam.cy / cam.fy);
    return f;
  };
  QuadForms q;
  q.iz = linear(p.n, 1.0 / p.h);
  q.ud = linear(p.u, 1.0);
  q.vd = linear(p.v, 1.0);
  q.uo = p.u.dot(p.o);
  q.vo = p.v.dot(p.o);
  return q;
}

// Visits the pixel spans [x0, x1] of row y the polygon covers.
template <typename SpanFn>
void for_each_span(const PreparedQuad& p, const ViewCamera& cam, SpanFn&& span) {
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
    if (x0 <= x1) span(y, x0, x1);
  }
}

// Visibility pass: the z-buffer and, per pixel, which quad wins. Only the winner is textured
// afterwards, so hidden surfaces cost a depth comparison and no texture read.
void rasterise_depth(const PreparedQuad& p, const QuadForms& f, std::int32_t index,
                     const ViewCamera& cam, Buffers& buf) {
  for_each_span(p, cam, [&](int y, int x0, int x1) {
    const double iz_row = f.iz.row(y);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width);
    float* inv_depth = buf.inv_depth + row;
    std::int32_t* owner = buf.owner + row;
    for (int x = x0; x <= x1; ++x) {
      const double inv_z = iz_row + f.iz.x * x;
      if (inv_z <= 0.0 || inv_z <= inv_depth[x]) continue;
      inv_depth[x] = static_cast<float>(inv_z);
      owner[x] = index;
    }
  });
}

// Textures the pixels [x0, x1] of row y, all seen on quad p. The texel coordinates are
// projective maps of x: s(x) = (s_0 + s_x x) / (iz_0 + iz_x x), the same for t. The pixel
// footprint d(s, t)/d(x, y), times z^2, has numerators that are constant along the row for d/dx
// and linear in x for d/dy.
void shade_run(const PreparedQuad& p, const QuadForms& f, const World& world, int y, int x0, int x1,
               const ViewCamera& cam, Buffers& buf) {
  const Quad& q = *p.quad;
  const Texture& tex = world.textures[static_cast<std::size_t>(q.texture)];
  const double su = q.texels_per_metre_u, sv = q.texels_per_metre_v;
  const double off_u = q.texel_offset_u, off_v = q.texel_offset_v;
  const float gain = p.brightness * (1.0f / 255.0f);
  const double iz_0 = f.iz.row(y), iz_x = f.iz.x;
  const double ud_0 = f.ud.row(y), vd_0 = f.vd.row(y);
  // s = (ud z - uo) su + off = (su (ud - uo iz) + off iz) z
  const double sn_0 = su * (ud_0 - f.uo * iz_0) + off_u * iz_0;
  const double sn_x = su * (f.ud.x - f.uo * iz_x) + off_u * iz_x;
  const double tn_0 = sv * (vd_0 - f.vo * iz_0) + off_v * iz_0;
  const double tn_x = sv * (f.vd.x - f.vo * iz_x) + off_v * iz_x;
  const double fsx = (f.ud.x * iz_0 - ud_0 * iz_x) * su;
  const double ftx = (f.vd.x * iz_0 - vd_0 * iz_x) * sv;
  const double fsy_0 = (f.ud.y * iz_0 - ud_0 * f.iz.y) * su;
  const double fsy_x = (f.ud.y * iz_x - f.ud.x * f.iz.y) * su;
  const double fty_0 = (f.vd.y * iz_0 - vd_0 * f.iz.y) * sv;
  const double fty_x = (f.vd.y * iz_x - f.vd.x * f.iz.y) * sv;
  const double foot_x = fsx * fsx + ftx * ftx;
  const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width);
  float* radiance = buf.radiance + row;
  std::uint8_t* labels = buf.label + row;
  for (int x = x0; x <= x1; ++x) {
    const double z = 1.0 / (iz_0 + iz_x * x);
    const double s = (sn_0 + sn_x * x) * z, t = (tn_0 + tn_x * x) * z;
    const double fsy = fsy_0 + fsy_x * x, fty = fty_0 + fty_x * x;
    const double z2 = z * z;
    const double rho2 = std::max(foot_x, fsy * fsy + fty * fty) * (z2 * z2);
    const float lod = 0.5f * fast_log2(static_cast<float>(rho2) + 1e-20f);
    radiance[x] = tex.sample(s, t, lod) * gain;
    labels[x] = q.label;
  }
}

// Shading pass: each covered pixel is textured once, by runs of pixels that see the same quad.
void shade_visible(const std::vector<PreparedQuad>& prepared, const std::vector<QuadForms>& forms,
                   const World& world, const ViewCamera& cam, Buffers& buf) {
  for (int y = 0; y < cam.height; ++y) {
    const std::int32_t* owner =
        buf.owner + static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width);
    int x = 0;
    while (x < cam.width) {
      const std::int32_t k = owner[x];
      int end = x + 1;
      while (end < cam.width && owner[end] == k) ++end;
      if (k >= 0) {
        const auto i = static_cast<std::size_t>(k);
        shade_run(prepared[i], forms[i], world, y, x, end - 1, cam, buf);
      }
      x = end;
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
  cv::Mat owner(size, CV_32S, cv::Scalar(-1));
  Buffers buf{layers.radiance.ptr<float>(), inv_depth.ptr<float>(),
              layers.label.ptr<std::uint8_t>(), owner.ptr<std::int32_t>()};

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
  std::vector<QuadForms> forms;
  forms.reserve(prepared.size());
  for (const PreparedQuad& pq : prepared) forms.push_back(quad_forms(pq, cam));
  for (std::size_t k = 0; k < prepared.size(); ++k)
    rasterise_depth(prepared[k], forms[k], static_cast<std::int32_t>(k), cam, buf);
  shade_visible(prepared, forms, world, cam, buf);
  fill_background(world, cam, T_world_camera, buf);

  layers.depth.create(size, CV_32F);
  const float* src = inv_depth.ptr<float>();
  float* dst = layers.depth.ptr<float>();
  for (std::size_t i = 0; i < static_cast<std::size_t>(size.area()); ++i)
    dst[i] = src[i] > 0.0f ? 1.0f / src[i] : 0.0f;
}

}  // namespace sbaslam::sim
