#pragma once
// Fixture images and ORB settings shared by the feature and matcher tests.

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sbaslam/core/settings.h"

namespace sbaslam::test {

inline cv::Mat read_gray(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) ADD_FAILURE() << "cannot read " << path;
  return image;
}

inline OrbSettings orb_settings_with(int n_features) {
  OrbSettings s;
  s.n_features = n_features;
  return s;
}

}  // namespace sbaslam::test
