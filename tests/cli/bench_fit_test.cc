// End-to-end checks of `mimic2d bench fit`: the quick table runs a real fit
// and prints a row of finite figures and a JSON file; a bad clip name is a
// named error.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "cli/cli_test_util.h"
#include "common/file_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

using BenchResult = testing::CommandResult;
using testing::RunMimic2d;

// The table line that starts with `prefix`, or "".
std::string LineStartingWith(const std::string& text,
                             const std::string& prefix) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.compare(0, prefix.size(), prefix) == 0) return line;
  }
  return "";
}

TEST(CliBenchFit, QuickPrintsARowOfFiniteFigures) {
  const std::string dir = testing::TempDir("cli_bench_fit");
  const std::string json_path = dir + "/table.json";
  const BenchResult result =
      RunMimic2d("bench fit --quick --from-truth -o " + json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("[1/1] walk, setting A, clean, view 1/1"),
            std::string::npos)
      << result.output;
  // "walk A clean 1/1 <frames> <10 figures>"
  const std::string row = LineStartingWith(result.output, "walk ");
  ASSERT_FALSE(row.empty()) << result.output;
  std::istringstream fields(row);
  std::string clip, setting, noise, fits;
  int frames = 0;
  fields >> clip >> setting >> noise >> fits >> frames;
  EXPECT_EQ(setting, "A");
  EXPECT_EQ(noise, "clean");
  EXPECT_EQ(fits, "1/1");
  EXPECT_GT(frames, 30);
  int figures = 0;
  std::string field;
  while (fields >> field) {
    const double value = std::stod(field);
    EXPECT_TRUE(std::isfinite(value)) << row;
    EXPECT_GE(value, 0.0) << row;
    ++figures;
  }
  EXPECT_EQ(figures, 10) << row;
  EXPECT_FALSE(LineStartingWith(result.output, "all ").empty())
      << result.output;

  // --from-truth: the refinement from the truth, per view and in a line.
  EXPECT_NE(result.output.find("    from the truth (cost there "),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(
      LineStartingWith(result.output, "from the truth (stages 2-3").empty())
      << result.output;

  const nlohmann::json json = ReadJsonFile(json_path);
  EXPECT_EQ(json["format"], "mimic2d.bench_fit");
  ASSERT_EQ(json["rows"].size(), 1u);
  ASSERT_EQ(json["rows"][0]["from_truth"].size(), 1u);
  const double truth_started_pa =
      json["rows"][0]["from_truth"][0]["pa_mpjpe_mm"].get<double>();
  EXPECT_GT(truth_started_pa, 0.0);
  EXPECT_LT(truth_started_pa, 60.0);  // the walk: 34 mm when written
  const nlohmann::json& mean = json["rows"][0]["mean"];
  for (const char* key :
       {"focal_error_pct", "pitch_error_deg", "roll_error_deg",
        "root_relative_mpjpe_mm", "pa_mpjpe_mm", "mean_reprojection_px",
        "seconds_per_100_frames", "cpu_seconds_per_100_frames"}) {
    ASSERT_TRUE(mean.contains(key)) << key;
    EXPECT_TRUE(std::isfinite(mean[key].get<double>())) << key;
  }
}

TEST(CliBenchFit, AnUnknownClipIsNamed) {
  const BenchResult result = RunMimic2d("bench fit --clips walk,moonwalk");
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("moonwalk"), std::string::npos) << result.output;
  // Rejected before any fit runs.
  EXPECT_EQ(result.output.find("[1/"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace m2d
