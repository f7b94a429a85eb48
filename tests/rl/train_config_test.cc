#include "rl/train_config.h"

#include <gtest/gtest.h>
#include <torch/torch.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/file_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

std::string Write(const std::string& dir, const std::string& name,
                  const std::string& text) {
  std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(TrainConfig, ReadsSectionsInlineOrFromFilesAndRoundTrips) {
  std::string dir = testing::TempDir("train_config");
  Write(dir, "agent.yaml",
        "num_envs: 8\nsteps_per_env: 16\nminibatch_size: 64\n"
        "target_kl: 0.02\ntorch_threads: 2\nadapt_torch_threads: true\n");
  std::string path =
      Write(dir, "config.yaml",
            "data: {bundles: [a.json]}\n"
            "env: {num_future_frames: 3, reward: {pose_alpha_per_px: 0.01}}\n"
            "agent: agent.yaml\n"
            "run: {seed: 9}\n");
  TrainConfig config = LoadTrainConfig(path);
  EXPECT_EQ(config.ppo.num_envs, 8);
  EXPECT_EQ(config.ppo.minibatch_size, 64);
  EXPECT_DOUBLE_EQ(config.ppo.target_kl, 0.02);
  EXPECT_TRUE(config.ppo.adapt_torch_threads);
  EXPECT_EQ(config.env.num_future_frames, 3);
  EXPECT_DOUBLE_EQ(config.env.reward.pose_alpha_per_px, 0.01);
  EXPECT_EQ(config.run.seed, 9u);
  EXPECT_EQ(config.model.policy_hidden, (std::vector<int>{512, 256, 256}));

  TrainConfig again = LoadTrainConfigText(TrainConfigToYaml(config), "text");
  EXPECT_EQ(TrainConfigToYaml(again), TrainConfigToYaml(config));
}

// `names_config`: the message names the config file itself (false when the
// problem is in a section file, which the message names instead).
void ExpectConfigError(const std::string& text, const std::string& needle,
                       bool names_config = true) {
  std::string dir = testing::TempDir("train_config_bad");
  std::string path = Write(dir, "bad.yaml", text);
  try {
    LoadTrainConfig(path);
    FAIL() << "expected InputError for: " << text;
  } catch (const InputError& e) {
    std::string message = e.what();
    if (names_config) {
      EXPECT_NE(message.find(path), std::string::npos) << message;
    }
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  }
}

TEST(TrainConfig, SourcesDefaultToTheTruthAndRoundTrip) {
  std::string dir = testing::TempDir("train_config_sources");
  TrainConfig defaults =
      LoadTrainConfig(Write(dir, "a.yaml", "data: {bundles: [a.json]}\n"));
  EXPECT_EQ(defaults.data.initial_states, InitialStateSource::kTruth);
  EXPECT_EQ(defaults.data.cameras, CameraSource::kTruth);
  TrainConfig config = LoadTrainConfig(
      Write(dir, "b.yaml",
            "data: {bundles: [a.json], initial_states: estimate, cameras: "
            "estimate}\n"));
  EXPECT_EQ(config.data.initial_states, InitialStateSource::kEstimate);
  EXPECT_EQ(config.data.cameras, CameraSource::kEstimate);
  const std::string yaml = TrainConfigToYaml(config);
  EXPECT_NE(yaml.find("initial_states: estimate"), std::string::npos) << yaml;
  TrainConfig again = LoadTrainConfigText(yaml, "text");
  EXPECT_EQ(again.data.initial_states, InitialStateSource::kEstimate);
  EXPECT_EQ(again.data.cameras, CameraSource::kEstimate);
  TrainingTaskOptions(again);  // carries them into the task
  EXPECT_EQ(TrainingTaskOptions(again).sources.cameras,
            CameraSource::kEstimate);
  // A checkpoint's embedded config from before the sources: the truth.
  std::string old_yaml = TrainConfigToYaml(defaults);
  for (const char* key : {"  initial_states: truth\n", "  cameras: truth\n"})
    old_yaml.erase(old_yaml.find(key), std::string(key).size());
  EXPECT_EQ(LoadTrainConfigText(old_yaml, "old").data.sources().cameras,
            CameraSource::kTruth);
}

// One list of fields (VisitFields) makes the parser, the emitter, the range
// checks and the reference table: every key the table lists round-trips.
TEST(TrainConfig, TheSettingsReferenceListsEveryEmittedKey) {
  const std::string table = TrainSettingsReference();
  const std::string yaml = TrainConfigToYaml(TrainConfig());
  const YAML::Node root = YAML::Load(yaml);
  int keys = 0;
  for (const auto& section : root) {
    for (const auto& field : section.second) {
      const std::string key =
          section.first.Scalar() + "." + field.first.Scalar();
      if (field.second.IsMap()) {
        for (const auto& inner : field.second) {
          EXPECT_NE(table.find("`" + key + "." + inner.first.Scalar() + "`"),
                    std::string::npos)
              << key;
          ++keys;
        }
      } else {
        EXPECT_NE(table.find("`" + key + "`"), std::string::npos) << key;
        ++keys;
      }
    }
  }
  EXPECT_GT(keys, 40);
  // Ranges and defaults come from the same list.
  EXPECT_NE(table.find("| `agent.discount` | `0.99` | (0, 1) |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| `asi.anchor_share` | `0` | [0, 1] |"),
            std::string::npos)
      << table;
  // configs/README.md carries the same table (regenerate with `mimic2d
  // train --list-settings`).
  const std::string readme =
      ReadFileText(std::string(MIMIC2D_SOURCE_DIR) + "/configs/README.md");
  EXPECT_NE(readme.find(table), std::string::npos)
      << "configs/README.md's settings table is stale: replace it with the "
         "output of `build/mimic2d train --list-settings`";
}

TEST(TrainConfig, EveryShippedConfigLoadsAndValidates) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(
           std::string(MIMIC2D_SOURCE_DIR) + "/configs")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(LoadTrainConfig(entry.path().string()));
    ++loaded;
  }
  EXPECT_GE(loaded, 3);  // walk, walk2d, walk2d_fast
  TrainConfig fast = LoadTrainConfig(std::string(MIMIC2D_SOURCE_DIR) +
                                     "/configs/walk2d_fast.yaml");
  EXPECT_EQ(fast.ppo.training_precision, TrainingPrecision::kAuto);
  EXPECT_EQ(fast.ppo.batch_size(), 2048);
}

