// sba-slam saliency make-dataset --images DIR --stable CSV: samples from a SLAM run's stable
// features, on the real KITTI and EuRoC image folders (read in place, never copied).

#include "sbaslam/saliency/stable_dataset.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "helper/cli.h"
#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam::saliency {
namespace {

using test::first_line;
using test::run_cli;

const std::string kKittiImages =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0";
const std::string kEurocImages =
    std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro/mav0/cam0/data";
const std::string kHeader = "timestamp,image,x,y,octave,point_id,observations,mean_error_px\n";

int lines_in(const std::string& path) {
  std::ifstream in(path);
  int n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

TEST(StableDataset, KittiSamplesPutTheDensityOnTheStableFeatures) {
  test::TempDir dir;
  test::write_text_file(dir.file("stable.csv"),
                        kHeader +
                            "0.000000000,000000.png,300.4,200.25,0,1,4,0.3\n"
                            "0.000000000,000000.png,900,100,2,2,5,0.6\n"
                            "0.103000000,000002.png,600,180,1,1,4,0.3\n");
  ASSERT_EQ(run_cli("saliency make-dataset --images " + kKittiImages + " --stable " +
                        dir.file("stable.csv") + " --out " + dir.file("ds"),
                    dir.file("log.txt")),
            0)
      << first_line(dir.file("log.txt"));
  EXPECT_EQ(lines_in(dir.file("ds/dataset.csv")), 3);  // header + 2 images
  const cv::Mat fixations = cv::imread(dir.file("ds/fixations/000000.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(fixations.size(), cv::Size(1226, 370));
  EXPECT_EQ(cv::countNonZero(fixations), 2);
  EXPECT_EQ(fixations.at<std::uint8_t>(200, 300), 255);  // rounded to the nearest pixel
  EXPECT_EQ(fixations.at<std::uint8_t>(100, 900), 255);
  const cv::Mat density = cv::imread(dir.file("ds/maps/000002.png"), cv::IMREAD_UNCHANGED);
  // One point: its pixel is the (8-bit, so possibly shared) maximum, far pixels are zero.
  EXPECT_EQ(density.at<std::uint8_t>(180, 600), 255);
  EXPECT_EQ(density.at<std::uint8_t>(20, 100), 0);
  // The unfiltered map is every geometric cue of the image, not just the stable ones.
  const cv::Mat unfiltered = cv::imread(dir.file("ds/unfiltered/000000.png"), cv::IMREAD_UNCHANGED);
  EXPECT_GT(cv::countNonZero(unfiltered), 1226 * 370 / 2);
  std::ifstream csv(dir.file("ds/dataset.csv"));
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(header, "image,labels,map,fixations,unfiltered,kept_points,total_points");
  EXPECT_EQ(row.rfind(kKittiImages + "/000000.png,", 0), 0u) << row;
  EXPECT_NE(row.find(",maps/000000.png,fixations/000000.png,unfiltered/000000.png,2,"),
            std::string::npos)
      << row;
}

TEST(StableDataset, EurocImageFolderByNanosecondNames) {
  test::TempDir dir;
  test::write_text_file(
      dir.file("stable.csv"),
      kHeader + "1403715273.262142976,1403715273262142976.png,376,240,0,8,4,0.2\n");
  EXPECT_EQ(write_stable_dataset(kEurocImages, dir.file("stable.csv"), dir.file("ds"),
                                 SalientDatasetOptions()),
            1);
  const cv::Mat fixations =
      cv::imread(dir.file("ds/fixations/1403715273262142976.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(fixations.size(), cv::Size(752, 480));
  EXPECT_EQ(fixations.at<std::uint8_t>(240, 376), 255);
}

TEST(StableDataset, ErrorsNameTheFile) {
  test::TempDir dir;
  const SalientDatasetOptions options;
  test::expect_error_naming(
      [&] { write_stable_dataset(kKittiImages, dir.file("none.csv"), dir.file("o"), options); },
      "none.csv: cannot read");
  test::write_text_file(dir.file("gone.csv"), kHeader +
                                                  "0.0,000000.png,1,1,0,1,4,0.1\n"
                                                  "0.1,999999.png,1,1,0,1,4,0.1\n");
  test::expect_error_naming(
      [&] { write_stable_dataset(kKittiImages, dir.file("gone.csv"), dir.file("o"), options); },
      "999999.png: image listed in " + dir.file("gone.csv") + " not found");
  test::write_text_file(dir.file("empty.csv"), kHeader);
  test::expect_error_naming(
      [&] { write_stable_dataset(kKittiImages, dir.file("empty.csv"), dir.file("o"), options); },
      "empty.csv: no stable features");

  // Through the CLI: one line, exit code 1.
  test::write_text_file(dir.file("bad.csv"), kHeader + "0.0,000000.png,1,1,0,1,4,0.1\n0.1,x\n");
  const std::string log = dir.file("log.txt");
  EXPECT_EQ(run_cli("saliency make-dataset --images " + kKittiImages + " --stable " +
                        dir.file("bad.csv") + " --out " + dir.file("o"),
                    log),
            1);
  EXPECT_NE(first_line(log).find("bad.csv:3: expected 8 comma-separated fields"), std::string::npos)
      << first_line(log);
  EXPECT_EQ(lines_in(log), 1);
  EXPECT_EQ(run_cli("saliency make-dataset --images " + kKittiImages + " --stable " +
                        dir.file("gone.csv") + " --out " + dir.file("o"),
                    log),
            1);
  EXPECT_NE(first_line(log).find("999999.png: image listed in"), std::string::npos)
      << first_line(log);
  EXPECT_EQ(
      run_cli("saliency make-dataset --images " + kKittiImages + " --stable " +
                  dir.file("bad.csv") + " --labels " + dir.file("l") + " --out " + dir.file("o"),
              log),
      1);
  EXPECT_NE(first_line(log).find("either --labels"), std::string::npos) << first_line(log);
}

}  // namespace
}  // namespace sbaslam::saliency
