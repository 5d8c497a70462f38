#include "sbaslam/map/map_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "helper/circular_map.h"
#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam {
namespace {

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Two maps (the second started after a "loss" at keyframe 25), one keyframe culled, one loop
// edge, and weights that differ per keypoint, so that every part of the file carries something;
// even keyframes keep an S_init per keypoint, odd ones none (Saliency.map_ba_depth: "frame").
std::unique_ptr<test::CircularMap> varied_map() {
  test::CircularMapOptions options;
  options.keyframes = 36;
  options.points = 1500;
  options.new_map_from = 25;
  auto c = test::make_circular_map(options);
  c->keyframes[7]->set_bad();
  c->keyframes[30]->add_loop_edge(c->keyframes[3]);
  c->keyframes[3]->add_loop_edge(c->keyframes[30]);
  for (map::KeyFrame* kf : c->map.keyframes()) {
    auto m = std::const_pointer_cast<map::Measurements>(kf->measurements_ptr());
    for (std::size_t i = 0; i < m->weights.size(); ++i) m->weights[i] = 1.0f + 0.25f * (i % 7);
    if (kf->id() % 2 == 0)
      for (std::size_t i = 0; i < m->size(); ++i) m->s_init.push_back(0.125f * (i % 9));
  }
  c->map.map_points()[5]->increase_visible(4);
  return c;
}

std::vector<std::size_t> ids(const std::vector<map::KeyFrame*>& keyframes) {
  std::vector<std::size_t> out;
  for (const map::KeyFrame* kf : keyframes) out.push_back(kf->id());
  return out;
}

void expect_same_keyframe(const map::KeyFrame& a, const map::KeyFrame& b) {
  SCOPED_TRACE("keyframe " + std::to_string(a.id()));
  EXPECT_EQ(a.id(), b.id());
  EXPECT_EQ(a.frame_id(), b.frame_id());
  EXPECT_EQ(a.map_id(), b.map_id());
  EXPECT_EQ(a.timestamp(), b.timestamp());
  EXPECT_EQ(a.T_cw().matrix(), b.T_cw().matrix());
  EXPECT_EQ(a.is_origin(), b.is_origin());
  ASSERT_EQ(a.keypoint_count(), b.keypoint_count());
  const map::Measurements &ma = a.measurements(), &mb = b.measurements();
  EXPECT_EQ(cv::norm(ma.descriptors, mb.descriptors, cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(ma.weights, mb.weights);
  EXPECT_EQ(ma.s_init, mb.s_init);
  EXPECT_EQ(ma.u_right, mb.u_right);
  for (std::size_t i = 0; i < a.keypoint_count(); ++i) {
    EXPECT_EQ(ma.keypoints_un[i].x, mb.keypoints_un[i].x);
    EXPECT_EQ(ma.keypoints_un[i].octave, mb.keypoints_un[i].octave);
    const map::MapPoint* pa = a.map_point(i);
    const map::MapPoint* pb = b.map_point(i);
    const bool live_a = pa && !pa->is_bad();
    ASSERT_EQ(live_a, pb != nullptr) << "keypoint " << i;
    if (live_a) {
      EXPECT_EQ(pa->id(), pb->id());
    }
  }
  EXPECT_EQ(ids(a.covisibles()), ids(b.covisibles()));
  const std::vector<map::KeyFrame*> covisibles_b = b.covisibles();
  for (map::KeyFrame* other : a.covisibles()) {
    const auto same = std::find_if(covisibles_b.begin(), covisibles_b.end(),
                                   [&](const map::KeyFrame* k) { return k->id() == other->id(); });
    ASSERT_NE(same, covisibles_b.end());
    EXPECT_EQ(a.connection_weight(other), b.connection_weight(*same));
  }
  EXPECT_EQ(a.parent() ? a.parent()->id() : 999u, b.parent() ? b.parent()->id() : 999u);
  EXPECT_EQ(ids({a.children().begin(), a.children().end()}),
            ids({b.children().begin(), b.children().end()}));
  EXPECT_EQ(ids({a.loop_edges().begin(), a.loop_edges().end()}),
            ids({b.loop_edges().begin(), b.loop_edges().end()}));
}

TEST(MapFile, LoadedMapIsTheSavedOneAndSavesToTheSameBytes) {
  const auto c = varied_map();
  test::TempDir dir;
  const map::MapFileSummary saved = map::save_map(c->map, c->rig, dir.file("a.map"));
  EXPECT_EQ(saved.keyframes, 35u);  // 36 made, 1 culled
  EXPECT_EQ(saved.maps, 2u);
  EXPECT_EQ(saved.biggest_map_id, 0u);
  EXPECT_EQ(saved.max_frame_id, 35u);

  map::Map loaded;
  const map::MapFileSummary summary = map::load_map(dir.file("a.map"), c->rig, loaded);
  EXPECT_EQ(summary.keyframes, saved.keyframes);
  EXPECT_EQ(summary.map_points, c->map.map_point_count());
  EXPECT_EQ(loaded.live_keyframes_per_map(), c->map.live_keyframes_per_map());
  EXPECT_EQ(loaded.first_keyframe()->id(), c->map.first_keyframe()->id());
  const std::vector<map::KeyFrame*> before = c->map.keyframes(), after = loaded.keyframes();
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t k = 0; k < before.size(); ++k) expect_same_keyframe(*before[k], *after[k]);

  const std::vector<map::MapPoint*> points_before = c->map.map_points();
  const std::vector<map::MapPoint*> points_after = loaded.map_points();
  ASSERT_EQ(points_before.size(), points_after.size());
  for (std::size_t k = 0; k < points_before.size(); ++k) {
    const map::MapPoint &a = *points_before[k], &b = *points_after[k];
    EXPECT_EQ(a.id(), b.id());
    EXPECT_EQ(a.position(), b.position());
    EXPECT_EQ(a.normal(), b.normal());
    EXPECT_EQ(a.max_distance(), b.max_distance());
    EXPECT_EQ(a.visible(), b.visible());
    EXPECT_EQ(a.observation_count(), b.observation_count());
    EXPECT_EQ(a.reference_keyframe()->id(), b.reference_keyframe()->id());
    EXPECT_EQ(cv::norm(a.descriptor(), b.descriptor(), cv::NORM_HAMMING), 0.0);
  }
  map::save_map(loaded, c->rig, dir.file("b.map"));
  // Not EXPECT_EQ on the contents: gtest would print megabytes of binary.
  EXPECT_TRUE(read_bytes(dir.file("a.map")) == read_bytes(dir.file("b.map")));
  // The counters go on where the saved map's stopped, so new ids never repeat old ones.
  EXPECT_EQ(loaded.new_map_id(), c->map.new_map_id());
}

TEST(MapFile, LeavesOutWhatTheMapCulled) {
  const auto c = varied_map();
  map::MapPoint* culled = c->map.map_points()[10];
  const std::size_t culled_id = culled->id();
  culled->set_bad();
  test::TempDir dir;
  map::save_map(c->map, c->rig, dir.file("a.map"));
  map::Map loaded;
  map::load_map(dir.file("a.map"), c->rig, loaded);
  for (const map::KeyFrame* kf : loaded.keyframes()) EXPECT_NE(kf->id(), 7u);
  for (const map::MapPoint* mp : loaded.map_points()) EXPECT_NE(mp->id(), culled_id);
  EXPECT_EQ(loaded.map_point_count(), c->map.map_point_count());
}

TEST(MapFile, RefusesAMapMadeWithAnotherCamera) {
  const auto c = varied_map();
  test::TempDir dir;
  map::save_map(c->map, c->rig, dir.file("a.map"));
  map::CameraRig other = c->rig;
  other.camera = PinholeCamera(PinholeIntrinsics{510.0, 500.0, 320.0, 240.0});
  map::Map loaded;
  const std::string message =
      test::error_message([&] { map::load_map(dir.file("a.map"), other, loaded); });
  EXPECT_NE(message.find(dir.file("a.map")), std::string::npos) << message;
  EXPECT_NE(message.find("fx 500"), std::string::npos) << message;
  other = c->rig;
  other.stereo = true;
  test::expect_error_naming([&] { map::load_map(dir.file("a.map"), other, loaded); },
                            "made with a monocular camera, this run is stereo");
  // The same K through another lens: its keypoints were undistorted otherwise.
  other = c->rig;
  other.camera = PinholeCamera(c->rig.camera.intrinsics(), KannalaBrandtDistortion{});
  test::expect_error_naming([&] { map::load_map(dir.file("a.map"), other, loaded); },
                            "made with a radial-tangential lens, this run has a Kannala-Brandt");
  other.camera = PinholeCamera(c->rig.camera.intrinsics(), RadTanDistortion{0.1, 0, 0, 0, 0});
  test::expect_error_naming([&] { map::load_map(dir.file("a.map"), other, loaded); },
                            "lens distortion coefficient 1 = 0, this run has 0.1");
}

TEST(MapFile, RefusesMissingTruncatedCorruptAndForeignFiles) {
  const auto c = varied_map();
  test::TempDir dir;
  map::save_map(c->map, c->rig, dir.file("a.map"));
  const std::string bytes = read_bytes(dir.file("a.map"));
  const auto load_error = [&](const std::string& content) {
    write_bytes(dir.file("bad.map"), content);
    map::Map loaded;
    return test::error_message([&] { map::load_map(dir.file("bad.map"), c->rig, loaded); });
  };
  for (const double share : {0.0, 0.001, 0.3, 0.9, 0.99999}) {
    const std::string message =
        load_error(bytes.substr(0, static_cast<std::size_t>(share * bytes.size())));
    EXPECT_NE(message.find("bad.map: truncated map file"), std::string::npos) << message;
  }
  EXPECT_NE(load_error(bytes + "x").find("bytes after the end"), std::string::npos);
  // ORB-SLAM3's atlas files: boost text and binary archives.
  EXPECT_NE(load_error("22 serialization::archive 19 0 0 ...").find("ORB-SLAM3's atlas"),
            std::string::npos);
  EXPECT_NE(load_error(std::string("\x16\0\0\0\0\0\0\0serialization::archive\x13\0", 32))
                .find("ORB-SLAM3's atlas"),
            std::string::npos);
  EXPECT_NE(load_error(std::string(200, '\0')).find("not an sba-slam map file"), std::string::npos);
  std::string newer = bytes;
  newer[16] = 4;  // the version word, after the magic and the byte-order mark
  EXPECT_NE(load_error(newer).find("version 4"), std::string::npos);
  std::string huge_count = bytes;
  // The keyframe count follows the header (12 + 4 + 4), the rig (2 * 4 + 6 * 8 + 2 + 4 + 8, and
  // its lens: 1 + 5 * 8) and four counters.
  const std::size_t keyframe_count_at = 20 + 111 + 32;
  ASSERT_EQ(huge_count[keyframe_count_at], 35);
  huge_count[keyframe_count_at + 6] = 1;
  EXPECT_NE(load_error(huge_count).find("corrupt map file"), std::string::npos)
      << load_error(huge_count);
  // Within the bound but more than the file holds: refused before 16 GB are allocated for it.
  std::string long_count = bytes;
  long_count[keyframe_count_at + 3] = static_cast<char>(0x80);
  EXPECT_NE(load_error(long_count).find("truncated map file (2147483683 keyframes"),
            std::string::npos)
      << load_error(long_count);
  map::Map loaded;
  test::expect_error_naming([&] { map::load_map(dir.file("missing.map"), c->rig, loaded); },
                            dir.file("missing.map") + ": map file not found");
}

}  // namespace
}  // namespace sbaslam
