#include "sbaslam/sim/city_scene.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/sim/procedural_textures.h"
#include "sbaslam/sim/random.h"

namespace sbaslam::sim {
namespace {

struct CityTextures {
  std::vector<int> facades, signs, car_sides, car_fronts, car_rears, people;
  int road = 0, road_arrows = 0, intersection = 0, parking = 0, sidewalk = 0, terrain = 0;
  int foliage = 0, bark = 0, metal = 0, dark_metal = 0, concrete = 0, fence = 0, rail = 0;
  int traffic_light = 0;
};

CityTextures make_city_textures(World& w, std::uint64_t seed, const std::vector<cv::Mat>& photos) {
  const auto R = TextureWrap::kRepeat;
  const auto C = TextureWrap::kClamp;
  CityTextures t;
  for (int i = 0; i < 8; ++i) {
    if (!photos.empty())
      t.facades.push_back(w.add_texture(photos[static_cast<std::size_t>(i) % photos.size()], R));
    else
      t.facades.push_back(w.add_texture(
          facade_texture(static_cast<FacadeStyle>(i % kFacadeStyleCount), mix_seed(seed, 1, i)),
          R));
  }
  t.road = w.add_texture(road_texture(false, mix_seed(seed, 2)), R);
  t.road_arrows = w.add_texture(road_texture(true, mix_seed(seed, 3)), R);
  t.intersection = w.add_texture(intersection_texture(mix_seed(seed, 4)), C);
  t.parking = w.add_texture(parking_texture(mix_seed(seed, 5)), R);
  t.sidewalk = w.add_texture(sidewalk_texture(mix_seed(seed, 6)), R);
  t.terrain = w.add_texture(terrain_texture(mix_seed(seed, 7)), R);
  t.foliage = w.add_texture(foliage_texture(mix_seed(seed, 8)), R);
  t.bark = w.add_texture(streaked_texture(80, mix_seed(seed, 9)), R);
  t.metal = w.add_texture(streaked_texture(150, mix_seed(seed, 10)), R);
  t.dark_metal = w.add_texture(streaked_texture(50, mix_seed(seed, 11)), R);
  t.concrete = w.add_texture(streaked_texture(135, mix_seed(seed, 12)), R);
  t.fence = w.add_texture(fence_texture(mix_seed(seed, 13)), R);
  t.rail = w.add_texture(rail_texture(mix_seed(seed, 14)), R);
  t.traffic_light = w.add_texture(traffic_light_texture(mix_seed(seed, 15)), C);
  for (int i = 0; i < 8; ++i)
    t.signs.push_back(w.add_texture(sign_texture(i, mix_seed(seed, 16, i)), C));
  for (int i = 0; i < 6; ++i) {
    t.car_sides.push_back(w.add_texture(car_side_texture(mix_seed(seed, 17, i)), C));
    t.car_fronts.push_back(w.add_texture(car_end_texture(true, mix_seed(seed, 18, i)), C));
    t.car_rears.push_back(w.add_texture(car_end_texture(false, mix_seed(seed, 19, i)), C));
    t.people.push_back(w.add_texture(person_texture(mix_seed(seed, 20, i)), C));
  }
  return t;
}

FaceSkin tiled(int texture, double texels_per_metre, Random& rng) {
  FaceSkin s;
  s.texture = texture;
  s.texels_per_metre = texels_per_metre;
  s.offset_u = std::floor(rng.uniform(0.0, 1024.0));
  s.offset_v = std::floor(rng.uniform(0.0, 1024.0));
  return s;
}

FaceSkin fitted(int texture) {
  FaceSkin s;
  s.texture = texture;
  s.fit = true;
  return s;
}

BoxSkin uniform_skin(const FaceSkin& face, std::uint8_t label, float albedo) {
  BoxSkin s;
  s.front = s.back = s.left = s.right = s.top = s.bottom = face;
  s.label = label;
  s.albedo = albedo;
  return s;
}

// A car-like box: textured sides and ends; `label` says car, truck or bus.
BoxSkin vehicle_skin(const CityTextures& tex, int variant, std::uint8_t label, float albedo) {
  const std::size_t i = static_cast<std::size_t>(variant) % tex.car_sides.size();
  BoxSkin s;
  s.front = fitted(tex.car_fronts[i]);
  s.back = fitted(tex.car_rears[i]);
  s.left = s.right = fitted(tex.car_sides[i]);
  s.top = fitted(tex.car_fronts[i]);
  s.top.texture = tex.dark_metal;
  s.label = label;
  s.albedo = albedo;
  return s;
}

// A street from a to b, with a crossing (or an open end) at each end.
struct Street {
  Vec2 a, b;
  bool a_crossing, b_crossing;
};

std::vector<Street> city_streets() {
  std::vector<Street> streets;
  const double lo = kCityStreetLines[0], hi = kCityStreetLines[2], stub = 60.0;
  for (double c : kCityStreetLines) {
    for (int i = 0; i < 2; ++i) {
      const double a = kCityStreetLines[i], b = kCityStreetLines[i + 1];
      streets.push_back({{a, c}, {b, c}, true, true});
      streets.push_back({{c, a}, {c, b}, true, true});
    }
    streets.push_back({{lo - stub, c}, {lo, c}, false, true});
    streets.push_back({{hi, c}, {hi + stub, c}, true, false});
    streets.push_back({{c, lo - stub}, {c, lo}, false, true});
    streets.push_back({{c, hi}, {c, hi + stub}, true, false});
  }
  return streets;
}

SE3 pose_facing(const Vec3& position, const Vec3& forward) {
  const Vec3 x = forward.normalized();
  const Vec3 y = Vec3::UnitZ().cross(x);
  Mat3 R;
  R << x, y, Vec3::UnitZ();
  return SE3(SO3::from_matrix(R), position);
}

class CityBuilder {
 public:
  CityBuilder(World& world, const CityTextures& tex, std::uint64_t seed)
      : w_(world), tex_(tex), rng_(mix_seed(seed, 0xc17)) {}

