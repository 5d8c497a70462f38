#pragma once
// The synthetic world: textured planar rectangles (quads), static or attached to moving objects,
// plus the lighting. It is the single source of truth for both the renderer and the analytic ray
// casting the tests compare the renderer against.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/sim/texture.h"

namespace sbaslam::sim {

// Cityscapes label ids (labelIds of the Cityscapes scripts).
namespace label {
constexpr std::uint8_t kRoad = 7, kSidewalk = 8, kParking = 9, kRailTrack = 10, kBuilding = 11,
                       kFence = 13, kBridge = 15, kPole = 17, kPoleGroup = 18, kTrafficLight = 19,
                       kTrafficSign = 20, kVegetation = 21, kTerrain = 22, kSky = 23, kPerson = 24,
                       kRider = 25, kCar = 26, kTruck = 27, kBus = 28;
}

// A textured rectangle. Texture columns run along axis_u and rows along axis_v; seen from the
// front (the side front_normal() points to) the texture reads as in the image, u right, v down.
struct Quad {
  Vec3 origin = Vec3::Zero();   // corner at texture coordinate (0, 0)
  Vec3 axis_u = Vec3::UnitX();  // unit
  Vec3 axis_v = Vec3::UnitY();  // unit, orthogonal to axis_u
  double size_u = 1.0;          // metres along axis_u
  double size_v = 1.0;
  int texture = 0;
  double texels_per_metre_u = 50.0;
  double texels_per_metre_v = 50.0;
  double texel_offset_u = 0.0;
  double texel_offset_v = 0.0;
  float albedo = 1.0f;
  std::uint8_t label = label::kBuilding;
  bool two_sided = false;
  // Drawn after every other quad (a ground plane under the streets): the pixels the streets
  // already cover then cost one depth comparison instead of a texture read.
  bool background = false;

  Vec3 front_normal() const { return axis_v.cross(axis_u); }
};

// How one face of a box is textured: the whole texture stretched over the face (fit), or tiled
// at a texel density with an offset. A face without texture (texture < 0) is left out.
struct FaceSkin {
  int texture = -1;
  bool fit = false;
  double texels_per_metre = 50.0;
  double offset_u = 0.0, offset_v = 0.0;
};

// Box frame: x forward (front face), y left, z up, origin at the centre of the bottom face.
struct BoxSkin {
  FaceSkin front, back, left, right, top, bottom;
  std::uint8_t label = label::kBuilding;
  float albedo = 1.0f;
};

struct MovingObject {
  std::string kind;                    // "car", "truck", "bus", "person"
  std::vector<Quad> quads;             // in the object's frame
  std::function<SE3(double)> pose_at;  // T_world_object at time t (seconds)
};

struct Lighting {
  Vec3 sun_direction = Vec3(0.35, 0.25, 0.9).normalized();  // towards the light
  double ambient = 0.65;
  double diffuse = 0.45;
  bool sky = true;            // rays hitting nothing see the sky (outdoor) or black (indoor)
  double sky_horizon = 0.80;  // sky radiance at the horizon and at the zenith
  double sky_zenith = 0.62;
};

struct World {
  std::vector<Texture> textures;
  std::vector<Quad> quads;  // static, in the world frame
  std::vector<MovingObject> objects;
  Lighting lighting;

  int add_texture(const cv::Mat& image, TextureWrap wrap);
  // Lambertian shading of a face with the given world-frame outward normal.
  float shade(const Quad& quad, const Vec3& normal_world) const;
};

// A quad spanning origin + a * u_vec + b * v_vec for a, b in [0, 1], with the texture tiled at
// texels_per_metre (or stretched over it when fit).
Quad make_quad(const Vec3& origin, const Vec3& u_vec, const Vec3& v_vec, int texture,
               std::uint8_t label, const FaceSkin& skin, const World& world, float albedo = 1.0f);

// Appends the faces of a box of size (length x, width y, height z) posed by T_frame_box.
void add_box(std::vector<Quad>& out, const World& world, const SE3& T_frame_box, const Vec3& size,
             const BoxSkin& skin);

// A quad in the frame of `pose` (T_world_frame): pose applied to its corners and axes.
Quad transform_quad(const SE3& pose, const Quad& quad);

struct RayHit {
  double distance = 0.0;  // along the unit ray direction
  Vec3 point = Vec3::Zero();
  std::uint8_t label = 0;
  const Quad* quad = nullptr;  // the hit quad (object quads: in the object's frame)
};

// Analytic nearest intersection of a ray with every quad of the world at time t (both sides of
// every quad), or nothing.
std::optional<RayHit> raycast(const World& world, const Vec3& origin, const Vec3& direction,
                              double time);

}  // namespace sbaslam::sim
