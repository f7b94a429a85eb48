// Resuming a training run: counters, the log and settings carry over from
// the checkpoint. Tiny networks and batches: only the bookkeeping matters.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli/cli_test_util.h"
#include "common/cpus.h"
#include "common/error.h"
#include "common/file_io.h"
#include "env/env_fixture.h"
#include "env/task.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "render/training_plot.h"
#include "rl/checkpoint.h"
#include "rl/trainer.h"
#include "sim/simulation.h"
#include "test_paths.h"
#include "tiny_walk_config.h"

namespace m2d {
namespace {

namespace fs = std::filesystem;

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";

// A 1 s walk bundle written into `dir`, and a config training on it with
// 4 envs x 16 steps (64 samples per iteration) and tiny networks.
TrainConfig TinyConfig(const std::string& walk_path, const std::string& dir) {
  TrainConfig config = testing::TinyWalkConfig(walk_path, dir);
  config.ppo.num_envs = 4;
  config.ppo.steps_per_env = 16;
  config.ppo.minibatch_size = 32;
  config.ppo.epochs = 1;
  config.run.seed = 3;
  config.Validate();
  return config;
}

constexpr int64_t kBatch = 4 * 16;

struct RunResult {
  TrainSummary summary;
  std::vector<TrainProgress> progress;
  double elapsed_s = 0.0;  // of the Run() call, measured outside it
};

RunResult TrainIterations(const TrainConfig& config, bool resume,
                          int iterations) {
  Trainer trainer(config, resume);
  RunResult result;
  auto start = std::chrono::steady_clock::now();
  result.summary =
      trainer.Run(iterations, nullptr, [&](const TrainProgress& progress) {
        result.progress.push_back(progress);
      });
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

struct LogRow {
  int iteration = 0;
  int64_t samples = 0;
  double wall_time_s = 0.0;
};

std::vector<LogRow> ReadLog(const std::string& run_dir) {
  std::ifstream in(run_dir + "/train_log.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("iteration,samples,wall_time_s,", 0), 0u) << line;
  std::vector<LogRow> rows;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    LogRow row;
    char comma;
    fields >> row.iteration >> comma >> row.samples >> comma >> row.wall_time_s;
    EXPECT_TRUE(fields) << "malformed row: " << line;
    rows.push_back(row);
  }
  return rows;
}

void AppendToLog(const std::string& run_dir, const std::string& text) {
  std::ofstream(run_dir + "/train_log.csv", std::ios::app) << text;
}

// The networks of a checkpoint, built from its own config, and its counters.
ActorCritic ReadModel(const std::string& path, CheckpointCounters* counters) {
  TrainConfig config = ReadCheckpointConfig(path);
  int action_size = 0;
  ObservationLayout layout = ReadCheckpointLayout(path, &action_size);
  ActorCritic model(layout, config.model, action_size);
  *counters = LoadCheckpoint(path, model, nullptr, nullptr, SimState());
  return model;
}

CheckpointCounters ReadCounters(const std::string& path,
                                torch::Tensor* log_std = nullptr) {
  CheckpointCounters counters;
  ActorCritic model = ReadModel(path, &counters);
  if (log_std != nullptr) *log_std = model->LogStd().detach().clone();
  return counters;
}

TEST(Resume, ContinuesCountersAndLogWhereTheCheckpointLeftOff) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_continues");
  const TrainConfig config = TinyConfig(walk_path, dir);

  RunResult first = TrainIterations(config, /*resume=*/false, 3);
  ASSERT_EQ(first.summary.iterations_run, 3);
  ASSERT_EQ(first.summary.last.iteration, 3);
  EXPECT_EQ(first.summary.last.samples, 3 * kBatch);
  const double first_wall_s = first.summary.last.wall_time_s;
  CheckpointCounters saved = ReadCounters(first.summary.checkpoint_path);
  EXPECT_EQ(saved.iteration, 3);
  EXPECT_EQ(saved.samples, 3 * kBatch);
  EXPECT_EQ(saved.wall_time_s, first_wall_s);

  RunResult second = TrainIterations(config, /*resume=*/true, 2);
  EXPECT_EQ(second.summary.iterations_run, 2);
  ASSERT_EQ(second.progress.size(), 2u);
  EXPECT_EQ(second.progress[0].iteration, 4);
  EXPECT_EQ(second.progress[1].iteration, 5);
  EXPECT_EQ(second.progress[0].samples, 4 * kBatch);
  EXPECT_EQ(second.progress[1].samples, 5 * kBatch);
  // Wall time adds this run's iterations to the first run's total: more
  // than it, by no more than the second Run() took.
  EXPECT_GT(second.progress[0].wall_time_s, first_wall_s);
  EXPECT_GT(second.progress[1].wall_time_s, second.progress[0].wall_time_s);
  EXPECT_LE(second.progress[1].wall_time_s,
            first_wall_s + second.elapsed_s + 1e-6);
  CheckpointCounters final_counters =
      ReadCounters(second.summary.checkpoint_path);
  EXPECT_EQ(final_counters.iteration, 5);
  EXPECT_EQ(final_counters.samples, 5 * kBatch);
  EXPECT_EQ(final_counters.wall_time_s, second.summary.last.wall_time_s);

  std::vector<LogRow> log = ReadLog(config.run.run_dir);
  ASSERT_EQ(log.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(log[i].iteration, i + 1);
    EXPECT_EQ(log[i].samples, (i + 1) * kBatch);
    if (i > 0) {
      EXPECT_GT(log[i].wall_time_s, log[i - 1].wall_time_s);
    }
  }
  fs::remove_all(dir);
}

TEST(Resume, WithoutACheckpointStartsFresh) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_fresh");
  const TrainConfig config = TinyConfig(walk_path, dir);
  ASSERT_FALSE(fs::exists(config.run.run_dir + "/checkpoint.pt"));

