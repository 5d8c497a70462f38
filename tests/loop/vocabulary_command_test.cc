// The `sba-slam vocabulary train` CLI: the summary line and a loadable file; errors as one line.

#include <gtest/gtest.h>

#include <string>

#include "helper/cli.h"
#include "helper/temp_dir.h"
#include "sbaslam/loop/vocabulary.h"

namespace sbaslam {
namespace {

using test::first_line;
using test::run_cli;

const std::string kKittiImages =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0";

TEST(VocabularyCommand, TrainsAndPrintsAOneLineSummary) {
  test::TempDir dir;
  const std::string voc = dir.file("kitti.voc"), out = dir.file("out.txt");
  ASSERT_EQ(run_cli("vocabulary train --images " + kKittiImages + " --images " + kKittiImages +
                        " --every 25 --branching 5 --levels 2 --max-features 300 --out " + voc,
                    out),
            0)
      << first_line(out);
  const std::string line = first_line(out);
  EXPECT_NE(line.find("vocabulary: 6 images"), std::string::npos) << line;
  const loop::Vocabulary loaded = loop::Vocabulary::load(voc);
  EXPECT_EQ(loaded.branching(), 5);
  EXPECT_EQ(loaded.levels(), 2);
  EXPECT_NE(line.find(std::to_string(loaded.word_count()) + " words"), std::string::npos) << line;
}

TEST(VocabularyCommand, FailsWithOneLineOnBadInput) {
  test::TempDir dir;
  const std::string out = dir.file("out.txt");
  EXPECT_EQ(
      run_cli("vocabulary train --images " + dir.file("none") + " --out " + dir.file("x.voc"), out),
      1);
  EXPECT_EQ(first_line(out), "sba-slam: error: " + dir.file("none") + ": not a folder");
  test::write_text_file(dir.file("bad/000000.png"), "not a png");
  EXPECT_EQ(
      run_cli("vocabulary train --images " + dir.file("bad") + " --out " + dir.file("x.voc"), out),
      1);
  EXPECT_NE(first_line(out).find("000000.png: cannot decode"), std::string::npos)
      << first_line(out);
  EXPECT_NE(run_cli("vocabulary train --images " + kKittiImages, out), 0);  // no --out
}

}  // namespace
}  // namespace sbaslam
