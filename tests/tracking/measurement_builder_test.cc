// The front end's Salient BA weights on a monocular frame: with a uniform saliency map, only
// Algorithm 1's depth can make them differ, so near keypoints must outweigh far ones when depth
// samples are given, and all must be equal without them or with Saliency.depth "none". The same
// frame with a depth image as an RGB-D frame: keypoint depths and Algorithm 1's D from it. And the
// adjustments of sessions 19 and 20: the saturated map and the floor of D (the rig's close-point
// threshold; for monocular frames the samples' median depth).

#include "sbaslam/tracking/measurement_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/saliency/depth_correction.h"

namespace sbaslam::tracking {
namespace {

const std::string kImage =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0/000000.png";

struct HalfMeans {
  double left = 0.0, right = 0.0;
};

// ORB-SLAM3's RGB-D virtual pair: an 8 cm baseline and ThDepth 40, a close-point threshold of
// 3.2 m.
StereoSettings virtual_rgbd_pair(double fx) {
  StereoSettings pair;
  pair.baseline = 0.08;
  pair.bf = 0.08 * fx;
  pair.th_depth = 40.0;
  return pair;
}

HalfMeans mean_weight_per_half(const map::Measurements& m, int width) {
  double sum[2] = {0, 0};
  int count[2] = {0, 0};
  for (std::size_t i = 0; i < m.size(); ++i) {
    const int half = m.keypoints[i].x < width / 2 ? 0 : 1;
    sum[half] += m.weights[i];
    ++count[half];
  }
  return {sum[0] / count[0], sum[1] / count[1]};
}

class MonocularWeights : public ::testing::Test {
 protected:
  void SetUp() override {
    image_ = cv::imread(kImage, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image_.empty()) << kImage;
    camera_.intrinsics.fx = camera_.intrinsics.fy = 707.0912;
    camera_.intrinsics.cx = 601.8873;
    camera_.intrinsics.cy = 183.1104;
    camera_.width = image_.cols;
    camera_.height = image_.rows;
    saliency_.weight_a = 4.0;
    saliency_.weight_b = 1.0;
    // Near (5 m) on the left half of the image, far (50 m) on the right half.
    for (int y = 10; y < image_.rows; y += 20)
      for (int x = 10; x < image_.cols; x += 20)
        depths_.push_back(
            {static_cast<float>(x), static_cast<float>(y), x < image_.cols / 2 ? 5.0f : 50.0f});
  }

  map::MeasurementsPtr build(const std::vector<saliency::DepthSample>& depths) const {
    const map::CameraRig rig = make_camera_rig(camera_, StereoSettings(), OrbSettings(), false);
    MeasurementBuilder builder(rig, OrbSettings(), saliency_);
    const cv::Mat uniform(96, 320, CV_8U, cv::Scalar(200));
    return builder.build(image_, cv::Mat(), uniform, depths);
  }

