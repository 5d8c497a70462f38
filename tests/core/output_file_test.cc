#include "sbaslam/core/output_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam {
namespace {

TEST(OutputFile, WritesTheWholeTextAndReplacesAnOlderFile) {
  const test::TempDir dir;
  const std::string path = dir.file("out.json");
  write_output_file(path, "a much longer first content\n");
  write_output_file(path, "{}\n");
  EXPECT_EQ(test::read_text_file(path), "{}\n");
}

TEST(OutputFile, AMissingFolderIsAnErrorNamingTheFile) {
  const test::TempDir dir;
  const std::string path = dir.file("no_such_folder/run.json");
  EXPECT_EQ(test::error_message([&] { write_output_file(path, "{}\n"); }),
            path + ": cannot open for writing");
}

// /dev/full accepts the open and refuses the data, as a full disk does.
TEST(OutputFile, AFullDiskIsAnErrorAtCloseNotAShortFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  const std::string text(1 << 16, 'x');
  EXPECT_EQ(test::error_message([&] { write_output_file("/dev/full", text); }),
            "/dev/full: write error");
  std::ofstream out = open_output_file("/dev/full");
  out << "one line\n";
  EXPECT_EQ(test::error_message([&] { close_output_file(out, "/dev/full"); }),
            "/dev/full: write error");
}

}  // namespace
}  // namespace sbaslam
