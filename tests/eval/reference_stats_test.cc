// Every case of reference_stats.json (numbers printed by evo v1.36.5) is run through the CLI and
// must match to a relative error of 1e-6. A case added to the JSON is picked up automatically.

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/eval_test_support.h"

namespace sbaslam {
namespace {

constexpr double kMaxRelativeError = 1e-6;

struct ReferenceCase {
  std::string name;
  nlohmann::json spec;
};

nlohmann::json load_reference_json() {
  std::ifstream in(test::shared_trajectory("reference_stats.json"));
  if (!in) return nlohmann::json::object();
  return nlohmann::json::parse(in);
}

std::vector<ReferenceCase> load_reference_cases() {
  std::vector<ReferenceCase> cases;
  const nlohmann::json json = load_reference_json();
  if (!json.contains("cases")) return cases;
  for (const auto& [name, spec] : json["cases"].items()) cases.push_back({name, spec});
  return cases;
}

// The pose and pair counts stated in the JSON's "about": 4541 KITTI 00 poses, 4540 pairs at one
// frame, 35 consecutive pairs at 100 m. A case may also give "n" itself.
std::optional<std::size_t> expected_count(const nlohmann::json& spec) {
  if (spec.contains("n")) return spec["n"].get<std::size_t>();
  if (spec.value("format", "") != "kitti" || spec.value("reference", "") != "KITTI_00_gt.txt")
    return std::nullopt;
  if (spec["metric"] == "ape") return 4541;
  const bool consecutive = spec.value("pairs", "consecutive") == "consecutive";
  if (spec["delta_unit"] == "frames" && spec["delta"] == 1 && consecutive) return 4540;
  if (spec["delta_unit"] == "meters" && spec["delta"] == 100 && consecutive) return 35;
  return std::nullopt;
}

std::string delta_unit_flag(const std::string& unit) {
  if (unit == "frames") return "f";
  if (unit == "meters") return "m";
  return unit;  // let the CLI reject anything else
}

std::string number_text(const nlohmann::json& value) {
  return value.dump();
}

std::string cli_arguments(const nlohmann::json& spec, const std::string& json_out) {
  std::string args = "eval " + spec["metric"].get<std::string>() + " " +
                     test::quoted(test::shared_trajectory(spec["reference"])) + " " +
                     test::quoted(test::shared_trajectory(spec["estimate"])) + " --format " +
                     spec["format"].get<std::string>();
  args += " --align " + spec.value("align", "none");
  args += " --pose-relation " + spec.value("pose_relation", "trans_part");
  if (spec.contains("t_max_diff")) args += " --t-max-diff " + number_text(spec["t_max_diff"]);
  if (spec.contains("t_offset")) args += " --t-offset " + number_text(spec["t_offset"]);
  if (spec.contains("n_to_align")) args += " --n-to-align " + number_text(spec["n_to_align"]);
  if (spec["metric"] == "rpe") {
    args += " --delta " + number_text(spec["delta"]);
    args += " --delta-unit " + delta_unit_flag(spec["delta_unit"]);
    if (spec.value("pairs", "consecutive") == "all") args += " --all-pairs";
  }
  return args + " --json " + test::quoted(json_out);
}

class ReferenceStatsTest : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(ReferenceStatsTest, CliMatchesEvo) {
  const nlohmann::json& spec = GetParam().spec;
  test::TempDir dir;
  const std::string json_out = dir.file("stats.json");
  const test::CliRun run = test::run_cli(cli_arguments(spec, json_out));
  ASSERT_EQ(run.exit_code, 0) << run.output;

  const nlohmann::json result = nlohmann::json::parse(test::read_text_file(json_out));
  ASSERT_FALSE(spec["stats"].empty());
  for (const auto& [stat, expected_value] : spec["stats"].items()) {
    ASSERT_TRUE(result.contains(stat)) << "missing statistic " << stat;
    const double expected = expected_value.get<double>();
    const double actual = result[stat].get<double>();
    EXPECT_LE(std::abs(actual - expected), kMaxRelativeError * std::abs(expected))
        << stat << ": got " << actual << ", evo " << expected;
  }
  if (const auto n = expected_count(spec)) {
    EXPECT_EQ(result["n"].get<std::size_t>(), *n);
  }
}

std::string case_name(const ::testing::TestParamInfo<ReferenceCase>& info) {
  std::string name = info.param.name;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(EvoV1365, ReferenceStatsTest, ::testing::ValuesIn(load_reference_cases()),
                         case_name);

TEST(ReferenceStatsFile, HoldsCases) {
  // Guards against a silently empty suite when the fixture is missing or renamed.
  EXPECT_GE(load_reference_cases().size(), 8u);
}

}  // namespace
}  // namespace sbaslam
