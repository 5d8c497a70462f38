#pragma once
// Small copies of the shared real-data fixtures in a temp folder, for tests that break them on
// purpose (truncated images, missing files, bad listings). Only the first few frames are copied.

#include <string>

namespace sbaslam::test {

std::string shared_data_dir();             // SBASLAM_SHARED_DIR/data
std::string euroc_fixture_dir();           // .../euroc_v101_micro (holds mav0/)
std::string kitti_fixture_sequence_dir();  // .../kitti06_first51/sequences/06

// Copies cam0 (and cam1 when `with_cam1`) of the EuRoC fixture, the first n frames of each
// listing, with sensor.yaml; returns the folder holding mav0/.
std::string copy_euroc_subset(const std::string& dst_root, std::size_t n, bool with_cam1);
// Copies image_0, calib.txt, times.txt and poses/06.txt of the KITTI fixture, first n frames;
// returns .../sequences/06.
std::string copy_kitti_subset(const std::string& dst_root, std::size_t n);
// Writes body_tum.txt (TUM: t x y z qx qy qz qw) as an ASL state_groundtruth_estimate0/data.csv
// (ns, p, q_w q_x q_y q_z, then zero velocity and biases) under <euroc_root>/mav0.
void write_euroc_groundtruth_csv(const std::string& tum_path, const std::string& euroc_root);
// Keeps the first `bytes` bytes of a file.
void truncate_file(const std::string& path, std::size_t bytes);

}  // namespace sbaslam::test
