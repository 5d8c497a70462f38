#include "sbaslam/io/velodyne_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam::io {
namespace {

std::vector<VelodynePoint> three_points() {
  std::vector<VelodynePoint> scan(3);
  for (int i = 0; i < 3; ++i) {
    scan[i].xyz = Eigen::Vector3f(10.0f + i, -2.5f * i, 0.25f - i);
    scan[i].reflectance = 0.1f * i;
  }
  return scan;
}

TEST(VelodyneScan, WrittenScanReadsBackAsKittiLaysItOut) {
  test::TempDir dir;
  write_velodyne_scan(dir.file("000000.bin"), three_points());
  std::ifstream raw(dir.file("000000.bin"), std::ios::binary);
  float first[4];
  raw.read(reinterpret_cast<char*>(first), sizeof(first));
  EXPECT_EQ(first[0], 10.0f);  // x, y, z, reflectance as float32
  EXPECT_EQ(first[3], 0.0f);
  const std::vector<VelodynePoint> scan = read_velodyne_scan(dir.file("000000.bin"));
  ASSERT_EQ(scan.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(scan[i].xyz, three_points()[i].xyz);
    EXPECT_EQ(scan[i].reflectance, three_points()[i].reflectance);
  }
}

TEST(VelodyneScan, BadFilesAreErrorsNamingTheFile) {
  test::TempDir dir;
  EXPECT_NE(test::error_message([&] {
              read_velodyne_scan(dir.file("none.bin"));
            }).find("none.bin: cannot open"),
            std::string::npos);

  write_velodyne_scan(dir.file("cut.bin"), three_points());
  std::ofstream(dir.file("cut.bin"), std::ios::app | std::ios::binary) << "abc";
  EXPECT_NE(test::error_message([&] {
              read_velodyne_scan(dir.file("cut.bin"));
            }).find("cut.bin: 51 bytes is not a whole number of 16-byte points"),
            std::string::npos);

  auto scan = three_points();
  scan[1].xyz.y() = std::numeric_limits<float>::quiet_NaN();
  write_velodyne_scan(dir.file("nan.bin"), scan);
  EXPECT_NE(test::error_message([&] {
              read_velodyne_scan(dir.file("nan.bin"));
            }).find("nan.bin: point 1 has a non-finite coordinate"),
            std::string::npos);

  std::ofstream(dir.file("empty.bin"), std::ios::binary).close();
  EXPECT_TRUE(read_velodyne_scan(dir.file("empty.bin")).empty());
}

}  // namespace
}  // namespace sbaslam::io
