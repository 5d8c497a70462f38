// Training a vocabulary from image folders (the library side of `sba-slam vocabulary train`) on
// the KITTI fixture, and its one-line errors.

#include "sbaslam/loop/vocabulary_training.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam::loop {
namespace {

const std::string kKittiImages =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0";

VocabularyTrainingOptions small_options(int every) {
  VocabularyTrainingOptions o;
  o.vocabulary.branching = 6;
  o.vocabulary.levels = 3;
  o.max_features = 500;
  o.every = every;
  return o;
}

TEST(VocabularyTraining, TrainsOnEveryNthImageOfEachFolderAndSaves) {
  test::TempDir dir;
  const std::string out = dir.file("kitti.voc");
  // Frames 0, 25 and 50 of the 51, from the folder given twice.
  const VocabularyTrainingReport report =
      train_vocabulary_from_folders({kKittiImages, kKittiImages + "/"}, small_options(25), out);
  EXPECT_EQ(report.images, 6u);
  EXPECT_NEAR(static_cast<double>(report.descriptors), 6 * 500,
              300);  // ORB-SLAM's count is approximate
  EXPECT_GT(report.words, 150u);
  EXPECT_LE(report.words, 216u);  // 6^3
  EXPECT_EQ(report.file_bytes, std::filesystem::file_size(out));
  EXPECT_GT(report.seconds, 0.0);
  const Vocabulary loaded = Vocabulary::load(out);
  EXPECT_EQ(loaded.word_count(), report.words);
  EXPECT_EQ(loaded.branching(), 6);
  EXPECT_EQ(loaded.levels(), 3);
  const std::string line = report.summary(out);
  EXPECT_NE(line.find("6 images"), std::string::npos) << line;
  EXPECT_NE(line.find(out), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
}

TEST(VocabularyTraining, BadInputFailsNamingIt) {
  test::TempDir dir;
  const std::string out = dir.file("out.voc");
  const std::string missing = dir.file("missing");
  test::expect_error_naming(
      [&] {
        train_vocabulary_from_folders({kKittiImages, missing}, small_options(1), out);
      },
      missing + ": not a folder");
  std::filesystem::create_directories(dir.path() / "empty");
  test::write_text_file(dir.file("empty/notes.txt"), "no images here\n");
  test::expect_error_naming(
      [&] { train_vocabulary_from_folders({dir.file("empty")}, small_options(1), out); },
      dir.file("empty") + ": no .png or .jpg images");
  test::write_text_file(dir.file("corrupt/000000.png"), "not a png");
  test::expect_error_naming(
      [&] { train_vocabulary_from_folders({dir.file("corrupt")}, small_options(1), out); },
      "000000.png: cannot decode");
  const std::string unwritable = dir.file("no/such/folder/out.voc");
  test::expect_error_naming(
      [&] { train_vocabulary_from_folders({kKittiImages}, small_options(50), unwritable); },
      unwritable);
  test::expect_error_naming(
      [&] { train_vocabulary_from_folders({kKittiImages}, small_options(0), out); }, "every");
  test::expect_error_naming([&] { train_vocabulary_from_folders({}, small_options(1), out); },
                            "no image folder");
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace sbaslam::loop