  RunResult run = TrainIterations(config, /*resume=*/true, 1);
  ASSERT_EQ(run.progress.size(), 1u);
  EXPECT_EQ(run.progress[0].iteration, 1);
  EXPECT_EQ(run.progress[0].samples, kBatch);
  EXPECT_LE(run.progress[0].wall_time_s, run.elapsed_s);
  std::vector<LogRow> log = ReadLog(config.run.run_dir);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_EQ(log[0].iteration, 1);
  EXPECT_TRUE(fs::exists(config.run.run_dir + "/checkpoint.pt"));
  fs::remove_all(dir);
}

// The progress line's ETA: the samples left at a running average of the
// iterations' seconds per sample (weight 0.05), not at one iteration's
// rate, which swings it by 10-20 % from line to line.
TEST(Trainer, TheEtaIsTheSamplesLeftAtTheRecentRate) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("trainer_eta");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.run.total_samples = 100 * kBatch;
  config.Validate();
  RunResult run = TrainIterations(config, /*resume=*/false, 6);
  ASSERT_EQ(run.progress.size(), 6u);
  double average_s = 0.0;
  for (const TrainProgress& p : run.progress) {
    const double seconds_per_sample = 1.0 / p.samples_per_s;
    average_s = average_s == 0.0 ? seconds_per_sample
                                 : 0.95 * average_s + 0.05 * seconds_per_sample;
    const double left =
        static_cast<double>(config.run.total_samples - p.samples);
    EXPECT_NEAR(p.eta_s, left * average_s, 1e-9 * left * average_s)
        << "iteration " << p.iteration;
  }
  fs::remove_all(dir);
}

TEST(Resume, KeptCheckpointsAreNamedByTheSamplesTheyHold) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_kept");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.run.keep_checkpoints = true;
  config.run.checkpoint_minutes = 1e-6;  // a checkpoint every iteration
  TrainIterations(config, /*resume=*/false, 2);
  const std::string kept = config.run.run_dir + "/checkpoints";
  // A copy torn by a kill: the resumed run removes it.
  WriteFileAtomic(kept + "/ckpt_192.pt.tmp.99", "torn");
  TrainIterations(config, /*resume=*/true, 1);

  // One copy per iteration (the final save of a run has the same name as
  // its last periodic one), each loading to the counters its name says.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(kept))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names, (std::vector<std::string>{"ckpt_128.pt", "ckpt_192.pt",
                                             "ckpt_64.pt"}));
  for (int i = 1; i <= 3; ++i) {
    CheckpointCounters counters =
        ReadCounters(kept + "/ckpt_" + std::to_string(i * kBatch) + ".pt");
    EXPECT_EQ(counters.iteration, i);
    EXPECT_EQ(counters.samples, i * kBatch);
  }
  // The last copy is the run's checkpoint, byte for byte.
  EXPECT_EQ(ReadFileText(kept + "/ckpt_192.pt"),
            ReadFileText(config.run.run_dir + "/checkpoint.pt"));
  fs::remove_all(dir);
}

