#include "sbaslam/sim/world.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::sim {

int World::add_texture(const cv::Mat& image, TextureWrap wrap) {
  textures.emplace_back(image, wrap);
  return static_cast<int>(textures.size()) - 1;
}

float World::shade(const Quad& quad, const Vec3& normal_world) const {
  const double lambert = std::max(0.0, normal_world.dot(lighting.sun_direction));
  return quad.albedo * static_cast<float>(lighting.ambient + lighting.diffuse * lambert);
}

Quad make_quad(const Vec3& origin, const Vec3& u_vec, const Vec3& v_vec, int texture,
               std::uint8_t label, const FaceSkin& skin, const World& world, float albedo) {
  Quad q;
  q.origin = origin;
  q.size_u = u_vec.norm();
  q.size_v = v_vec.norm();
  q.axis_u = u_vec / q.size_u;
  q.axis_v = v_vec / q.size_v;
  q.texture = texture;
  q.label = label;
  q.albedo = albedo;
  if (skin.fit) {
    const Texture& tex = world.textures.at(static_cast<std::size_t>(texture));
    q.texels_per_metre_u = tex.width() / q.size_u;
    q.texels_per_metre_v = tex.height() / q.size_v;
  } else {
    q.texels_per_metre_u = q.texels_per_metre_v = skin.texels_per_metre;
    q.texel_offset_u = skin.offset_u;
    q.texel_offset_v = skin.offset_v;
  }
  return q;
}

void add_box(std::vector<Quad>& out, const World& world, const SE3& T_frame_box, const Vec3& size,
             const BoxSkin& skin) {
  const double hx = 0.5 * size.x(), hy = 0.5 * size.y(), h = size.z();
  // Vertical faces: v points down, u = n x v so that the face reads correctly from outside.
  struct Face {
    const FaceSkin* skin;
    Vec3 normal;
    double half_width;
    double distance;
  };
  const Face faces[] = {{&skin.front, Vec3::UnitX(), hy, hx},
                        {&skin.back, -Vec3::UnitX(), hy, hx},
                        {&skin.left, Vec3::UnitY(), hx, hy},
                        {&skin.right, -Vec3::UnitY(), hx, hy}};
  const Vec3 down = -Vec3::UnitZ();
  for (const Face& f : faces) {
    if (f.skin->texture < 0) continue;
    const Vec3 u = f.normal.cross(down);
    const Vec3 origin = f.normal * f.distance - u * f.half_width + Vec3(0, 0, h);
    Quad q = make_quad(origin, u * 2.0 * f.half_width, down * h, f.skin->texture, skin.label,
                       *f.skin, world, skin.albedo);
    out.push_back(transform_quad(T_frame_box, q));
  }
  if (skin.top.texture >= 0) {
    const Vec3 origin(-hx, hy, h);
    Quad q = make_quad(origin, Vec3(2.0 * hx, 0, 0), Vec3(0, -2.0 * hy, 0), skin.top.texture,
                       skin.label, skin.top, world, skin.albedo);
    out.push_back(transform_quad(T_frame_box, q));
  }
  if (skin.bottom.texture >= 0) {
    const Vec3 origin(-hx, -hy, 0.0);
    Quad q = make_quad(origin, Vec3(2.0 * hx, 0, 0), Vec3(0, 2.0 * hy, 0), skin.bottom.texture,
                       skin.label, skin.bottom, world, skin.albedo);
    out.push_back(transform_quad(T_frame_box, q));
  }
}

Quad transform_quad(const SE3& pose, const Quad& quad) {
  Quad q = quad;
  q.origin = pose * quad.origin;
  q.axis_u = pose.so3() * quad.axis_u;
  q.axis_v = pose.so3() * quad.axis_v;
  return q;
}

namespace {

// Ray-rectangle intersection; returns the distance along the ray or a negative value.
double intersect(const Quad& q, const Vec3& origin, const Vec3& dir) {
  const Vec3 n = q.axis_u.cross(q.axis_v);
  const double denom = n.dot(dir);
  if (std::abs(denom) < 1e-12) return -1.0;
  const double t = n.dot(q.origin - origin) / denom;
  if (t <= 0.0) return -1.0;
  const Vec3 rel = origin + t * dir - q.origin;
  const double a = rel.dot(q.axis_u), b = rel.dot(q.axis_v);
  if (a < 0.0 || a > q.size_u || b < 0.0 || b > q.size_v) return -1.0;
  return t;
}

}  // namespace

std::optional<RayHit> raycast(const World& world, const Vec3& origin, const Vec3& direction,
                              double time) {
  const Vec3 dir = direction.normalized();
  std::optional<RayHit> best;
  auto consider = [&](const Quad& q, const Vec3& o, const Vec3& d, const Quad* source,
                      const SE3* pose) {
    const double t = intersect(q, o, d);
    if (t <= 0.0 || (best && t >= best->distance)) return;
    RayHit hit;
    hit.distance = t;
    hit.point = pose ? (*pose) * (o + t * d) : o + t * d;
    hit.label = q.label;
    hit.quad = source;
    best = hit;
  };
  for (const Quad& q : world.quads) consider(q, origin, dir, &q, nullptr);
  for (const MovingObject& obj : world.objects) {
    const SE3 T_wo = obj.pose_at(time);
    const SE3 T_ow = T_wo.inverse();
    // Intersect in the object's frame: distances are preserved by the rigid motion.
    const Vec3 o = T_ow * origin;
    const Vec3 d = T_ow.so3() * dir;
    for (const Quad& q : obj.quads) consider(q, o, d, &q, &T_wo);
  }
  return best;
}

}  // namespace sbaslam::sim