  void build() {
    add_ground();
    for (double x : kCityStreetLines)
      for (double y : kCityStreetLines) add_crossing(Vec2(x, y));
    for (const Street& s : city_streets()) add_street(s);
    add_overpass();
  }

 private:
  // Street frame: along the direction d, offset to the right r, height z.
  struct Frame {
    Vec2 a, d, r;
    Vec3 at(double along, double offset, double z) const {
      const Vec2 p = a + d * along + r * offset;
      return Vec3(p.x(), p.y(), z);
    }
    Vec3 dir() const { return Vec3(d.x(), d.y(), 0.0); }
    Vec3 right() const { return Vec3(r.x(), r.y(), 0.0); }
  };

  // Horizontal strip between two offsets, texture rows growing with the offset.
  Quad& strip(const Frame& f, double a0, double a1, double o0, double o1, double z, int texture,
              std::uint8_t label, double tpm_u, double tpm_v) {
    FaceSkin skin;
    skin.texels_per_metre = tpm_u;
    w_.quads.push_back(make_quad(f.at(a0, o0, z), f.dir() * (a1 - a0), f.right() * (o1 - o0),
                                 texture, label, skin, w_));
    w_.quads.back().texels_per_metre_v = tpm_v;
    return w_.quads.back();
  }

  // Vertical rectangle facing `normal`, bottom centre at `base`.
  void panel(const Vec3& base, const Vec3& normal, double width, double height,
             const FaceSkin& skin, std::uint8_t label, float albedo = 1.0f) {
    const Vec3 down = -Vec3::UnitZ();
    const Vec3 u = normal.cross(down);
    const Vec3 origin = base - u * (0.5 * width) + Vec3(0, 0, height);
    w_.quads.push_back(
        make_quad(origin, u * width, down * height, skin.texture, label, skin, w_, albedo));
  }

  void box(const SE3& pose, const Vec3& size, const BoxSkin& skin) {
    add_box(w_.quads, w_, pose, size, skin);
  }

  void add_ground() {
    FaceSkin skin;
    skin.texels_per_metre = 33.0;
    w_.quads.push_back(make_quad(Vec3(-200, 440, -0.02), Vec3(640, 0, 0), Vec3(0, -640, 0),
                                 tex_.terrain, label::kTerrain, skin, w_));
    w_.quads.back().background = true;
  }

  void add_crossing(const Vec2& c) {
    const double h = kCitySidewalkOffset;
    w_.quads.push_back(make_quad(Vec3(c.x() - h, c.y() + h, 0.0), Vec3(2 * h, 0, 0),
                                 Vec3(0, -2 * h, 0), tex_.intersection, label::kRoad,
                                 fitted(tex_.intersection), w_));
  }