TEST(Resume, DropsLogRowsPastTheCheckpoint) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_trim");
  const TrainConfig config = TinyConfig(walk_path, dir);
  TrainIterations(config, /*resume=*/false, 2);
  // A run killed after logging past its last checkpoint: a whole row that
  // the checkpoint does not know about, then row 10 torn mid-write after
  // its first digit (which alone reads as iteration 1).
  AppendToLog(config.run.run_dir,
              "9,999999,1.5,1,2,3,0.5,10,0.1,0.2,0.3,0.0002\n1");

  RunResult resumed = TrainIterations(config, /*resume=*/true, 1);
  ASSERT_EQ(resumed.progress.size(), 1u);
  EXPECT_EQ(resumed.progress[0].iteration, 3);
  std::vector<LogRow> log = ReadLog(config.run.run_dir);
  ASSERT_EQ(log.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(log[i].iteration, i + 1);
    EXPECT_EQ(log[i].samples, (i + 1) * kBatch);
  }
  fs::remove_all(dir);
}

TEST(Resume, RowsOfAnOlderLogGetEmptyCellsForNewColumns) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_old_log");
  const TrainConfig config = TinyConfig(walk_path, dir);
  TrainIterations(config, /*resume=*/false, 2);
  // Rewrite the log as the trainer wrote it before the last four columns.
  const std::string log_path = config.run.run_dir + "/train_log.csv";
  std::vector<std::string> lines;
  {
    std::ifstream in(log_path);
    std::string line;
    while (std::getline(in, line)) {
      size_t cut = 0;
      for (int comma = 0; comma < 12 && cut != std::string::npos; ++comma)
        cut = line.find(',', cut + (comma > 0));
      lines.push_back(line.substr(0, cut));
    }
  }
  ASSERT_EQ(lines.size(), 3u);
  ASSERT_EQ(std::count(lines[1].begin(), lines[1].end(), ','), 11);
  {
    std::ofstream out(log_path);
    for (const std::string& line : lines) out << line << "\n";
  }

  TrainIterations(config, /*resume=*/true, 1);
  std::ifstream in(log_path);
  std::string header, row;
  std::getline(in, header);
  EXPECT_NE(header.find(",approx_kl,clip_fraction,torch_threads,bf16"),
            std::string::npos)
      << header;
  std::vector<std::string> rows;
  while (std::getline(in, row)) rows.push_back(row);
  ASSERT_EQ(rows.size(), 3u);
  for (const std::string& r : rows)
    EXPECT_EQ(std::count(r.begin(), r.end(), ','), 15) << r;
  // The old rows' new cells are empty; the new row fills them.
  EXPECT_EQ(rows[0].substr(rows[0].size() - 4), ",,,,");
  EXPECT_EQ(rows[1].substr(rows[1].size() - 4), ",,,,");
  EXPECT_NE(rows[2].back(), ',');
  fs::remove_all(dir);
}

TEST(Resume, AFixedActionStdFollowsTheConfig) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_action_std");
  TrainConfig config = TinyConfig(walk_path, dir);
  ASSERT_FALSE(config.model.learn_action_std);
  config.model.action_std = 0.2;
  RunResult first = TrainIterations(config, /*resume=*/false, 1);
  torch::Tensor log_std;
  ReadCounters(first.summary.checkpoint_path, &log_std);
  EXPECT_TRUE(torch::allclose(log_std, torch::full_like(log_std, std::log(0.2)),
                              0.0, 1e-6));

  // Less exploration for the rest of the run.
  config.model.action_std = 0.05;
  RunResult second = TrainIterations(config, /*resume=*/true, 1);
  EXPECT_EQ(second.summary.last.iteration, 2);
  ReadCounters(second.summary.checkpoint_path, &log_std);
  EXPECT_TRUE(torch::allclose(
      log_std, torch::full_like(log_std, std::log(0.05)), 0.0, 1e-6))
      << log_std;
  fs::remove_all(dir);
}

