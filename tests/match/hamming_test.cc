#include "sbaslam/match/hamming.h"

#include <gtest/gtest.h>

#include <bitset>
#include <opencv2/core.hpp>
#include <random>

namespace sbaslam::match {
namespace {

int naive_distance(const std::uint8_t* a, const std::uint8_t* b) {
  int d = 0;
  for (int i = 0; i < kDescriptorBytes; ++i)
    d += static_cast<int>(std::bitset<8>(a[i] ^ b[i]).count());
  return d;
}

TEST(Hamming, AgreesWithBitCountAndOpenCv) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  cv::Mat a(200, kDescriptorBytes, CV_8U), b(200, kDescriptorBytes, CV_8U);
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < kDescriptorBytes; ++c) {
      a.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(byte(rng));
      // Rows share more and more bits so that small and large distances both occur.
      b.at<std::uint8_t>(r, c) =
          c < r % 33 ? static_cast<std::uint8_t>(byte(rng)) : a.at<std::uint8_t>(r, c);
    }
  for (int r = 0; r < a.rows; ++r) {
    const int d = descriptor_distance(a.ptr<std::uint8_t>(r), b.ptr<std::uint8_t>(r));
    EXPECT_EQ(d, naive_distance(a.ptr<std::uint8_t>(r), b.ptr<std::uint8_t>(r)));
    EXPECT_EQ(d, static_cast<int>(cv::norm(a.row(r), b.row(r), cv::NORM_HAMMING)));
  }
}

TEST(Hamming, ExtremeDistances) {
  std::uint8_t zeros[kDescriptorBytes] = {}, ones[kDescriptorBytes];
  for (auto& v : ones) v = 0xff;
  EXPECT_EQ(descriptor_distance(zeros, zeros), 0);
  EXPECT_EQ(descriptor_distance(zeros, ones), kMaxDescriptorDistance);
  EXPECT_EQ(descriptor_distance(ones, ones), 0);
}

}  // namespace
}  // namespace sbaslam::match
