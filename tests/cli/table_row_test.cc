// bench/table_row.sh: every results table's row is a real eval's "all" line,
// and a row that cannot be measured says so instead of showing empty cells.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "cli/cli_test_util.h"
#include "test_paths.h"

namespace m2d {
namespace {

namespace fs = std::filesystem;

using testing::CommandResult;
using testing::RunCommand;
using testing::RunMimic2d;

class TableRowTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("table_row"); }

  // Sources the script (as the bench tables do, under `set -euo
  // pipefail`) and runs `call`, written to a file so that names with
  // spaces need no second level of quoting.
  // `settings` (shell assignments) come after the source, before the
  // header.
  CommandResult Run(const std::string& call,
                    const std::string& settings = "") const {
    const std::string driver = dir_ + "/driver.sh";
    std::ofstream(driver) << "set -euo pipefail\n"
                          << "TABLE_BIN=" << MIMIC2D_BINARY << "\n"
                          << "source "
                          << testing::SourcePath("bench/table_row.sh") << "\n"
                          << settings << "\n"
                          << "table_header\n"
                          << call << "\n";
    return RunCommand("bash " + driver);
  }

  // 1 s of `walk` (a DeepMimic clip) seen by one camera, and the table_row
  // call that evaluates the walk policy on it from the truth's starts and
  // cameras, as the row `name`.
  std::string WalkRowCall(const std::string& walk,
                          const std::string& name) const {
    const std::string bundle = dir_ + "/walk.json";
    EXPECT_EQ(RunMimic2d("clip from-motion " + walk +
                         " --views 1 --duration 1 -o " + bundle)
                  .exit_code,
              0);
    return "table_row " + name + " walk clean " +
           testing::SourcePath("assets/policies/walk/checkpoint.pt") + " " +
           dir_ + "/walk_row --bundle " + bundle +
           " --episodes 1 --episode-s 1 --starts truth --cameras truth";
  }

  std::string dir_;
};

TEST_F(TableRowTest, ARowIsTheEvalsAllLine) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  CommandResult result = Run(WalkRowCall(walk, "'the walk (truth starts)'"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Succ, E2D, E3D, root-relative, PA and Jitter: all measured (the truth
  // starts and cameras share the truth's world, so global E3D exists).
  const std::regex row(
      R"(\| the walk \(truth starts\) \| walk \| clean \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \|)");
  EXPECT_TRUE(std::regex_search(result.output, row)) << result.output;
  EXPECT_TRUE(fs::exists(dir_ + "/walk_row.json"));
  EXPECT_TRUE(fs::exists(dir_ + "/walk_row.txt"));
}

// TABLE_OBJECTS=1 (bench/ball_table.sh) adds the ball's EO2D after E2D, in
// the header, the rows and a missing checkpoint's empty cells alike.
TEST_F(TableRowTest, WithObjectsTheTableCarriesEO2D) {
  M2D_REQUIRE_SHARED(walk, "deepmimic/motions/humanoid3d_walk.txt");
  CommandResult result =
      Run(WalkRowCall(walk, "walk") + "\ntable_row ours walk clean " + dir_ +
              "/none.pt " + dir_ + "/none",
          "TABLE_OBJECTS=1");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("| E2D (px) | EO2D (px) | E3D (mm) |"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("|---|---|---|---|---|---|---|---|---|---|\n"),
            std::string::npos)
      << result.output;
  // This walk has no ball: its EO2D cell is the eval's "-".
  const std::regex row(
      R"(\| walk \| walk \| clean \| [0-9.]+ \| [0-9.]+ \| - \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \|)");
  EXPECT_TRUE(std::regex_search(result.output, row)) << result.output;
  EXPECT_NE(result.output.find("/none.pt) | | | | | | |"), std::string::npos)
      << result.output;
}

TEST_F(TableRowTest, AMissingCheckpointsRowSaysSoAndTheTableGoesOn) {
  CommandResult result = Run("table_row ours walk clean " + dir_ + "/none.pt " +
                             dir_ + "/none --bundle x.json\necho after");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("| ours | walk | clean | (no checkpoint " +
                               dir_ + "/none.pt) |"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("after"), std::string::npos) << result.output;
}

TEST_F(TableRowTest, AFailedEvalStopsTheTableAndNamesItsLog) {
  const std::string policy =
      testing::SourcePath("assets/policies/walk/checkpoint.pt");
  const std::string missing = dir_ + "/missing.json";
  CommandResult result =
      Run("table_row ours walk clean " + policy + " " + dir_ +
          "/failed --bundle " + missing + "\necho after");
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("see " + dir_ + "/failed.txt"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find(missing), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("after"), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("| ours |"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace m2d