  void add_street(const Street& s) {
    Frame f;
    f.a = s.a;
    f.d = (s.b - s.a).normalized();
    f.r = Vec2(f.d.y(), -f.d.x());
    const double length = (s.b - s.a).norm();
    const double a0 = s.a_crossing ? kCitySidewalkOffset : 0.0;
    const double a1 = length - (s.b_crossing ? kCitySidewalkOffset : 0.0);
    const int road = rng_.chance(0.5) ? tex_.road_arrows : tex_.road;
    strip(f, a0, a1, -kCityCarriageHalfWidth, kCityCarriageHalfWidth, 0.0, road, label::kRoad, 40.0,
          40.0);
    const double park_w = kCityCurbOffset - kCityCarriageHalfWidth;
    for (int side : {-1, 1}) {
      const double inner = side * kCityCarriageHalfWidth, outer = side * kCityCurbOffset;
      strip(f, a0, a1, std::min(inner, outer), std::max(inner, outer), 0.0, tex_.parking,
            label::kParking, 40.0, 128.0 / park_w);
      const double walk_out = side * (kCityFacadeOffset + 0.5);
      strip(f, a0, a1, std::min(outer, walk_out), std::max(outer, walk_out), 0.12, tex_.sidewalk,
            label::kSidewalk, 50.0, 50.0);
      FaceSkin curb = tiled(tex_.concrete, 100.0, rng_);
      panel(f.at(0.5 * (a0 + a1), outer, 0.0), -side * f.right(), a1 - a0, 0.12, curb,
            label::kSidewalk);
      add_street_side(f, a0, a1, side, s.a_crossing, s.b_crossing);
    }
    if (!s.a_crossing) add_street_end(f.at(-10.0, 0.0, 0.0), f.dir());
    if (!s.b_crossing) add_street_end(f.at(length + 10.0, 0.0, 0.0), -f.dir());
    // A tram track along the centre of the eastern street of the first block.
    if (s.a == Vec2(240, 0) && s.b == Vec2(240, 120)) {
      Quad& q = strip(f, a0, a1, -1.6, 1.6, 0.005, tex_.rail, label::kRailTrack, 40.0, 40.0);
      q.texel_offset_v = 0.0;
    }
  }

  void add_street_end(const Vec3& centre, const Vec3& facing) {
    const double height = rng_.uniform(14.0, 26.0);
    BoxSkin skin = uniform_skin(tiled(pick_facade(), 50.0, rng_), label::kBuilding,
                                static_cast<float>(rng_.uniform(0.75, 1.05)));
    skin.front.offset_v = -height * 50.0;
    box(pose_facing(centre, facing), Vec3(16.0, 40.0, height), skin);
  }

  int pick_facade() {
    return tex_.facades[static_cast<std::size_t>(
        rng_.integer(0, static_cast<int>(tex_.facades.size()) - 1))];
  }

  void add_street_side(const Frame& f, double a0, double a1, int side, bool crossing_at_a,
                       bool crossing_at_b) {
    // Buildings with gaps holding fences or hedges.
    double along = a0 + 1.0;
    while (along < a1 - 6.0) {
      const double width = std::min(rng_.uniform(8.0, 24.0), a1 - 1.0 - along);
      if (width < 5.0) break;
      if (rng_.chance(0.2)) {
        const double gap = std::min(rng_.uniform(3.0, 8.0), a1 - 1.0 - along);
        add_gap(f, along, gap, side);
        along += gap;
        continue;
      }
      add_building(f, along, width, side);
      along += width;
    }
    // Street furniture on the sidewalk.
    const double lamp_phase = rng_.uniform(0.0, 30.0);
    for (double a = a0 + 4.0 + lamp_phase * 0.3; a < a1 - 3.0; a += 30.0) add_lamp(f, a, side);
    for (double a = a0 + 6.0 + rng_.uniform(0.0, 8.0); a < a1 - 4.0; a += rng_.uniform(11.0, 18.0))
      if (rng_.chance(0.7)) add_tree(f, a, side);
    for (double a = a0 + 10.0 + rng_.uniform(0.0, 20.0); a < a1 - 6.0;
         a += rng_.uniform(35.0, 60.0))
      add_traffic_sign(f, a, side);
    // Traffic lights where traffic on this side arrives at a crossing.
    if (side > 0 && crossing_at_b) add_traffic_light(f, a1 - 1.5, side);
    if (side < 0 && crossing_at_a) add_traffic_light(f, a0 + 1.5, side);
    for (double a = a0 + 5.0; a < a1 - 5.0; a += 6.4)
      if (rng_.chance(0.3)) add_parked_car(f, a, side);
  }

