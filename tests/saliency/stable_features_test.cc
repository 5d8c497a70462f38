// The stability gate and stable_features.csv, on hand-made tracks (no map involved).

#include "sbaslam/saliency/stable_features.h"

#include <gtest/gtest.h>

#include <limits>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"

namespace sbaslam::saliency {
namespace {

// A track seen by `keyframes` keyframes 0.1 s apart, every observation with the same error.
PointTrack track(std::size_t id, int keyframes, double error_px, double level_sigma = 1.0) {
  PointTrack t;
  t.point_id = id;
  for (int k = 0; k < keyframes; ++k) {
    PointObservation o;
    o.timestamp = 0.1 * k;
    o.image = "00000" + std::to_string(k) + ".png";
    o.x = 10.0f + static_cast<float>(id);
    o.y = 20.0f + static_cast<float>(k);
    o.error_px = error_px;
    o.level_sigma = level_sigma;
    t.observations.push_back(o);
  }
  return t;
}

TEST(StableFeatures, GateNeedsEnoughKeyframesAndASmallNormalisedError) {
  const StabilityGate gate;  // 4 keyframes, chi2 5.991 (2.448 sigma)
  EXPECT_TRUE(is_stable(track(0, 4, 1.0), gate));
  EXPECT_FALSE(is_stable(track(1, 3, 1.0), gate));      // too few keyframes
  EXPECT_FALSE(is_stable(track(2, 6, 2.5), gate));      // 2.5^2 = 6.25 > 5.991
  EXPECT_TRUE(is_stable(track(3, 6, 2.5, 1.2), gate));  // 2.08 sigma at level 1
  EXPECT_TRUE(is_stable(track(4, 5, 2.4), gate));       // 5.76 < 5.991
  EXPECT_FALSE(is_stable(track(5, 0, 0.0), gate));      // no observation
  PointTrack behind = track(6, 5, 0.5);
  behind.observations[2].error_px = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(is_stable(behind, gate));
  // The gate is on the mean: one large error among small ones passes.
  PointTrack one_outlier = track(7, 5, 0.5);
  one_outlier.observations[0].error_px = 5.0;  // mean 1.4
  EXPECT_TRUE(is_stable(one_outlier, gate));
  StabilityGate strict;
  strict.min_observations = 6;
  EXPECT_FALSE(is_stable(track(8, 5, 0.1), strict));
}

TEST(StableFeatures, SelectionGivesOneRowPerObservationOrderedByKeyframe) {
  const std::vector<PointTrack> tracks = {track(9, 5, 1.0), track(3, 2, 0.1), track(4, 4, 0.5)};
  const std::vector<StableFeature> rows = select_stable_features(tracks, StabilityGate());
  ASSERT_EQ(rows.size(), 9u);  // 5 + 4 observations; the 2-keyframe point is left out
  EXPECT_EQ(rows[0].point_id, 4u);
  EXPECT_EQ(rows[1].point_id, 9u);
  EXPECT_DOUBLE_EQ(rows[0].timestamp, 0.0);
  EXPECT_EQ(rows[0].image, "000000.png");
  EXPECT_EQ(rows[0].observations, 4);
  EXPECT_DOUBLE_EQ(rows[0].mean_error_px, 0.5);
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_LE(rows[i - 1].timestamp, rows[i].timestamp);
}

TEST(StableFeatures, CsvRoundTrip) {
  test::TempDir dir;
  std::vector<StableFeature> rows =
      select_stable_features({track(1, 4, 0.25), track(2, 5, 1.5, 1.44)}, StabilityGate());
  rows[0].timestamp = 1403715273.262143;  // EuRoC-size stamps keep microseconds
  rows[0].octave = 3;
  rows[0].image = "1403715273262142976.png";
  write_stable_features_csv(dir.file("stable_features.csv"), rows);
  const std::vector<StableFeature> back = read_stable_features_csv(dir.file("stable_features.csv"));
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, rows[i].timestamp, 1e-6);
    EXPECT_EQ(back[i].image, rows[i].image);
    EXPECT_NEAR(back[i].x, rows[i].x, 1e-3);
    EXPECT_NEAR(back[i].y, rows[i].y, 1e-3);
    EXPECT_EQ(back[i].octave, rows[i].octave);
    EXPECT_EQ(back[i].point_id, rows[i].point_id);
    EXPECT_EQ(back[i].observations, rows[i].observations);
    EXPECT_NEAR(back[i].mean_error_px, rows[i].mean_error_px, 1e-4);
  }
  write_stable_features_csv(dir.file("empty.csv"), {});
  EXPECT_TRUE(read_stable_features_csv(dir.file("empty.csv")).empty());
}

TEST(StableFeatures, BadCsvGivesOneLineErrorNamingFileAndLine) {
  test::TempDir dir;
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("missing.csv")); },
                            "missing.csv: cannot read");
  const std::string header = "timestamp,image,x,y,octave,point_id,observations,mean_error_px\n";
  test::write_text_file(dir.file("header.csv"), "t,image,x,y\n");
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("header.csv")); },
                            "header.csv: not a stable-features csv");
  test::write_text_file(dir.file("short.csv"), header + "0.1,a.png,1,2,0,7,4,0.5\n0.2,a.png,1\n");
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("short.csv")); },
                            "short.csv:3: expected 8 comma-separated fields");
  test::write_text_file(dir.file("nan.csv"), header + "0.1,a.png,abc,2,0,7,4,0.5\n");
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("nan.csv")); },
                            "nan.csv:2: x 'abc' is not a finite number");
  test::write_text_file(dir.file("octave.csv"), header + "0.1,a.png,1,2,1.5,7,4,0.5\n");
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("octave.csv")); },
                            "octave.csv:2: octave '1.5' is not a non-negative integer");
  test::write_text_file(dir.file("neg.csv"), header + "0.1,a.png,-1,2,0,7,4,0.5\n");
  test::expect_error_naming([&] { read_stable_features_csv(dir.file("neg.csv")); },
                            "neg.csv:2: negative pixel position");
  test::expect_error_naming(
      [&] {
        StableFeature row;
        row.image = "a,b.png";
        write_stable_features_csv(dir.file("comma.csv"), {row});
      },
      "comma.csv: image name 'a,b.png' holds a comma");
}

}  // namespace
}  // namespace sbaslam::saliency