TEST(TrainConfig, AutoPrecisionFollowsTheMeasuredBf16Speedup) {
  TrainingPrecision precision = TrainingPrecision::kFp32;
  ASSERT_TRUE(ParseSetting("auto", &precision));
  EXPECT_EQ(precision, TrainingPrecision::kAuto);
  // The probe times real passes, once: where bf16 runs, a positive, finite
  // ratio; where it does not, LibTorch's reason.
  const Bf16Support& bf16 = ProbeBf16();
  EXPECT_EQ(&ProbeBf16(), &bf16);
  if (bf16.runs) {
    EXPECT_GT(bf16.speedup, 0.0);
    EXPECT_TRUE(std::isfinite(bf16.speedup));
    EXPECT_NO_THROW(RequirePrecisionRuns(TrainingPrecision::kBf16, "x"));
  } else {
    EXPECT_EQ(bf16.speedup, 0.0);
    EXPECT_FALSE(bf16.error.empty());
    EXPECT_THROW(RequirePrecisionRuns(TrainingPrecision::kBf16, "x"),
                 ConfigError);
  }
  EXPECT_EQ(ResolvePrecision(TrainingPrecision::kAuto),
            bf16.runs && bf16.speedup >= kAutoBf16MinSpeedup
                ? TrainingPrecision::kBf16
                : TrainingPrecision::kFp32);
  // An explicit choice is kept whatever the CPU.
  EXPECT_EQ(ResolvePrecision(TrainingPrecision::kBf16),
            TrainingPrecision::kBf16);
  EXPECT_EQ(ResolvePrecision(TrainingPrecision::kFp32),
            TrainingPrecision::kFp32);
  EXPECT_NO_THROW(RequirePrecisionRuns(TrainingPrecision::kFp32, "x"));
  EXPECT_STREQ(SettingName(TrainingPrecision::kAuto), "auto");
}

TEST(TrainConfig, Bf16ThatThrowsIsMeasuredAsNotRunning) {
  // A CPU where oneDNN refuses bf16 (as under ONEDNN_MAX_CPU_ISA=AVX2 on an
  // AVX-512 CPU): the probe's bf16 step throws LibTorch's error.
  int fp32_steps = 0;
  const Bf16Support refused =
      MeasureBf16Support([&](TrainingPrecision precision, int) -> double {
        if (precision == TrainingPrecision::kBf16) {
          throw c10::Error(
              "could not create a primitive descriptor iterator\n"
              "Exception raised from ... (most recent call first)",
              "backtrace");
        }
        ++fp32_steps;
        return 1.0;
      });
  EXPECT_FALSE(refused.runs);
  EXPECT_EQ(refused.speedup, 0.0);
  EXPECT_EQ(refused.error, "could not create a primitive descriptor iterator");
  EXPECT_EQ(fp32_steps, 1);
  // Where it runs: the ratio of the timed steps.
  const Bf16Support runs =
      MeasureBf16Support([](TrainingPrecision precision, int) {
        return precision == TrainingPrecision::kBf16 ? 0.5 : 1.0;
      });
  EXPECT_TRUE(runs.runs);
  EXPECT_DOUBLE_EQ(runs.speedup, 2.0);
  EXPECT_TRUE(runs.error.empty());
}