  void add_building(const Frame& f, double along, double width, int side) {
    const double depth = 14.0;
    const double height = rng_.chance(0.15) ? rng_.uniform(25.0, 40.0) : rng_.uniform(7.0, 22.0);
    const double setback = rng_.chance(0.4) ? rng_.uniform(0.0, 1.0) : 0.0;
    const double facade = kCityFacadeOffset + setback;
    const Vec3 towards_road = -side * f.right();
    const Vec3 centre = f.at(along + 0.5 * width, side * (facade + 0.5 * depth), 0.0);
    BoxSkin skin = uniform_skin(tiled(pick_facade(), 50.0, rng_), label::kBuilding,
                                static_cast<float>(rng_.uniform(0.7, 1.1)));
    skin.front.offset_v = skin.back.offset_v = skin.left.offset_v = skin.right.offset_v =
        -height * 50.0;  // floors line up with the ground
    skin.top.texture = skin.bottom.texture = -1;
    box(pose_facing(centre, towards_road), Vec3(depth, width, height), skin);
    if (rng_.chance(0.6)) {  // a shop sign over the ground floor, unique text per building
      const int sign = w_.add_texture(shop_sign_texture(rng_.next()), TextureWrap::kClamp);
      const double sign_w = std::min(width - 1.0, rng_.uniform(3.0, 6.0));
      const double pos = along + rng_.uniform(0.5 + 0.5 * sign_w, width - 0.5 - 0.5 * sign_w);
      panel(f.at(pos, side * (facade - 0.08), rng_.uniform(3.2, 3.8)), towards_road, sign_w,
            sign_w / 4.0, fitted(sign), label::kBuilding);
    }
  }

  void add_gap(const Frame& f, double along, double gap, int side) {
    const Vec3 towards_road = -side * f.right();
    const Vec3 base = f.at(along + 0.5 * gap, side * (kCityFacadeOffset + 0.3), 0.12);
    if (rng_.chance(0.5)) {
      panel(base, towards_road, gap, 1.8, tiled(tex_.fence, 100.0, rng_), label::kFence);
    } else {
      box(pose_facing(base, towards_road), Vec3(1.0, gap, 1.3),
          uniform_skin(tiled(tex_.foliage, 50.0, rng_), label::kVegetation, 0.9f));
    }
  }

  void add_lamp(const Frame& f, double along, int side) {
    const Vec3 towards_road = -side * f.right();
    const Vec3 base = f.at(along, side * 9.1, 0.12);
    const BoxSkin metal = uniform_skin(tiled(tex_.metal, 100.0, rng_), label::kPole, 0.9f);
    box(pose_facing(base, towards_road), Vec3(0.16, 0.16, 6.5), metal);
    box(pose_facing(base + towards_road * 0.6 + Vec3(0, 0, 6.25), towards_road),
        Vec3(1.2, 0.22, 0.15), metal);
  }

  void add_tree(const Frame& f, double along, int side) {
    const Vec3 base = f.at(along, side * 10.7, 0.12);
    const Vec3 facing =
        f.dir() * std::cos(rng_.uniform(0, 1.5)) + f.right() * std::sin(rng_.uniform(0, 1.5));
    box(pose_facing(base, facing), Vec3(0.3, 0.3, 2.6),
        uniform_skin(tiled(tex_.bark, 100.0, rng_), label::kVegetation, 0.8f));
    const double crown = rng_.uniform(2.4, 3.4);
    box(pose_facing(base + Vec3(0, 0, 2.4), facing), Vec3(crown, crown, rng_.uniform(2.4, 3.4)),
        uniform_skin(tiled(tex_.foliage, 50.0, rng_), label::kVegetation,
                     static_cast<float>(rng_.uniform(0.8, 1.05))));
  }

