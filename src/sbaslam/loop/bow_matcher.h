#pragma once
// Descriptor matching between two keyframes through the vocabulary (ORB-SLAM's SearchByBoW):
// only keypoints filed under the same vocabulary node are compared, which keeps the search far
// below brute force and needs no pose, so it can link a keyframe to one seen long ago.

#include <cstddef>
#include <vector>

#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/map/keyframe.h"

namespace sbaslam::loop {

struct KeypointPair {
  std::size_t keypoint1 = 0;  // in the first keyframe
  std::size_t keypoint2 = 0;  // in the second
};

// Pairs of keypoints that both carry a good map point: descriptor distance within ORB-SLAM's
// TH_LOW (50), nearest below 0.75 of the second nearest, and a rotation consistent with the
// majority. At most one pair per keypoint of either keyframe. Map lock held.
std::vector<KeypointPair> match_keyframes_by_bow(const map::KeyFrame& kf1,
                                                 const FeatureVector& features1,
                                                 const map::KeyFrame& kf2,
                                                 const FeatureVector& features2);

}  // namespace sbaslam::loop