// Fine-tuning: a fresh run (another run folder, another seed) starts from
// another run's networks and normalizer; counters start at zero.
TEST(Resume, InitFromStartsAFreshRunFromAnotherRunsNetworks) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_init_from");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.learning_rate = 7e-5;  // the source's rate, fixed
  RunResult first = TrainIterations(config, /*resume=*/false, 2);
  const std::string pretrained = first.summary.checkpoint_path;

  TrainConfig tuned = config;
  tuned.run.run_dir = dir + "/tuned";
  tuned.run.seed = 9;
  tuned.run.init_from = pretrained;
  tuned.ppo.learning_rate = 2e-4;  // not the source's
  {
    Trainer trainer(tuned, /*resume=*/false);
    trainer.SaveCheckpoint();
  }
  CheckpointCounters from, started;
  ActorCritic a = ReadModel(pretrained, &from);
  ActorCritic b = ReadModel(tuned.run.run_dir + "/checkpoint.pt", &started);
  EXPECT_EQ(from.iteration, 2);
  EXPECT_EQ(started.iteration, 0);
  EXPECT_EQ(started.samples, 0);
  // A fixed rate is the config's, not the source's.
  EXPECT_DOUBLE_EQ(from.learning_rate, 7e-5);
  EXPECT_DOUBLE_EQ(started.learning_rate, 2e-4);
  const auto a_state = a->named_parameters(), b_state = b->named_parameters();
  for (const auto& item : a_state)
    EXPECT_TRUE(torch::equal(item.value(), b_state[item.key()])) << item.key();
  const auto a_buffers = a->named_buffers(), b_buffers = b->named_buffers();
  ASSERT_GT(a_buffers.size(), 0u);
  for (const auto& item : a_buffers)
    EXPECT_TRUE(torch::equal(item.value(), b_buffers[item.key()]))
        << item.key();
  // A fresh seed alone gives other weights: the equality is the init's.
  TrainConfig unrelated = tuned;
  unrelated.run.run_dir = dir + "/unrelated";
  unrelated.run.init_from.clear();
  {
    Trainer trainer(unrelated, /*resume=*/false);
    trainer.SaveCheckpoint();
  }
  ActorCritic c = ReadModel(unrelated.run.run_dir + "/checkpoint.pt", &started);
  EXPECT_FALSE(torch::equal(a->named_parameters()["actor.0.weight"],
                            c->named_parameters()["actor.0.weight"]));

  // An adaptive rate starts at the source's, within the config's bounds.
  const auto starting_rate = [&](const std::string& name, double min_rate) {
    TrainConfig adaptive = tuned;
    adaptive.run.run_dir = dir + "/" + name;
    adaptive.ppo.target_kl = 0.01;
    adaptive.ppo.learning_rate_min = min_rate;
    {
      Trainer trainer(adaptive, /*resume=*/false);
      trainer.SaveCheckpoint();
    }
    CheckpointCounters counters;
    ReadModel(adaptive.run.run_dir + "/checkpoint.pt", &counters);
    return counters.learning_rate;
  };
  EXPECT_DOUBLE_EQ(starting_rate("adaptive", 1e-6), 7e-5);
  EXPECT_DOUBLE_EQ(starting_rate("adaptive_floor", 1e-4), 1e-4);

  // A longer horizon of future frames: the source's weights, its encoders'
  // first layers widened with zero columns for the new frames.
  TrainConfig longer = tuned;
  longer.run.run_dir = dir + "/longer";
  longer.env.num_future_frames = config.env.num_future_frames + 3;
  {
    Trainer trainer(longer, /*resume=*/false);
    trainer.SaveCheckpoint();
  }
  ActorCritic d = ReadModel(longer.run.run_dir + "/checkpoint.pt", &started);
  EXPECT_EQ(d->layout().num_future_frames, config.env.num_future_frames + 3);
  const int64_t source_width = a->layout().view_size();
  for (const auto& item : d->named_parameters()) {
    const torch::Tensor source = a_state[item.key()];
    if (source.sizes() == item.value().sizes()) {
      EXPECT_TRUE(torch::equal(item.value(), source)) << item.key();
    } else {
      EXPECT_TRUE(torch::equal(item.value().narrow(1, 0, source_width), source))
          << item.key();
      EXPECT_EQ(
          item.value()
              .narrow(1, source_width, item.value().size(1) - source_width)
              .abs()
              .sum()
              .item<double>(),
          0.0)
          << item.key();
    }
  }
  // A shorter one is not widened: an error naming the checkpoint.
  TrainConfig shorter = tuned;
  shorter.run.run_dir = dir + "/shorter";
  shorter.env.num_future_frames = config.env.num_future_frames - 1;
  try {
    Trainer trainer(shorter, /*resume=*/false);
    ADD_FAILURE() << "a shorter horizon was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(pretrained), std::string::npos)
        << e.what();
  }

  // Networks of other sizes: an error naming the checkpoint.
  TrainConfig other_sizes = tuned;
  other_sizes.run.run_dir = dir + "/other_sizes";
  other_sizes.model.policy_hidden = {24};
  try {
    Trainer trainer(other_sizes, /*resume=*/false);
    ADD_FAILURE() << "networks of other sizes were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(pretrained), std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

TEST(Resume, AnAdaptiveLearningRateContinuesFromTheCheckpoint) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_adaptive_lr");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.target_kl = 0.01;
  config.ppo.learning_rate = 2e-4;
  RunResult first = TrainIterations(config, /*resume=*/false, 2);
  const CheckpointCounters saved = ReadCounters(first.summary.checkpoint_path);
  ASSERT_GT(saved.learning_rate, 0.0);

  // The config's rate is only the first iteration's: a resumed run goes on
  // with the adapted one.
  config.ppo.learning_rate = 7e-4;
  RunResult second = TrainIterations(config, /*resume=*/true, 1);
  ASSERT_EQ(second.progress.size(), 1u);
  EXPECT_EQ(second.progress[0].learning_rate, saved.learning_rate);
  fs::remove_all(dir);
}