  void add_traffic_sign(const Frame& f, double along, int side) {
    const Vec3 facing = -side * f.dir();  // towards the traffic approaching on this side
    const Vec3 base = f.at(along, side * 9.3, 0.12);
    box(pose_facing(base, facing), Vec3(0.07, 0.07, 2.9),
        uniform_skin(tiled(tex_.metal, 100.0, rng_), label::kPole, 0.9f));
    const int sign = tex_.signs[static_cast<std::size_t>(rng_.integer(0, 7))];
    panel(base + facing * 0.05 + Vec3(0, 0, 2.05), facing, 0.75, 0.75, fitted(sign),
          label::kTrafficSign);
    panel(base + facing * 0.04 + Vec3(0, 0, 2.05), -facing, 0.75, 0.75,
          tiled(tex_.metal, 100.0, rng_), label::kTrafficSign);
  }

  void add_traffic_light(const Frame& f, double along, int side) {
    const Vec3 facing = -side * f.dir();
    const Vec3 base = f.at(along, side * 9.0, 0.12);
    box(pose_facing(base, facing), Vec3(0.2, 0.2, 4.8),
        uniform_skin(tiled(tex_.dark_metal, 100.0, rng_), label::kPole, 0.9f));
    BoxSkin head = uniform_skin(tiled(tex_.dark_metal, 100.0, rng_), label::kTrafficLight, 1.0f);
    head.front = fitted(tex_.traffic_light);
    box(pose_facing(base + facing * 0.3 + Vec3(0, 0, 3.6), facing), Vec3(0.35, 0.4, 1.1), head);
  }

  void add_parked_car(const Frame& f, double along, int side) {
    const Vec3 forward = side * f.dir();
    const Vec3 base = f.at(along, side * 7.5, 0.0);
    const double yaw = rng_.uniform(-0.03, 0.03);
    const Vec3 heading = std::cos(yaw) * forward + std::sin(yaw) * Vec3::UnitZ().cross(forward);
    box(pose_facing(base, heading), Vec3(4.3, 1.8, 1.45),
        vehicle_skin(tex_, rng_.integer(0, 5), label::kCar,
                     static_cast<float>(rng_.uniform(0.7, 1.1))));
  }

  void add_overpass() {
    const BoxSkin concrete = uniform_skin(tiled(tex_.concrete, 50.0, rng_), label::kBridge, 0.9f);
    box(pose_facing(Vec3(60, 120, 6.0), Vec3::UnitX()), Vec3(8.0, 44.0, 1.2), concrete);
    for (double dy : {-10.5, 10.5})
      box(pose_facing(Vec3(60, 120 + dy, 0.12), Vec3::UnitX()), Vec3(1.0, 1.0, 5.9), concrete);
  }

