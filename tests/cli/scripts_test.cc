// scripts/private_binary.sh: the dataset scripts run a copy of the binary.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli/cli_test_util.h"
#include "test_paths.h"

namespace m2d {
namespace {

namespace fs = std::filesystem;

// A script in <root>/scripts/ that takes its copy, then has build/mimic2d
// removed under it (a rebuild in progress) before it runs the copy, once
// in a background job, as make_dataset.sh's fits run, and once in the
// script itself.
constexpr char kDriver[] = R"(set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/private_binary.sh
private_binary
echo "copy $bin"
rm -f build/mimic2d
"$bin" &
wait
"$bin"
)";

class PrivateBinaryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::TempDir("private_binary");
    fs::remove_all(root_);
    fs::create_directories(root_ + "/scripts");
    fs::create_directories(root_ + "/build");
    fs::copy_file(testing::SourcePath("scripts/private_binary.sh"),
                  root_ + "/scripts/private_binary.sh");
    std::ofstream(root_ + "/scripts/driver.sh") << kDriver;
  }

  void MakeBinary() const {
    const std::string path = root_ + "/build/mimic2d";
    std::ofstream(path) << "#!/bin/sh\necho ran the build\n";
    fs::permissions(path, fs::perms::owner_all, fs::perm_options::add);
  }

  testing::CommandResult RunDriver() const {
    return testing::RunCommand("bash " + root_ + "/scripts/driver.sh");
  }

  std::string root_;
};

TEST_F(PrivateBinaryTest, ACopyRunsWhileTheBuildIsReplacedAndGoesAtExit) {
  MakeBinary();
  const testing::CommandResult result = RunDriver();
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Both runs used the copy, though build/mimic2d was gone.
  size_t runs = 0;
  for (size_t at = result.output.find("ran the build"); at != std::string::npos;
       at = result.output.find("ran the build", at + 1)) {
    ++runs;
  }
  EXPECT_EQ(runs, 2u) << result.output;
  // The copy is removed when the script exits (not when its background job
  // does: that one ran before the second run).
  const size_t start = result.output.find("copy ");
  ASSERT_NE(start, std::string::npos) << result.output;
  const std::string copy = result.output.substr(
      start + 5, result.output.find('\n', start) - start - 5);
  EXPECT_FALSE(copy.empty());
  EXPECT_FALSE(fs::exists(copy)) << copy;
}

TEST_F(PrivateBinaryTest, AMissingBuildIsNamed) {
  const testing::CommandResult result = RunDriver();
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("driver.sh: build/mimic2d not built"),
            std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace m2d