TEST(TrainConfig, ProbingThePrecisionLeavesTheSeededDrawsAlone) {
  torch::manual_seed(7);
  const torch::Tensor expected = torch::randn({4});
  torch::manual_seed(7);
  (void)ResolvePrecision(TrainingPrecision::kAuto);
  EXPECT_TRUE(torch::equal(torch::randn({4}), expected));
}

TEST(TrainConfig, BadConfigsNameTheFileAndTheSetting) {
  ExpectConfigError("data: {bundles: [a.json], initial_states: fitted}\n",
                    "'data.initial_states' must be one of truth, estimate, "
                    "default");
  ExpectConfigError("data: {bundles: [a.json], cameras: default}\n",
                    "'data.cameras' must be one of truth, estimate");
  ExpectConfigError("data: {bundles: [a.json]}\nenv: {torque_limit: total}\n",
                    "'env.torque_limit' must be one of servo, pd");
  ExpectConfigError(
      "data: {bundles: [a.json], initial_states: estimate, cameras: truth}\n",
      "initial_states: estimate needs cameras: estimate");
  ExpectConfigError(
      "data: {bundles: [a.json], initial_states: default}\n"
      "env: {critic_observes_3d: true}\n",
      "critic_observes_3d needs a 3D reference");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {num_envz: 3}\n",
                    "'agent.num_envz' is not a known setting");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {num_envs: many}\n",
                    "'agent.num_envs' has the wrong type");
  ExpectConfigError("data: {bundles: []}\n", "data.bundles");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {discount: 1.5}\n",
                    "discount");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: missing.yaml\n",
                    "missing.yaml: cannot open file", false);
  ExpectConfigError("data: [\n", "malformed YAML");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nagent: {minibatch_size: 100000}\n",
      "minibatch_size");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {target_kl: -1}\n",
                    "target_kl");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nagent: {adapt_torch_threads: true}\n",
      "adapt_torch_threads");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nagent: {torch_threads: 2, "
      "adapt_torch_threads: true, overlap_update: true}\n",
      "overlap_update and agent.adapt_torch_threads exclude each other");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nagent: {training_precision: fp16}\n",
      "'agent.training_precision' must be one of fp32, bf16");
  ExpectConfigError(
      "data: {bundles: [a.json]}\n"
      "agent: {learning_rate_min: 0.01, learning_rate_max: 0.001}\n",
      "learning_rate_min");
  // Found by fuzzing: these trained to NaN, made 1-frame episodes, or kept
  // the first of two settings without a word.
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {learning_rate: .inf}\n",
                    "'agent.learning_rate' must be a finite number");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {clip_ratio: .nan}\n",
                    "'agent.clip_ratio' must be a finite number");
  ExpectConfigError("data: {bundles: [a.json]}\nenv: {max_episode_s: .inf}\n",
                    "'env.max_episode_s' must be a finite number");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nagent: {epochs: 3, epochs: 5}\n",
      "'agent.epochs' appears twice");
  // libFuzzer (scripts/fuzz.sh): a list used as a key escaped as
  // YAML::TypedBadConversion and aborted.
  ExpectConfigError("data: {bundles: [a.json]}\nagent: {[epochs]: 3}\n",
                    "a key is not a plain name");
  ExpectConfigError(
      "data: {bundles: [a.json]}\nmodel: {policy_hidden: [100000]}\n",
      "'model.policy_hidden' must be in [1, 65536]");
  ExpectConfigError("data: {bundles: [a.json]}\nagent: /dev/null\n",
                    "not a regular file", false);
  ExpectConfigError("data: {bundles: [a.json]}\nagent: /tmp\n",
                    "is a folder, not a file", false);
}

// Config paths are read from the working directory: a command started
// outside the repository's root hears which directory that was.
TEST(TrainConfig, AMissingRelativePathNamesTheWorkingDirectory) {
  const auto message_of = [](const std::string& path) -> std::string {
    try {
      ReadFileText(path);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string relative = message_of("no_such_folder/config.yaml");
  EXPECT_NE(relative.find("no_such_folder/config.yaml: cannot open file (No "
                          "such file or directory); relative paths are read "
                          "from the working directory " +
                          std::filesystem::current_path().string()),
            std::string::npos)
      << relative;
  const std::string absolute = message_of("/no_such_folder/config.yaml");
  EXPECT_NE(absolute.find("cannot open file"), std::string::npos) << absolute;
  EXPECT_EQ(absolute.find("working directory"), std::string::npos) << absolute;
}

}  // namespace
}  // namespace m2d