TEST(Resume, ACorruptWallTimeContinuesFromTheLog) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_corrupt_wall_time");
  TrainConfig config = TinyConfig(walk_path, dir);
  RunResult first = TrainIterations(config, /*resume=*/false, 2);
  const std::string checkpoint = first.summary.checkpoint_path;

  // Rewrite the checkpoint with the counter a fixed bug produced (a double's
  // bits read as int64), keeping everything else.
  TrainConfig saved_config = ReadCheckpointConfig(checkpoint);
  int action_size = 0;
  ObservationLayout layout = ReadCheckpointLayout(checkpoint, &action_size);
  ActorCritic model(layout, saved_config.model, action_size);
  torch::optim::Adam optimizer(model->parameters(), 1e-3);
  CheckpointCounters counters =
      LoadCheckpoint(checkpoint, model, &optimizer, nullptr, SimState());
  counters.wall_time_s = 4.658e18;
  SaveCheckpoint(checkpoint, saved_config, model, optimizer, counters, nullptr,
                 SimState());

  const double logged_s = ReadLog(config.run.run_dir).back().wall_time_s;
  RunResult second = TrainIterations(config, /*resume=*/true, 1);
  ASSERT_EQ(second.progress.size(), 1u);
  EXPECT_GT(second.progress[0].wall_time_s, logged_s);
  EXPECT_LE(second.progress[0].wall_time_s, logged_s + second.elapsed_s);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace m2d

namespace m2d {
namespace {

// Found by fuzzing: resuming with a changed structural setting ran into a
// LibTorch backtrace after config.yaml had been overwritten. It is a named
// error now, and the run folder is left as it was.
TEST(Resume, AChangedStructuralSettingFailsBeforeAnythingIsWritten) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_structural");
  const TrainConfig config = TinyConfig(walk_path, dir);
  TrainIterations(config, /*resume=*/false, 1);
  const std::string run_dir = config.run.run_dir;
  auto contents = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string config_before = contents(run_dir + "/config.yaml");
  const std::string log_before = contents(run_dir + "/train_log.csv");

  TrainConfig more_future = config;
  more_future.env.num_future_frames = config.env.num_future_frames + 3;
  TrainConfig wider = config;
  wider.model.policy_hidden = {48};
  TrainConfig asymmetric = config;
  asymmetric.env.critic_observes_3d = true;
  for (const TrainConfig& changed : {more_future, wider, asymmetric}) {
    std::string message;
    try {
      Trainer trainer(changed, /*resume=*/true);
    } catch (const InputError& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(run_dir + "/checkpoint.pt"), std::string::npos)
        << message;
    EXPECT_TRUE(message.find("future frames") != std::string::npos ||
                message.find("network differs") != std::string::npos ||
                message.find("critic-only inputs") != std::string::npos)
        << message;
    EXPECT_EQ(contents(run_dir + "/config.yaml"), config_before);
    EXPECT_EQ(contents(run_dir + "/train_log.csv"), log_before);
  }
  fs::remove_all(dir);
}

// Found by fuzzing: resuming on another bundle of the same length reused
// the initial-state buffers filled for the old one. They are restored only
// into the reference they were filled for.
TEST(Resume, BuffersOfAnotherReferenceAreNotReused) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_reference");
  const TrainConfig config = TinyConfig(walk_path, dir);
  TrainIterations(config, /*resume=*/false, 1);
  const std::string checkpoint = config.run.run_dir + "/checkpoint.pt";

  // The same bundle shifted by 40 px in every view: same frame count,
  // different 2D.
  ReferenceBundle shifted = ReadBundle(config.data.bundles[0]);
  for (ReferenceView& view : shifted.views) {
    for (int t = 0; t < view.clip.num_frames(); ++t) {
      for (int j = 0; j < view.clip.keypoints.num_keypoints(); ++j)
        view.clip.keypoints.at(t, j).x_px += 40.0;
    }
  }
  TrainConfig other = config;
  other.data.bundles = {dir + "/shifted.json"};
  WriteBundle(other.data.bundles[0], shifted);

