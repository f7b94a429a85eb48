// scripts/carry_run.sh: an unfinished training travels through git.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli/cli_test_util.h"
#include "test_paths.h"

namespace m2d {
namespace {

namespace fs = std::filesystem;

using testing::CommandResult;

// The script works from the folder above its own, so a copy in
// <root>/scripts/ carries runs of <root>, never the repository's.
class CarryRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::TempDir("carry_run");
    fs::remove_all(root_);
    fs::create_directories(root_ + "/scripts");
    fs::copy_file(testing::SourcePath("scripts/carry_run.sh"),
                  root_ + "/scripts/carry_run.sh");
  }

  CommandResult Run(const std::string& arguments) const {
    return testing::RunCommand("bash " + root_ + "/scripts/carry_run.sh " +
                               arguments);
  }

  // A run folder whose log's last row is at `samples`.
  void MakeRun(const std::string& folder, int samples) const {
    fs::create_directories(folder);
    std::ofstream(folder + "/checkpoint.pt") << "weights " << samples;
    std::ofstream(folder + "/config.yaml") << "run: {}\n";
    std::ofstream(folder + "/train_log.csv")
        << "iteration,samples,wall_time_s\n1,50,1.0\n2," << samples << ",2.0\n";
  }

  std::string Read(const std::string& path) const {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  std::string root_;
};

TEST_F(CarryRunTest, SavesAndRestoresWhatResumeNeeds) {
  MakeRun(root_ + "/runs/demo", 4096);
  CommandResult saved = Run("save demo");
  ASSERT_EQ(saved.exit_code, 0) << saved.output;
  EXPECT_NE(saved.output.find("4096 samples"), std::string::npos)
      << saved.output;
  EXPECT_EQ(Read(root_ + "/assets/runs/demo/checkpoint.pt"), "weights 4096");
  // A new machine: runs/ is gone; restore brings the three files back.
  fs::remove_all(root_ + "/runs");
  CommandResult restored = Run("restore demo");
  ASSERT_EQ(restored.exit_code, 0) << restored.output;
  for (const char* file : {"checkpoint.pt", "train_log.csv", "config.yaml"}) {
    EXPECT_EQ(Read(root_ + "/runs/demo/" + file),
              Read(root_ + "/assets/runs/demo/" + file))
        << file;
  }
  EXPECT_FALSE(fs::is_empty(root_ + "/runs/demo"));
  for (const auto& entry : fs::directory_iterator(root_ + "/runs/demo")) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos);
  }
}

TEST_F(CarryRunTest, RestoreNeverReplacesARunThatTrainedFurther) {
  MakeRun(root_ + "/assets/runs/demo", 4096);
  MakeRun(root_ + "/runs/demo", 8192);
  CommandResult refused = Run("restore demo");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.output.find("has trained further"), std::string::npos)
      << refused.output;
  EXPECT_EQ(Read(root_ + "/runs/demo/checkpoint.pt"), "weights 8192");
}

TEST_F(CarryRunTest, MissingFilesAndBadUsageAreNamed) {
  CommandResult missing = Run("save nothing");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("runs/nothing/checkpoint.pt not found"),
            std::string::npos)
      << missing.output;
  EXPECT_EQ(Run("carry demo").exit_code, 2);
  EXPECT_EQ(Run("save").exit_code, 2);
}

}  // namespace
}  // namespace m2d
