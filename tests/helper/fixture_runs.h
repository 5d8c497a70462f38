#pragma once
// `run` configurations on the shared real-data fixtures, for tests that play them whole.

#include <string>

#include "sbaslam/runner.h"

namespace sbaslam::test {

inline const std::string kKitti06 = std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51";

// KITTI 06's 51 frames, monocular, with the shipped KITTI 04-12 settings and seed 3.
inline RunConfig kitti06_mono_config(const std::string& out, bool deterministic) {
  RunConfig config;
  config.settings_path = std::string(SBASLAM_SOURCE_DIR) + "/config/KITTI04-12.yaml";
  config.dataset_kind = "kitti";
  config.dataset_path = kKitti06 + "/sequences/06";
  config.sensor = "mono";
  config.out_dir = out;
  config.deterministic = deterministic;
  config.seed = 3;
  config.progress = false;
  return config;
}

}  // namespace sbaslam::test