  auto buffers_for = [&](const TrainConfig& task_config) {
    TrackingTask task = BuildTrackingTask(
        task_config.data.character_config, task_config.data.scene,
        task_config.data.bundles, TrainingTaskOptions(task_config));
    TrackingEnv env(task.character, task.reference, task.initial_states,
                    task_config.env, 0);
    ActorCritic model(env.layout(), task_config.model, env.action_size());
    LoadCheckpoint(checkpoint, model, nullptr, task.initial_states.get(),
                   env.simulation().Save());
    return task.initial_states;
  };
  const auto same = buffers_for(config);
  // Only the buffers (eval --asi-starts): restored into the same reference,
  // refused for another.
  {
    TrackingTask task =
        BuildTrackingTask(config.data.character_config, config.data.scene,
                          config.data.bundles, TrainingTaskOptions(config));
    TrackingEnv env(task.character, task.reference, task.initial_states,
                    config.env, 0);
    LoadCheckpointStateBuffers(checkpoint, task.initial_states.get(),
                               env.simulation().Save());
    for (int f = 0; f < same->buffer(0).num_frames(); ++f) {
      ASSERT_EQ(task.initial_states->buffer(0).size(f),
                same->buffer(0).size(f));
      for (int i = 0; i < same->buffer(0).size(f); ++i) {
        EXPECT_EQ(task.initial_states->buffer(0).entry(f, i).state.qpos,
                  same->buffer(0).entry(f, i).state.qpos);
      }
    }
    TrackingTask other_task =
        BuildTrackingTask(other.data.character_config, other.data.scene,
                          other.data.bundles, TrainingTaskOptions(other));
    EXPECT_THROW(
        LoadCheckpointStateBuffers(checkpoint, other_task.initial_states.get(),
                                   env.simulation().Save()),
        InputError);
  }
  const auto fresh_task =
      BuildTrackingTask(other.data.character_config, other.data.scene,
                        other.data.bundles, TrainingTaskOptions(other));
  const auto other_buffers = buffers_for(other);
  EXPECT_NE(same->reference_fingerprint(),
            other_buffers->reference_fingerprint());
  // The other reference's buffers are its own fresh ones, state for state.
  const StateBuffer& restored = other_buffers->buffer(0);
  const StateBuffer& fresh = fresh_task.initial_states->buffer(0);
  ASSERT_EQ(restored.num_frames(), fresh.num_frames());
  for (int f = 0; f < restored.num_frames(); ++f) {
    ASSERT_EQ(restored.size(f), fresh.size(f));
    for (int i = 0; i < restored.size(f); ++i)
      EXPECT_EQ(restored.entry(f, i).state.qpos, fresh.entry(f, i).state.qpos);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace m2d

namespace m2d {
namespace {

// Starts `mimic2d train CONFIG --resume [extra]` with its output to
// `log_path`; returns the child's pid.
pid_t StartTraining(const std::string& config, const std::string& extra,
                    const std::string& log_path) {
  const std::string command = std::string(MIMIC2D_BINARY) + " train " + config +
                              " --resume " + extra + " > " + log_path + " 2>&1";
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);  // the shell and mimic2d, killed together
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Kill -9 at random moments (mid-iteration, mid-checkpoint), resume each
// time: every checkpoint left behind loads, progress is never lost beyond
// the last checkpoint, no temp file survives a restart, and the final
// log counts its iterations without a gap or a repeat.
TEST(Resume, SurvivesKillsAtRandomMoments) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("resume_kill");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.run.checkpoint_minutes = 0.005;  // every 0.3 s: kills land in saves
  config.run.total_samples = 1'000'000'000;
  const std::string config_path = dir + "/tiny.yaml";
  WriteFileAtomic(config_path, TrainConfigToYaml(config));
  const std::string checkpoint = config.run.run_dir + "/checkpoint.pt";

  std::mt19937 rng(7);
  std::uniform_int_distribution<int> delay_ms(800, 3500);
  int last_iteration = 0;
  for (int kill = 0; kill < 4; ++kill) {
    SCOPED_TRACE("kill " + std::to_string(kill));
    const pid_t pid = StartTraining(config_path, "", dir + "/out.txt");
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    ::kill(-pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    if (!fs::exists(checkpoint)) continue;  // killed before the first save
    const CheckpointCounters counters = ReadCounters(checkpoint);
    EXPECT_GE(counters.iteration, last_iteration);  // nothing lost
    last_iteration = counters.iteration;
  }
  // The last start: a few iterations to the end, exit 0.
  const pid_t pid =
      StartTraining(config_path, "--iterations 3", dir + "/final.txt");
  int status = 0;
  waitpid(pid, &status, 0);
  std::ifstream final_output(dir + "/final.txt");
  const std::string output(std::istreambuf_iterator<char>(final_output), {});
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  EXPECT_GT(last_iteration, 0) << "no checkpoint was ever written";
  EXPECT_EQ(ReadCounters(checkpoint).iteration, last_iteration + 3) << output;
  for (const auto& entry : fs::directory_iterator(config.run.run_dir)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos)
        << entry.path();
  }
  const std::vector<LogRow> log = ReadLog(config.run.run_dir);
  ASSERT_EQ(static_cast<int>(log.size()), last_iteration + 3);
  for (size_t i = 0; i < log.size(); ++i) EXPECT_EQ(log[i].iteration, i + 1);
  fs::remove_all(dir);
}

// With training_precision auto the start-up probe picks the first
// precision; the trainer then measures the other in real iterations (the
// probe answers only for the load at start-up), and the log says which
// arithmetic each iteration ran in.
TEST(Trainer, AutoPrecisionIsMeasuredAgainWhileTraining) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("trainer_auto_precision");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.training_precision = TrainingPrecision::kAuto;
  config.Validate();
  const bool start_bf16 =
      ResolvePrecision(TrainingPrecision::kAuto) == TrainingPrecision::kBf16;

  // The first probe comes after 4 iterations of the starting pick (sooner
  // if an iteration is much slower than the others).
  RunResult run = TrainIterations(config, /*resume=*/false, 6);
  ASSERT_EQ(run.progress.size(), 6u);
  EXPECT_EQ(run.progress[0].bf16, start_bf16);
  int other = 0;
  for (const TrainProgress& p : run.progress) other += p.bf16 != start_bf16;
  EXPECT_GE(other, 1);
  EXPECT_LE(other, 5);

  std::ifstream in(config.run.run_dir + "/train_log.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.substr(line.size() - 5), ",bf16") << line;
  for (const TrainProgress& p : run.progress) {
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line.substr(line.size() - 2), p.bf16 ? ",1" : ",0") << line;
  }
  // `plot` and `report --log` read it (every cell a number).
  const TrainingCurves curves =
      ReadTrainingLog(config.run.run_dir + "/train_log.csv");
  EXPECT_EQ(curves.num_rows(), 6);
  EXPECT_EQ(curves.columns.count("bf16"), 1u);
  fs::remove_all(dir);
}

// Where oneDNN refuses bf16 (a user can cap it below AVX-512 with
// ONEDNN_MAX_CPU_ISA; on an AVX-512 CPU LibTorch still routes bf16 there,
// and training died on "could not create a primitive descriptor iterator"),
// `auto` trains in fp32 and says why, and an explicit bf16 is a named
// error. Child processes: oneDNN reads the cap once per process. Where
// LibTorch does not route bf16 to oneDNN, both run.
TEST(Trainer, AutoTrainsInFp32WhereBf16DoesNotRun) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("trainer_bf16_refused");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.training_precision = TrainingPrecision::kAuto;
  config.run.total_samples = 6 * kBatch;
  config.Validate();
  WriteFileAtomic(dir + "/auto.yaml", TrainConfigToYaml(config));
  const std::string capped_train =
      "ONEDNN_MAX_CPU_ISA=AVX2 " + std::string(MIMIC2D_BINARY) + " train ";

  const testing::CommandResult run =
      testing::RunCommand(capped_train + dir + "/auto.yaml");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const bool refused =
      run.output.find("fp32 (bf16 does not run here: ") != std::string::npos;
  std::cout << "bf16 under ONEDNN_MAX_CPU_ISA=AVX2: "
            << (refused ? "refused, trained in fp32" : "runs") << "\n";
  const TrainingCurves curves =
      ReadTrainingLog(config.run.run_dir + "/train_log.csv");
  ASSERT_EQ(curves.num_rows(), 6);
  if (refused) {
    for (double bf16 : curves.columns.at("bf16")) EXPECT_EQ(bf16, 0.0);
  }

  config.ppo.training_precision = TrainingPrecision::kBf16;
  config.run.run_dir = dir + "/run_bf16";
  WriteFileAtomic(dir + "/bf16.yaml", TrainConfigToYaml(config));
  const testing::CommandResult explicit_bf16 =
      testing::RunCommand(capped_train + dir + "/bf16.yaml");
  if (refused) {
    EXPECT_EQ(explicit_bf16.exit_code, 2) << explicit_bf16.output;
    EXPECT_NE(explicit_bf16.output.find(
                  "agent.training_precision: bf16 does not run on this CPU "
                  "and LibTorch ("),
              std::string::npos)
        << explicit_bf16.output;
    EXPECT_FALSE(fs::exists(config.run.run_dir + "/checkpoint.pt"));
  } else {
    EXPECT_EQ(explicit_bf16.exit_code, 0) << explicit_bf16.output;
  }
  fs::remove_all(dir);
}

// More threads than CPUs only time-slice (torch_threads 500 trained at 57
// samples/s on 2 CPUs): the trainer caps both thread counts at the CPUs
// this process may use, and says so. In a child process under taskset, one
// CPU: the log's torch_threads column reads 1 for a config asking 2.
TEST(Trainer, ThreadCountsAreCappedAtTheUsableCpus) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("trainer_thread_cap");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.torch_threads = UsableCpus() + 3;
  config.run.env_threads = UsableCpus() + 5;
  config.ppo.adapt_torch_threads = false;
  config.ppo.training_precision = TrainingPrecision::kFp32;
  config.Validate();
  RunResult run = TrainIterations(config, /*resume=*/false, 2);
  ASSERT_EQ(run.progress.size(), 2u);
  for (const TrainProgress& p : run.progress)
    EXPECT_EQ(p.torch_threads, UsableCpus());

