// The semantic-gaze maker keeps geometric cues only on the 13 static Cityscapes classes.

#include "sbaslam/saliency/salient_dataset.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"

namespace sbaslam::saliency {
namespace {

// Random grey blocks with sharp edges and corners everywhere (a seeded "city" texture).
cv::Mat textured_image(cv::Size size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> grey(20, 235), pos(0, 10000), extent(6, 30);
  cv::Mat image(size, CV_8U, cv::Scalar(128));
  for (int i = 0; i < 400; ++i) {
    const cv::Rect r(pos(rng) % size.width, pos(rng) % size.height, extent(rng), extent(rng));
    cv::rectangle(image, r, cv::Scalar(grey(rng)), cv::FILLED);
  }
  return image;
}

// Left half building (11), right half car (26).
cv::Mat half_car_labels(cv::Size size) {
  cv::Mat labels(size, CV_8U, cv::Scalar(11));
  labels(cv::Rect(size.width / 2, 0, size.width - size.width / 2, size.height)).setTo(26);
  return labels;
}

TEST(SalientDataset, TheThirteenStaticClasses) {
  int count = 0;
  for (int id = 0; id < 256; ++id) count += is_static_class(static_cast<std::uint8_t>(id));
  EXPECT_EQ(count, 13);
  for (int id : {7, 8, 9, 10, 11, 13, 15, 17, 18, 19, 20, 21, 22})
    EXPECT_TRUE(is_static_class(static_cast<std::uint8_t>(id))) << id;
  for (int id : {0, 6, 12, 14, 16, 23, 24, 25, 26, 27, 28, 33})
    EXPECT_FALSE(is_static_class(static_cast<std::uint8_t>(id))) << id;
}

TEST(SalientDataset, NoFixationAndNoDensityOnACar) {
  const cv::Size size(320, 160);
  const cv::Mat image = textured_image(size, 3);
  const SalientDatasetOptions options;
  const SalientSample sample = make_salient_sample(image, half_car_labels(size), options);

  // Cues exist on both halves before the filter...
  int unfiltered_right = 0;
  for (const cv::Point2f& p : geometric_points(image, options)) unfiltered_right += p.x >= 160;
  EXPECT_GT(unfiltered_right, 100);
  // ...but none on the car is kept (not even on its border: boundary_margin).
  ASSERT_GT(sample.kept.size(), 100u);
  for (const cv::Point2f& p : sample.kept) EXPECT_LT(p.x, 160.0f - options.boundary_margin + 0.5f);
  EXPECT_EQ(cv::countNonZero(sample.fixations(cv::Rect(160, 0, 160, 160))), 0);
  EXPECT_GT(cv::countNonZero(sample.fixations(cv::Rect(0, 0, 160, 160))), 100);

  // Density: peak 255 on the building; beyond 3 sigma into the car it is ~0.
  double max_value = 0;
  cv::minMaxLoc(sample.density, nullptr, &max_value);
  EXPECT_EQ(max_value, 255.0);
  const int beyond = 160 + static_cast<int>(3 * options.sigma_fraction * size.width) + 1;
  double car_max = 0;
  cv::minMaxLoc(sample.density(cv::Rect(beyond, 0, size.width - beyond, 160)), nullptr, &car_max);
  EXPECT_LE(car_max, 3.0);
  EXPECT_GT(cv::mean(sample.density(cv::Rect(0, 0, 140, 160)))[0], 50.0);
  // The unfiltered baseline keeps the car's cues.
  EXPECT_GT(cv::mean(sample.unfiltered_density(cv::Rect(beyond, 0, size.width - beyond, 160)))[0],
            50.0);
}

TEST(SalientDataset, DensityIsAGaussianSplat) {
  SalientDatasetOptions options;
  options.sigma_fraction = 0.05;  // 5 px on 100 px
  const cv::Mat d = density_map({{50.0f, 20.0f}}, cv::Size(100, 40), options);
  EXPECT_EQ(d.at<std::uint8_t>(20, 50), 255);
  EXPECT_NEAR(d.at<std::uint8_t>(20, 55), 255 * std::exp(-0.5), 2.0);  // one sigma away
  EXPECT_EQ(cv::countNonZero(density_map({}, cv::Size(10, 10), options)), 0);
}

TEST(SalientDataset, WritesMapsFixationsAndIndexFromFolders) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "img");
  std::filesystem::create_directories(dir.path() / "lab");
  const cv::Size size(160, 80);
  for (const char* name : {"a", "b"}) {
    cv::imwrite(dir.file(std::string("img/") + name + ".png"), textured_image(size, 5));
    cv::imwrite(dir.file(std::string("lab/") + name + ".png"), half_car_labels(size));
  }
  const auto pairs = pairs_from_folders(dir.file("img"), dir.file("lab"));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(write_salient_dataset(pairs, dir.file("out"), SalientDatasetOptions{}), 2);
  for (const char* sub : {"maps", "fixations", "unfiltered"}) {
    const cv::Mat m =
        cv::imread(dir.file(std::string("out/") + sub + "/b.png"), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(m.empty()) << sub;
    EXPECT_EQ(m.size(), size);
    EXPECT_EQ(m.type(), CV_8UC1);
  }
  std::ifstream csv(dir.file("out/dataset.csv"));
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 3);
}

TEST(SalientDataset, MissingLabelOrWrongSizeIsAnError) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "img");
  std::filesystem::create_directories(dir.path() / "lab");
  cv::imwrite(dir.file("img/a.png"), textured_image({64, 32}, 1));
  try {
    pairs_from_folders(dir.file("img"), dir.file("lab"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no label map"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_salient_sample(textured_image({64, 32}, 1), cv::Mat(16, 16, CV_8U), {}), Error);
  EXPECT_THROW(pairs_from_simulation(dir.file("img")), Error);
}

}  // namespace
}  // namespace sbaslam::saliency
