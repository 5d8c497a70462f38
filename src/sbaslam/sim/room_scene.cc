#include "sbaslam/sim/room_scene.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/sim/procedural_textures.h"
#include "sbaslam/sim/random.h"

namespace sbaslam::sim {
namespace {

FaceSkin tile_skin(int texture, double texels_per_metre, Random& rng) {
  FaceSkin s;
  s.texture = texture;
  s.texels_per_metre = texels_per_metre;
  s.offset_u = std::floor(rng.uniform(0.0, 512.0));
  s.offset_v = std::floor(rng.uniform(0.0, 512.0));
  return s;
}

FaceSkin fit_skin(int texture) {
  FaceSkin s;
  s.texture = texture;
  s.fit = true;
  return s;
}

// Smooth step from 0 to 1 over [a, b] (zero slope at both ends).
double smooth_step(double x, double a, double b) {
  const double u = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return u * u * u * (u * (6.0 * u - 15.0) + 10.0);
}

struct Wall {
  Vec3 origin, u, v;  // as seen from inside the room
};

}  // namespace

World build_room_world(std::uint64_t seed, const std::vector<cv::Mat>& wall_photos) {
  World w;
  Random rng(mix_seed(seed, 0x2004));
  const auto R = TextureWrap::kRepeat;
  w.lighting.sky = false;
  w.lighting.sun_direction = Vec3(0.45, 0.3, 0.84).normalized();
  w.lighting.ambient = 0.7;
  w.lighting.diffuse = 0.35;

  std::vector<int> wall_tex;
  for (int i = 0; i < 4; ++i)
    wall_tex.push_back(
        wall_photos.empty()
            ? w.add_texture(wall_texture(mix_seed(seed, 40, i)), R)
            : w.add_texture(wall_photos[static_cast<std::size_t>(i) % wall_photos.size()], R));
  const int floor_tex = w.add_texture(floor_mat_texture(mix_seed(seed, 41)), R);
  const int ceiling_tex = w.add_texture(ceiling_texture(mix_seed(seed, 42)), R);

  const double X = kRoomHalfX, Y = kRoomHalfY, H = kRoomHeight;
  // Walls seen from inside: u to the right, v down.
  const Wall walls[] = {{Vec3(-X, Y, H), Vec3(2 * X, 0, 0), Vec3(0, 0, -H)},    // north, faces -y
                        {Vec3(X, -Y, H), Vec3(-2 * X, 0, 0), Vec3(0, 0, -H)},   // south, faces +y
                        {Vec3(X, Y, H), Vec3(0, -2 * Y, 0), Vec3(0, 0, -H)},    // east, faces -x
                        {Vec3(-X, -Y, H), Vec3(0, 2 * Y, 0), Vec3(0, 0, -H)}};  // west, faces +x
  for (int i = 0; i < 4; ++i) {
    const Wall& wall = walls[i];
    w.quads.push_back(make_quad(wall.origin, wall.u, wall.v, wall_tex[static_cast<std::size_t>(i)],
                                label::kBuilding,
                                tile_skin(wall_tex[static_cast<std::size_t>(i)], 100.0, rng), w,
                                static_cast<float>(rng.uniform(0.85, 1.05))));
    // Posters 2 cm in front of the wall.
    const Vec3 inward = wall.v.normalized().cross(wall.u.normalized());
    const int posters = rng.integer(3, 5);
    for (int k = 0; k < posters; ++k) {
      const int tex = w.add_texture(poster_texture(rng.next()), TextureWrap::kClamp);
      const double size = rng.uniform(0.6, 1.3);
      const double a = (k + rng.uniform(0.2, 0.8)) / posters;
      const double along = std::clamp(a * wall.u.norm(), 0.2, wall.u.norm() - size - 0.2);
      const double drop = rng.uniform(0.4, 1.4);
      const Vec3 origin =
          wall.origin + wall.u.normalized() * along + wall.v.normalized() * drop + inward * 0.02;
      w.quads.push_back(make_quad(origin, wall.u.normalized() * size, wall.v.normalized() * size,
                                  tex, label::kBuilding, fit_skin(tex), w));
    }
  }
  // Floor (faces up) and ceiling (faces down).
  w.quads.push_back(make_quad(Vec3(-X, Y, 0), Vec3(2 * X, 0, 0), Vec3(0, -2 * Y, 0), floor_tex,
                              label::kSidewalk, tile_skin(floor_tex, 100.0, rng), w));
  w.quads.push_back(make_quad(Vec3(-X, -Y, H), Vec3(2 * X, 0, 0), Vec3(0, 2 * Y, 0), ceiling_tex,
                              label::kBuilding, tile_skin(ceiling_tex, 50.0, rng), w));

  // Furniture-like boxes and stacks along the walls, outside the flight volume
  // (|x| < 2.4, |y| < 1.9).
  for (int i = 0; i < 16; ++i) {
    const bool crate = rng.chance(0.4);
    const int tex = w.add_texture(box_texture(crate, rng.next()), TextureWrap::kClamp);
    BoxSkin skin;
    skin.front = skin.back = skin.left = skin.right = skin.top = fit_skin(tex);
    skin.label = label::kFence;
    skin.albedo = static_cast<float>(rng.uniform(0.75, 1.05));
    Vec3 size(rng.uniform(0.4, 1.2), rng.uniform(0.4, 1.2), rng.uniform(0.3, 1.6));
    Vec2 p;
    if (i % 2 == 0)
      p = Vec2(rng.uniform(-4.3, 4.3), (rng.chance(0.5) ? 1 : -1) * rng.uniform(2.6, 3.4));
    else
      p = Vec2((rng.chance(0.5) ? 1 : -1) * rng.uniform(3.1, 4.3), rng.uniform(-3.3, 3.3));
    const SE3 pose(SO3::exp(Vec3(0, 0, rng.uniform(-0.6, 0.6))), Vec3(p.x(), p.y(), 0.0));
    add_box(w.quads, w, pose, size, skin);
    if (rng.chance(0.35)) {  // a smaller box stacked on top
      const Vec3 top(size.x() * 0.6, size.y() * 0.6, rng.uniform(0.2, 0.6));
      const SE3 up = pose * SE3(SO3::exp(Vec3(0, 0, rng.uniform(-0.4, 0.4))), Vec3(0, 0, size.z()));
      add_box(w.quads, w, up, top, skin);
    }
  }
  return w;
}

SE3 room_body_pose(double t, std::uint64_t seed) {
  Random rng(mix_seed(seed, 0x3a7));
  const double p1 = rng.uniform(0, 2 * M_PI), p2 = rng.uniform(0, 2 * M_PI),
               p3 = rng.uniform(0, 2 * M_PI);
  const Vec3 position(1.9 * std::sin(0.23 * t + p1), 1.4 * std::sin(0.31 * t + p2),
                      1.35 + 0.35 * std::sin(0.47 * t + p3));
  // Vibration of the airframe: a few millimetres at higher frequencies.
  const Vec3 vibration(0.004 * std::sin(13.1 * t), 0.003 * std::sin(17.3 * t + 1.0),
                       0.004 * std::sin(11.7 * t + 2.0));
  const double fast_turns =
      0.5 * M_PI * smooth_step(t, 10.5, 11.5) - 0.5 * M_PI * smooth_step(t, 26.5, 27.5);
  const double yaw = 0.3 * t + 0.6 * std::sin(0.21 * t + p1) + fast_turns;
  const double pitch = 0.12 * std::sin(0.53 * t + p2) + 0.05 * std::sin(1.7 * t);
  const double roll = 0.1 * std::sin(0.61 * t + p3) + 0.04 * std::sin(2.3 * t);
  const Mat3 R = (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
                  Eigen::AngleAxisd(roll, Vec3::UnitX()))
                     .toRotationMatrix();
  return SE3(SO3::from_matrix(R), position + vibration);
}

double room_light_level(double t) {
  const double dark = smooth_step(t, 16.0, 17.0) - smooth_step(t, 20.0, 21.0);
  return 1.0 - 0.85 * dark;
}

}  // namespace sbaslam::sim