  config.ppo.torch_threads = 2;
  config.ppo.adapt_torch_threads = true;
  config.run.env_threads = 2;
  config.run.total_samples = 2 * kBatch;
  config.run.run_dir = dir + "/run_taskset";
  config.Validate();
  WriteFileAtomic(dir + "/two.yaml", TrainConfigToYaml(config));
  const testing::CommandResult one_cpu =
      testing::RunCommand("taskset -c 0 " + std::string(MIMIC2D_BINARY) +
                          " train " + dir + "/two.yaml");
  ASSERT_EQ(one_cpu.exit_code, 0) << one_cpu.output;
  EXPECT_NE(one_cpu.output.find("agent.torch_threads 2 exceeds the 1 CPU(s) "
                                "this process may use; using 1"),
            std::string::npos)
      << one_cpu.output;
  EXPECT_NE(one_cpu.output.find("run.env_threads 2 exceeds the 1 CPU(s)"),
            std::string::npos)
      << one_cpu.output;
  const TrainingCurves curves =
      ReadTrainingLog(config.run.run_dir + "/train_log.csv");
  ASSERT_EQ(curves.num_rows(), 2);
  for (double threads : curves.columns.at("torch_threads"))
    EXPECT_EQ(threads, 1.0);
  fs::remove_all(dir);
}

