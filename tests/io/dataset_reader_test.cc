#include <gtest/gtest.h>

#include "helper/fixture_copy.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"
#include "sbaslam/io/dataset.h"

namespace sbaslam::io {
namespace {

TEST(DatasetReaderTest, UnknownKindIsAnError) {
  try {
    make_dataset_reader("kitty", test::kitti_fixture_sequence_dir());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown dataset kind 'kitty'"), std::string::npos)
        << e.what();
  }
}

TEST(DatasetReaderTest, MissingFolderIsAnError) {
  test::TempDir tmp;
  const std::string missing = tmp.file("none");
  for (const char* kind : {"kitti", "euroc", "tum"}) {
    try {
      make_dataset_reader(kind, missing);
      ADD_FAILURE() << kind;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
  }
}

TEST(DatasetReaderTest, StampsMustIncrease) {
  EXPECT_NO_THROW(check_increasing_stamps({0.0, 0.1, 0.2}, "f"));
  EXPECT_THROW(check_increasing_stamps({0.0, 0.2, 0.1}, "f"), Error);
  EXPECT_THROW(check_increasing_stamps({0.0, 0.1, 0.1}, "f"), Error);
}

}  // namespace
}  // namespace sbaslam::io