  cv::Mat image_;
  CameraSettings camera_;
  SaliencySettings saliency_;
  std::vector<saliency::DepthSample> depths_;
};

TEST_F(MonocularWeights, NearKeypointsOutweighFarOnesWhenTheMapGivesDepth) {
  saliency_.depth_near = 0.0;  // the paper's plain 1 / D
  const map::MeasurementsPtr m = build(depths_);
  ASSERT_GT(m->size(), 500u);
  const HalfMeans means = mean_weight_per_half(*m, image_.cols);
  // S_final = S / D normalised by its maximum: 1 on the near half, 0.1 on the far half, so
  // w = 4 S^2 + 1 is about 5 against 1.04 (cells on the seam blend the two).
  EXPECT_GT(means.left, 4.0);
  EXPECT_LT(means.right, 1.3);
}

TEST_F(MonocularWeights, AllWeightsAreEqualWithoutDepth) {
  for (bool depth_off : {false, true}) {
    saliency_.depth_source = depth_off ? "none" : "auto";
    const map::MeasurementsPtr m =
        build(depth_off ? depths_ : std::vector<saliency::DepthSample>{});
    ASSERT_GT(m->size(), 500u);
    const auto [lo, hi] = std::minmax_element(m->weights.begin(), m->weights.end());
    EXPECT_EQ(*lo, *hi) << "Saliency.depth " << saliency_.depth_source;
  }
}

// The car: where the model's map is zero a keypoint keeps weight b, however the rest of
// the map is saturated (S >= 0.02 * 255 counts as static structure, S = 1, w = a + b).
TEST_F(MonocularWeights, AZeroMapKeepsWeightBWhileSaturatedStructureGetsAPlusB) {
  saliency_.depth_source = "none";
  saliency_.saturation = 0.02;
  const map::CameraRig rig = make_camera_rig(camera_, StereoSettings(), OrbSettings(), false);
  MeasurementBuilder builder(rig, OrbSettings(), saliency_);
  cv::Mat map(96, 320, CV_8U, cv::Scalar(0));
  map(cv::Rect(160, 0, 160, 96)).setTo(6);  // a faint 6 / 255: above the saturation level
  const map::MeasurementsPtr m = builder.build(image_, cv::Mat(), map, {});
  int car = 0, structure = 0;
  for (std::size_t i = 0; i < m->size(); ++i) {
    const float x = m->keypoints[i].x;
    if (x < image_.cols / 2 - 8) {
      EXPECT_EQ(m->weights[i], 1.0f);
      ++car;
    } else if (x > image_.cols / 2 + 8) {
      EXPECT_EQ(m->weights[i], 5.0f);
      ++structure;
    }
  }
  EXPECT_GT(car, 200);
  EXPECT_GT(structure, 200);
}

// Saliency-guided extraction (Saliency.keypoint_floor): the keypoints on the map's zero half go,
// and every per-keypoint field and the grid shrink with them, so each kept keypoint keeps its own
// descriptor, weight and grid cell.
TEST_F(MonocularWeights, AKeypointFloorDropsTheZeroHalfConsistently) {
  saliency_.depth_source = "none";
  const map::CameraRig rig = make_camera_rig(camera_, StereoSettings(), OrbSettings(), false);
  cv::Mat map(96, 320, CV_8U, cv::Scalar(0));
  map(cv::Rect(160, 0, 160, 96)).setTo(255);
  const map::MeasurementsPtr all =
      MeasurementBuilder(rig, OrbSettings(), saliency_).build(image_, cv::Mat(), map, {});
  saliency_.keypoint_floor = 0.5;
  saliency_.keypoint_max_dropped_share = 0.9;
  const map::MeasurementsPtr kept =
      MeasurementBuilder(rig, OrbSettings(), saliency_).build(image_, cv::Mat(), map, {});
  std::size_t right_half = 0;
  for (std::size_t i = 0; i < all->size(); ++i) right_half += all->weights[i] > 1.0f;
  ASSERT_GT(right_half, 200u);
  ASSERT_LT(right_half, all->size() - 200u);
  ASSERT_EQ(kept->size(), right_half);
  EXPECT_EQ(kept->descriptors.rows, static_cast<int>(kept->size()));
  EXPECT_EQ(kept->keypoints_un.size(), kept->size());
  EXPECT_EQ(kept->depth.size(), kept->size());
  EXPECT_EQ(kept->u_right.size(), kept->size());
  std::size_t j = 0;  // the kept keypoints are the right half's, in their order
  for (std::size_t i = 0; i < all->size(); ++i) {
    if (all->weights[i] <= 1.0f) continue;
    EXPECT_EQ(kept->keypoints[j].x, all->keypoints[i].x);
    EXPECT_EQ(kept->weights[j], all->weights[i]);
    EXPECT_EQ(cv::norm(kept->descriptors.row(static_cast<int>(j)),
                       all->descriptors.row(static_cast<int>(i)), cv::NORM_HAMMING),
              0.0);
    ++j;
  }
  EXPECT_EQ(kept->grid.size(), kept->size());
  const feature::OrbKeypoint& last = kept->keypoints_un.back();
  const std::vector<int> near = kept->grid.features_in_area(last.x, last.y, 2.0f);
  EXPECT_NE(std::find(near.begin(), near.end(), static_cast<int>(kept->size()) - 1), near.end());
}

// Saliency.depth_near: depths below it count alike. "auto" on an RGB-D rig is its close-point
// threshold, ThDepth x baseline = 3.2 m here, so 2.5 m and 3 m weigh the same; 0 restores 1 / D.
TEST_F(MonocularWeights, DepthsBelowTheCloseThresholdWeighAlikeOnAStereoRig) {
  const StereoSettings virtual_pair = virtual_rgbd_pair(camera_.intrinsics.fx);
  const map::CameraRig rig = make_camera_rig(camera_, virtual_pair, OrbSettings(), false, true);
  RgbdSettings rgbd;
  rgbd.depth_map_factor = 1000.0;
  cv::Mat depth(image_.size(), CV_16U, cv::Scalar(3000));
  depth(cv::Rect(0, 0, image_.cols / 2, image_.rows)).setTo(2500);
  const cv::Mat uniform(96, 320, CV_8U, cv::Scalar(200));
  for (const bool plain : {false, true}) {
    if (plain) saliency_.depth_near = 0.0;
    MeasurementBuilder builder(rig, OrbSettings(), saliency_, rgbd);
    const map::MeasurementsPtr m = builder.build(image_, cv::Mat(), uniform, {}, depth);
    const HalfMeans means = mean_weight_per_half(*m, image_.cols);
    if (plain) {
      // (3 / 2.5)^2 = 1.44: w = 4 S^2 + 1 is 5 against 4 S^2 / 1.44 + 1 = 3.78.
      EXPECT_GT(means.left, means.right + 1.0) << means.left << " vs " << means.right;
    } else {
      EXPECT_DOUBLE_EQ(means.left, 5.0);
      EXPECT_DOUBLE_EQ(means.right, 5.0);
    }
  }
}

// "auto" on a monocular frame floors D at the median of the map's depth samples: with 5, 20 and
// 50 (arbitrary units) on the image's thirds the median is 20, so the near and middle thirds
// weigh alike, w = 4 + 1, and the far one 4 (20 / 50)^2 + 1 = 1.64.
TEST_F(MonocularWeights, AutoFloorsMonocularDepthAtTheSamplesMedian) {
  std::vector<saliency::DepthSample> thirds;
  for (int y = 10; y < image_.rows; y += 20)
    for (int x = 10; x < image_.cols; x += 20) {
      const int third = 3 * x / image_.cols;
      thirds.push_back({static_cast<float>(x), static_cast<float>(y),
                        third == 0 ? 5.0f : (third == 1 ? 20.0f : 50.0f)});
    }
  EXPECT_FLOAT_EQ(saliency::median_sample_depth(thirds), 20.0f);
  const map::MeasurementsPtr m = build(thirds);
  double sum[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
  for (std::size_t i = 0; i < m->size(); ++i) {
    const float x = m->keypoints[i].x;
    const int third = static_cast<int>(3 * x / image_.cols);
    // Cells on the seams blend neighbouring depths; keep clear of them.
    if (std::abs(x - (third + 0.5f) * image_.cols / 3) > image_.cols / 6 - 24) continue;
    sum[third] += m->weights[i];
    ++count[third];
  }
  ASSERT_GT(count[0], 50);
  ASSERT_GT(count[1], 50);
  ASSERT_GT(count[2], 50);
  EXPECT_NEAR(sum[0] / count[0], 5.0, 0.05);
  EXPECT_NEAR(sum[1] / count[1], 5.0, 0.05);
  EXPECT_NEAR(sum[2] / count[2], 1.64, 0.05);
}

// Saliency.map_ba_depth: the keypoints keep their saturated S_init where local and full BA will
// weigh by each point's depth ("auto" on a monocular rig, or "point"), and nothing otherwise.
TEST_F(MonocularWeights, KeypointsKeepSInitWhereMapBaWeighsByPointDepth) {
  saliency_.saturation = 0.5;  // the uniform 200 / 255 saturates to 1
  const map::MeasurementsPtr automatic = build(depths_);
  ASSERT_EQ(automatic->s_init.size(), automatic->size());
  for (float s : automatic->s_init) EXPECT_EQ(s, 1.0f);
  saliency_.map_ba_depth = "frame";
  EXPECT_TRUE(build(depths_)->s_init.empty());
  saliency_.map_ba_depth = "auto";
  saliency_.depth_source = "none";
  EXPECT_TRUE(build(depths_)->s_init.empty());
  saliency_.depth_source = "auto";
  const StereoSettings virtual_pair = virtual_rgbd_pair(camera_.intrinsics.fx);
  const map::CameraRig rgbd_rig =
      make_camera_rig(camera_, virtual_pair, OrbSettings(), false, true);
  const cv::Mat uniform(96, 320, CV_8U, cv::Scalar(200));
  const cv::Mat depth(image_.size(), CV_16U, cv::Scalar(2500));
  EXPECT_TRUE(MeasurementBuilder(rgbd_rig, OrbSettings(), saliency_)
                  .build(image_, cv::Mat(), uniform, {}, depth)
                  ->s_init.empty());
  saliency_.map_ba_depth = "point";
  const map::MeasurementsPtr rgbd = MeasurementBuilder(rgbd_rig, OrbSettings(), saliency_)
                                        .build(image_, cv::Mat(), uniform, {}, depth);
  EXPECT_EQ(rgbd->s_init.size(), rgbd->size());
}

// Saliency.depth "model": D from the test network (depth = 1 + 9 * grey / 255), so on an image
// that is dark on the left (near) and bright on the right (far) the left keypoints outweigh the
// right ones, whatever the sensor.
TEST_F(MonocularWeights, DepthModelMakesDarkNearKeypointsOutweighBrightFarOnes) {
  saliency_.depth_source = "model";
  saliency_.depth_model.path =
      std::string(SBASLAM_SOURCE_DIR) + "/tests/data/depth_model_test.onnx";
  saliency_.depth_model.width = 64;
  saliency_.depth_model.height = 32;
  saliency_.depth_model.inverse = false;
  cv::Mat left_half = image_(cv::Rect(0, 0, image_.cols / 2, image_.rows));
  left_half.convertTo(left_half, CV_8U, 0.3);
  cv::Mat right_half =
      image_(cv::Rect(image_.cols / 2, 0, image_.cols - image_.cols / 2, image_.rows));
  right_half.convertTo(right_half, CV_8U, 0.5, 127);
  const map::MeasurementsPtr m = build({});
  ASSERT_GT(m->size(), 300u);
  const HalfMeans means = mean_weight_per_half(*m, image_.cols);
  EXPECT_GT(means.left, 2.0 * means.right) << means.left << " vs " << means.right;
  std::printf("mean weight left %.2f right %.2f\n", means.left, means.right);
}

// RGB-D: a keypoint takes the depth at its pixel and the virtual right column u - bf / d, as
// ORB-SLAM3's RGB-D frames; where the depth image has none, it stays monocular.
TEST_F(MonocularWeights, RgbdKeypointsTakeTheirDepthAndAVirtualRightColumn) {
  const StereoSettings virtual_pair = virtual_rgbd_pair(camera_.intrinsics.fx);
  const map::CameraRig rig = make_camera_rig(camera_, virtual_pair, OrbSettings(), false, true);
  ASSERT_TRUE(rig.stereo && rig.rgbd);
  RgbdSettings rgbd;
  rgbd.depth_map_factor = 1000.0;
  MeasurementBuilder builder(rig, OrbSettings(), saliency_, rgbd);
  // 2.5 m on the left half, no depth on the right half.
  cv::Mat depth(image_.size(), CV_16U, cv::Scalar(0));
  depth(cv::Rect(0, 0, image_.cols / 2, image_.rows)).setTo(2500);
  const map::MeasurementsPtr m = builder.build(image_, cv::Mat(), cv::Mat(), {}, depth);
  ASSERT_GT(m->size(), 500u);
  int with_depth = 0;
  for (std::size_t i = 0; i < m->size(); ++i) {
    if (std::lround(m->keypoints[i].x) < image_.cols / 2) {
      ASSERT_FLOAT_EQ(m->depth[i], 2.5f);
      EXPECT_NEAR(m->u_right[i], m->keypoints_un[i].x - virtual_pair.bf / 2.5, 1e-3);
      ++with_depth;
    } else {
      EXPECT_EQ(m->depth[i], -1.0f);
      EXPECT_EQ(m->u_right[i], -1.0f);
    }
  }
  EXPECT_GT(with_depth, 200);
  EXPECT_THROW(builder.build(image_, cv::Mat(), cv::Mat(), {}, cv::Mat()), Error);

  // Algorithm 1 takes D from the whole depth image: 2.5 m on the left, 25 m on the right.
  depth(cv::Rect(image_.cols / 2, 0, image_.cols - image_.cols / 2, image_.rows)).setTo(25000);
  const cv::Mat uniform(96, 320, CV_8U, cv::Scalar(200));
  const HalfMeans means =
      mean_weight_per_half(*builder.build(image_, cv::Mat(), uniform, {}, depth), image_.cols);
  EXPECT_GT(means.left, 4.0);   // w = 4 S^2 + 1 with S = 1
  EXPECT_LT(means.right, 1.3);  // S = 0.1
}

}  // namespace
}  // namespace sbaslam::tracking