// `kill -STOP` / `-CONT` (or Ctrl-Z and fg) on a training: an iteration
// that spans the stop measured the stop, and as one reading in the speed
// tuner's running average it read as a slowdown and moved the tuner off
// its pick (docs/training.md, "Throughput", item 3). Stopped 10 times for
// 0.1 s mid-training, the command says which iterations it left out.
TEST(Trainer, AStoppedIterationIsLeftOutOfTheSpeedTuner) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("trainer_stopped");
  TrainConfig config = TinyConfig(walk_path, dir);
  config.ppo.torch_threads = 2;
  config.ppo.adapt_torch_threads = true;
  config.ppo.training_precision = TrainingPrecision::kFp32;
  config.run.total_samples = 1'000'000'000;
  config.Validate();
  const std::string config_path = dir + "/tiny.yaml";
  WriteFileAtomic(config_path, TrainConfigToYaml(config));
  const std::string output_path = dir + "/out.txt";
  const pid_t pid = StartTraining(config_path, "", output_path);
  ASSERT_GT(pid, 0);
  auto read_output = [&] {
    std::ifstream in(output_path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  // Stop it only once it iterates (setup builds the task first).
  for (int wait = 0;
       wait < 600 && read_output().find("\nit ") == std::string::npos; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (int stop = 0; stop < 10; ++stop) {
    ::kill(-pid, SIGSTOP);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(-pid, SIGCONT);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string output = read_output();
  ASSERT_NE(output.find("interrupted after"), std::string::npos) << output;
  // Most stops land inside an iteration's timing, some between two.
  int left_out = 0;
  const std::string notice =
      "the process was stopped or the machine slept; its timing is left out";
  for (size_t at = output.find(notice); at != std::string::npos;
       at = output.find(notice, at + 1)) {
    ++left_out;
  }
  EXPECT_GE(left_out, 1) << output.substr(0, 4000);
  EXPECT_LE(left_out, 10);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace m2d