  World& w_;
  const CityTextures& tex_;
  Random rng_;
};

}  // namespace

World build_city_world(std::uint64_t seed, const std::vector<cv::Mat>& facade_photos) {
  World world;
  const CityTextures tex = make_city_textures(world, seed, facade_photos);
  CityBuilder(world, tex, seed).build();
  return world;
}

Route city_loop_route() {
  // S -> C -> D -> F -> A -> B -> H -> G -> (A): two counter-clockwise loops sharing the streets
  // A-S-B (driven three times eastwards) and F-A (twice southwards), crossing at E = (120, 120).
  const std::vector<Vec2> waypoints = {{20, 0},  {240, 0},   {240, 120}, {0, 120}, {0, 0},
                                       {120, 0}, {120, 240}, {0, 240},   {0, 0}};
  return Route(waypoints, 14.0, true);
}

Route straight_route() {
  return Route({{20, 0}, {230, 0}}, 14.0, false);
}

namespace {

// Pose of an object on the route at arc length s, in the lane at `offset`; reversed objects
// travel against the route's direction.
SE3 pose_on_route(const Route& route, double s, double offset, bool reversed, double height) {
  const RoutePoint p = route.at(s, offset);
  const double yaw = p.heading + (reversed ? M_PI : 0.0);
  return SE3(SO3::exp(Vec3(0, 0, yaw)), Vec3(p.position.x(), p.position.y(), height));
}

}  // namespace

void add_city_traffic(World& world, std::shared_ptr<const Route> route,
                      std::function<double(double)> ego_distance, int count, std::uint64_t seed) {
  CityTextures tex;
  for (int i = 0; i < 6; ++i) {
    const auto C = TextureWrap::kClamp;
    tex.car_sides.push_back(world.add_texture(car_side_texture(mix_seed(seed, 31, i)), C));
    tex.car_fronts.push_back(world.add_texture(car_end_texture(true, mix_seed(seed, 32, i)), C));
    tex.car_rears.push_back(world.add_texture(car_end_texture(false, mix_seed(seed, 33, i)), C));
    tex.people.push_back(world.add_texture(person_texture(mix_seed(seed, 34, i)), C));
  }
  tex.dark_metal =
      world.add_texture(streaked_texture(50, mix_seed(seed, 35)), TextureWrap::kRepeat);
  const double inner_lane = kCityEgoLane - kCityLaneWidth;
  for (int i = 0; i < count; ++i) {
    Random rng(mix_seed(seed, 0x7a4f, static_cast<std::uint64_t>(i)));
    MovingObject obj;
    const int role = i % 4;
    const int variant = rng.integer(0, 5);
    const float albedo = static_cast<float>(rng.uniform(0.7, 1.1));
    if (role == 3) {  // pedestrian on a sidewalk, walking either way
      obj.kind = "person";
      const double offset = (rng.chance(0.5) ? 1.0 : -1.0) * rng.uniform(9.6, 11.6);
      const double speed = rng.uniform(1.0, 1.7) * (rng.chance(0.5) ? 1.0 : -1.0);
      const double t0 = rng.uniform(0.0, 120.0);
      const double phase = rng.uniform(-40.0, 60.0);
      BoxSkin skin = uniform_skin(fitted(tex.people[static_cast<std::size_t>(variant)]),
                                  label::kPerson, albedo);
      skin.top.texture = skin.bottom.texture = -1;
      add_box(obj.quads, world, SE3(), Vec3(0.3, 0.55, 1.75), skin);
      // Met by the ego car around time t0, phase metres ahead of it.
      const double s_meet = ego_distance(t0) + phase;
      obj.pose_at = [route, offset, speed, t0, s_meet](double t) {
        return pose_on_route(*route, s_meet + speed * (t - t0), offset, speed < 0.0, 0.12);
      };
      world.objects.push_back(std::move(obj));
      continue;
    }
    // Vehicles: mostly cars, some trucks and buses (never directly ahead in the ego lane).
    std::uint8_t lbl = label::kCar;
    Vec3 size(4.4, 1.8, 1.5);
    const double kind = rng.uniform();
    if (role != 1 && kind < 0.15) {
      lbl = label::kTruck;
      size = Vec3(7.5, 2.4, 3.2);
    } else if (role != 1 && kind < 0.25) {
      lbl = label::kBus;
      size = Vec3(12.0, 2.5, 3.1);
    }
    obj.kind = lbl == label::kCar ? "car" : (lbl == label::kTruck ? "truck" : "bus");
    add_box(obj.quads, world, SE3(), size, vehicle_skin(tex, variant, lbl, albedo));
    if (role == 0 || role == 1) {
      // Next to the ego car in the inner lane (role 0), or ahead of it in its lane (role 1):
      // drifting back and forth around a mean gap, so it fills a large part of the view.
      const double offset = role == 0 ? inner_lane : kCityEgoLane;
      const double mean_gap = role == 0 ? rng.uniform(-4.0, 18.0) : rng.uniform(15.0, 25.0);
      const double amplitude = role == 0 ? rng.uniform(4.0, 10.0) : rng.uniform(2.0, 6.0);
      const double omega = rng.uniform(0.05, 0.15), phase = rng.uniform(0.0, 2.0 * M_PI);
      obj.pose_at = [route, ego_distance, offset, mean_gap, amplitude, omega, phase](double t) {
        const double s = ego_distance(t) + mean_gap + amplitude * std::sin(omega * t + phase);
        return pose_on_route(*route, s, offset, false, 0.0);
      };
    } else {  // oncoming, met by the ego car around time t0
      const double offset = rng.chance(0.5) ? -kCityEgoLane : -inner_lane;
      const double speed = rng.uniform(7.0, 11.0);
      const double t0 = rng.uniform(0.0, 150.0);
      const double s_meet = ego_distance(t0);
      obj.pose_at = [route, offset, speed, t0, s_meet](double t) {
        return pose_on_route(*route, s_meet - speed * (t - t0), offset, true, 0.0);
      };
    }
    world.objects.push_back(std::move(obj));
  }
}

}  // namespace sbaslam::sim
