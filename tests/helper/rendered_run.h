#pragma once
// A deterministic `run` of a sequence the simulator wrote into DIR/data (KITTI layout, sequence
// 00), with its outputs in DIR/out.

#include "helper/temp_dir.h"
#include "sbaslam/runner.h"

namespace sbaslam::test {

inline RunConfig rendered_kitti_run(const TempDir& dir) {
  RunConfig config;
  config.settings_path = dir.file("data/settings.yaml");
  config.dataset_kind = "kitti";
  config.dataset_path = dir.file("data/sequences/00");
  config.out_dir = dir.file("out");
  config.deterministic = true;
  config.progress = false;
  return config;
}

}  // namespace sbaslam::test
