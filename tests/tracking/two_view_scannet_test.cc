// The two-view initialiser on real indoor image pairs with ground-truth relative poses (ScanNet,
// /work/shared/data/two_view_pairs/scannet): ORB features, brute-force matching with a ratio test,
// then the initialiser; any motion it accepts is compared with the ground truth.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "geometry/two_view_scene.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/tracking/two_view_initializer.h"

namespace sbaslam::tracking {
namespace {

const std::string kScanNet = std::string(SBASLAM_SHARED_DIR) + "/data/two_view_pairs/scannet";

struct ScanNetPair {
  std::string image0, image1;
  PinholeIntrinsics k0, k1;
  Mat4 T_0to1;  // camera 0 -> camera 1, metres
};

std::vector<ScanNetPair> read_pairs() {
  std::ifstream in(kScanNet + "/pairs_with_gt.txt");
  EXPECT_TRUE(in.good()) << "cannot open " << kScanNet << "/pairs_with_gt.txt";
  std::vector<ScanNetPair> pairs;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    ScanNetPair p;
    int rot0 = 0, rot1 = 0;
    double K0[9], K1[9], T[16];
    fields >> p.image0 >> p.image1 >> rot0 >> rot1;
    for (double& v : K0) fields >> v;
    for (double& v : K1) fields >> v;
    for (double& v : T) fields >> v;
    if (!fields) {
      ADD_FAILURE() << "malformed line: " << line;
      continue;
    }
    EXPECT_EQ(rot0, 0);  // no EXIF rotation in this set
    EXPECT_EQ(rot1, 0);
    p.k0 = {K0[0], K0[4], K0[2], K0[5]};
    p.k1 = {K1[0], K1[4], K1[2], K1[5]};
    for (int i = 0; i < 16; ++i) p.T_0to1(i / 4, i % 4) = T[i];
    pairs.push_back(p);
  }
  return pairs;
}

struct PairOutcome {
  int matches = 0;
  TwoViewResult result;
  double rotation_error_deg = -1.0, direction_error_deg = -1.0, gt_rotation_deg = 0.0;
};

PairOutcome run_pair(const ScanNetPair& pair, feature::OrbExtractor& extractor) {
  const cv::Mat image0 = cv::imread(kScanNet + "/images/" + pair.image0, cv::IMREAD_GRAYSCALE);
  const cv::Mat image1 = cv::imread(kScanNet + "/images/" + pair.image1, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(image0.empty() || image1.empty()) << pair.image0 << " / " << pair.image1;
  PairOutcome out;
  if (image0.empty() || image1.empty()) return out;
  // No distortion is listed for these images: the detected keypoints are the undistorted ones.
  const feature::OrbFeatures f0 = extractor.extract(image0);
  const feature::OrbFeatures f1 = extractor.extract(image1);
  match::BruteForceOptions bf;
  bf.nn_ratio = 0.8f;
  bf.cross_check = true;
  const std::vector<match::Match> matches =
      match::match_brute_force(f0.descriptors, f1.descriptors, bf);
  out.matches = static_cast<int>(matches.size());
  // Both images of every pair share the intrinsics (checked by the caller).
  const TwoViewInitializer initializer(pair.k0, extractor.levels());
  out.result = initializer.initialize(f0.keypoints, f1.keypoints, matches, 7);
  const Mat3 R_gt = pair.T_0to1.topLeftCorner<3, 3>();
  const Vec3 t_gt = pair.T_0to1.topRightCorner<3, 1>();
  out.gt_rotation_deg = test::rotation_error_deg(R_gt, Mat3::Identity());
  if (out.result.ok()) {
    out.rotation_error_deg = test::rotation_error_deg(out.result.R21, R_gt);
    out.direction_error_deg = test::direction_error_deg(out.result.t21, t_gt);
  }
  return out;
}

TEST(TwoViewScanNet, AcceptedMotionsAgreeWithGroundTruth) {
  const std::vector<ScanNetPair> pairs = read_pairs();
  ASSERT_EQ(pairs.size(), 15u);
  OrbSettings settings;
  settings.n_features = 2000;
  feature::OrbExtractor extractor(settings);
  int accepted = 0;
  std::printf("%-58s %7s %5s %6s %6s %6s %6s %7s %7s  %s\n", "pair", "matches", "model", "R_H",
              "gt_rot", "parlx", "points", "rot_err", "dir_err", "outcome");
  for (const ScanNetPair& pair : pairs) {
    ASSERT_EQ(pair.k0.fx, pair.k1.fx);
    ASSERT_EQ(pair.k0.cx, pair.k1.cx);
    const PairOutcome o = run_pair(pair, extractor);
    const TwoViewResult& r = o.result;
    std::printf("%-58s %7d %5s %6.3f %6.1f %6.2f %6d %7.2f %7.2f  %s\n",
                (pair.image0 + " " + pair.image1).c_str(), o.matches,
                std::string(to_string(r.model)).substr(0, 5).c_str(), r.ratio_h, o.gt_rotation_deg,
                r.parallax_deg, r.triangulated_count, o.rotation_error_deg, o.direction_error_deg,
                r.message.c_str());
    if (!r.ok()) continue;
    ++accepted;
    EXPECT_LT(o.rotation_error_deg, 5.0) << pair.image0;
    EXPECT_LT(o.direction_error_deg, 10.0) << pair.image0;
  }
  std::printf("accepted %d of %zu pairs\n", accepted, pairs.size());
  // These are SuperGlue's wide-baseline pairs (31 to 172 degrees of rotation): ORB with a ratio
  // test finds 41-122 matches, mostly wrong, and the initialiser refuses every pair (measured: 0
  // of 15). What this test holds it to is never accepting a wrong motion, checked above.
}

}  // namespace
}  // namespace sbaslam::tracking
