#include "sbaslam/saliency/observation_weight.h"

#include <gtest/gtest.h>

namespace sbaslam::saliency {
namespace {

feature::OrbKeypoint keypoint_at(float x, float y) {
  feature::OrbKeypoint kp;
  kp.x = x;
  kp.y = y;
  return kp;
}

TEST(ObservationWeight, FollowsASquaredPlusB) {
  SaliencySettings s;
  s.weight_a = 3.0;
  s.weight_b = 0.5;
  EXPECT_FLOAT_EQ(observation_weight(0.0f, s), 0.5f);
  EXPECT_FLOAT_EQ(observation_weight(1.0f, s), 3.5f);
  EXPECT_FLOAT_EQ(observation_weight(0.5f, s), 3.0f * 0.25f + 0.5f);
}

// A map predicted at a smaller size than the image: the right half (a "car") is 0, the left
// half fully salient. A keypoint on the car gets weight b, one on the left a + b.
TEST(ObservationWeight, KeypointOnAZeroRegionGetsB) {
  SaliencySettings s;
  s.weight_a = 2.0;
  s.weight_b = 0.25;
  cv::Mat map(96, 320, CV_8UC1, cv::Scalar(0));
  map(cv::Rect(0, 0, 160, 96)).setTo(255);
  const std::vector<feature::OrbKeypoint> kps = {keypoint_at(100.0f, 50.0f),
                                                 keypoint_at(1100.0f, 300.0f)};
  const std::vector<float> w = keypoint_weights(map, cv::Size(1241, 376), kps, s);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_FLOAT_EQ(w[0], 2.25f);
  EXPECT_FLOAT_EQ(w[1], 0.25f);
}

TEST(ObservationWeight, EmptyMapMeansUniformWeights) {
  SaliencySettings s;
  s.weight_a = 5.0;
  s.weight_b = 0.1;
  const std::vector<float> w =
      keypoint_weights(cv::Mat(), cv::Size(640, 480), {keypoint_at(1.0f, 2.0f)}, s);
  EXPECT_EQ(w, std::vector<float>{1.0f});
}

// Saliency.map_ba_depth: "point": Algorithm 1 for one observation. With depth_a = 1, depth_b = 0
// it is s_init * min(1, near / z); depth_b lifts far points, and the divisor keeps s in [0, 1].
TEST(PointDepthWeight, ScalesSInitByTheFloorOverThePointsDepth) {
  SaliencySettings s;
  s.weight_a = 4.0;
  s.weight_b = 1.0;
  EXPECT_FLOAT_EQ(point_depth_weight(0.5f, 5.0, 10.0, s), 4.0f * 0.25f + 1.0f);
  EXPECT_FLOAT_EQ(point_depth_weight(0.5f, 20.0, 10.0, s), 4.0f * 0.0625f + 1.0f);
  EXPECT_FLOAT_EQ(point_depth_weight(1.0f, 10.0, 10.0, s), 5.0f);
  EXPECT_FLOAT_EQ(point_depth_weight(0.0f, 1.0, 10.0, s), 1.0f);
  s.depth_b = 0.5;
  EXPECT_FLOAT_EQ(point_depth_weight(1.0f, 2.0, 10.0, s), 5.0f);
  const float far = (0.1f / 1000.0f + 0.5f) / 0.6f;
  EXPECT_FLOAT_EQ(point_depth_weight(0.1f, 1000.0, 10.0, s), 4.0f * far * far + 1.0f);
  s.depth_b = -1.0;  // a negative depth_b clamps s at 0, as the frame's map does
  s.depth_a = 20.0;
  EXPECT_FLOAT_EQ(point_depth_weight(0.1f, 100.0, 10.0, s), 1.0f);
}

TEST(KeypointSaliency, SamplesTheMapScaledToTheImage) {
  cv::Mat map(96, 320, CV_8UC1, cv::Scalar(51));
  map(cv::Rect(0, 0, 160, 96)).setTo(255);
  const std::vector<feature::OrbKeypoint> kps = {keypoint_at(100.0f, 50.0f),
                                                 keypoint_at(1100.0f, 300.0f)};
  EXPECT_EQ(keypoint_saliency(map, cv::Size(1241, 376), kps), (std::vector<float>{1.0f, 0.2f}));
  EXPECT_TRUE(keypoint_saliency(cv::Mat(), cv::Size(1241, 376), kps).empty());
}

// Saliency-guided extraction: of five keypoints, the two on the zero half go, the least salient
// first, but only as many as the share allows.
TEST(SalientKeypoints, DropsTheLeastSalientUpToTheShare) {
  cv::Mat map(100, 200, CV_8UC1, cv::Scalar(255));
  map(cv::Rect(100, 0, 100, 100)).setTo(0);
  map.at<std::uint8_t>(50, 150) = 20;  // below a floor of 0.1, but above the rest of the half
  const std::vector<feature::OrbKeypoint> kps = {
      keypoint_at(10.0f, 10.0f), keypoint_at(150.0f, 50.0f), keypoint_at(50.0f, 50.0f),
      keypoint_at(180.0f, 80.0f), keypoint_at(90.0f, 90.0f)};
  const cv::Size size(200, 100);
  EXPECT_EQ(salient_keypoints(map, size, kps, 0.1, 0.5),
            (std::vector<bool>{true, false, true, false, true}));
  // One keypoint of five may go: the one at value 0, not the one at 20.
  EXPECT_EQ(salient_keypoints(map, size, kps, 0.1, 0.2),
            (std::vector<bool>{true, true, true, false, true}));
  EXPECT_EQ(salient_keypoints(map, size, kps, 0.0, 0.5), std::vector<bool>(5, true));
  EXPECT_EQ(salient_keypoints(cv::Mat(), size, kps, 0.1, 0.5), std::vector<bool>(5, true));
}

}  // namespace
}  // namespace sbaslam::saliency
