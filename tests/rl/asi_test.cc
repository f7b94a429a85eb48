// ASI corrects noisy initial states (the paper's Noisy S.I.): a run whose
// initial-state buffers start with sigma = 0.5 rad of joint noise replaces
// them by visited states that match the 2D reference better; without ASI
// the buffers stay as filled.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "env/env_fixture.h"
#include "env/reward.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "rl/asi_updater.h"
#include "rl/checkpoint.h"
#include "rl/trainer.h"
#include "sim/simulation.h"
#include "test_paths.h"
#include "tiny_walk_config.h"

namespace m2d {
namespace {

namespace fs = std::filesystem;

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";
constexpr double kNoiseRad = 0.5;  // the paper's Noisy S.I.

// A 1 s walk bundle written into `dir`; 8 envs x 16 steps per iteration,
// every visited state offered to ASI, tiny networks, and the Learning
// test's faster learning rate (with the default 2e-4 the policy learns too
// slowly: 1000 iterations only took the error to 0.84x).
TrainConfig NoisyConfig(const std::string& walk_path, const std::string& dir,
                        bool asi_enabled) {
  TrainConfig config = testing::TinyWalkConfig(walk_path, dir);
  config.env.initial_state_noise_rad = kNoiseRad;
  config.ppo.num_envs = 8;
  config.ppo.steps_per_env = 16;
  config.ppo.minibatch_size = 64;
  config.ppo.epochs = 2;
  config.ppo.learning_rate = 5e-4;
  config.asi.enabled = asi_enabled;
  config.asi.capture_every_steps = 1;
  config.run.seed = 5;
  config.Validate();
  return config;
}

// The mean over frames of the 2D error (px, view 0, mean over keypoints) of
// each frame's best-scoring initial state: from the checkpoint's buffers,
// or from noise-free buffers when `checkpoint` is empty.
double MeanBestStateErrorPx(const TrainConfig& config,
                            const std::string& checkpoint) {
  auto character = LoadCharacterForSimulation(
      config.data.character_config, config.data.scene, config.env.simulation);
  auto reference =
      TrackingReference::Prepare({ReadBundle(config.data.bundles[0])},
                                 *character, config.env.simulation.control_hz);
  auto states = std::make_shared<InitialStates>(
      *reference, character, config.env.simulation, config.asi.buffer);
  TrackingEnv env(character, reference, states, config.env, 0);
  if (!checkpoint.empty()) {
    int action_size = 0;
    ActorCritic model(ReadCheckpointLayout(checkpoint, &action_size),
                      config.model, action_size);
    LoadCheckpoint(checkpoint, model, nullptr, states.get(),
                   env.simulation().Save());
  }
  const TrackedView& view = reference->views()[0];
  const int num_keypoints = character->keypoint_layout().num_keypoints();
  const StateBuffer& buffer = states->buffer(0);
  std::vector<float> observation(env.observation_size());
  double sum_px = 0.0;
  for (int frame = 0; frame < buffer.num_frames(); ++frame) {
    env.ResetTo(0, frame, buffer.entry(frame, buffer.Best(frame)).state,
                observation.data());
    sum_px += MeasureReprojection(env.projected_px().data(), env.in_front(),
                                  view.frame(frame), num_keypoints)
                  .mean_px;
  }
  return sum_px / buffer.num_frames();
}

struct BufferErrors {
  double as_filled_px = 0.0;  // before the first iteration
  double trained_px = 0.0;    // after training
};

BufferErrors TrainAndMeasure(const TrainConfig& config, int iterations) {
  Trainer trainer(config, /*resume=*/false);
  trainer.SaveCheckpoint();
  BufferErrors errors;
  errors.as_filled_px = MeanBestStateErrorPx(config, trainer.checkpoint_path());
  TrainSummary summary = trainer.Run(iterations, nullptr, nullptr);
  EXPECT_EQ(summary.iterations_run, iterations);
  errors.trained_px = MeanBestStateErrorPx(config, summary.checkpoint_path);
  return errors;
}

// Measured on this machine (seed 5, 1000 iterations = 128k samples, 28 s
// while a training shared the machine): the best states were 0.00 px from
// the reference without noise, 51.5 px as filled, 21.2 px after training
// (0.41x). Seeds 6 and 7 gave 46.9 -> 30.8 px (0.66x) and 51.8 -> 29.5 px
// (0.57x). After 600 iterations seed 5 was at 31.6 px (0.61x): the policy
// has to learn before its visited states beat the noise.
constexpr int kIterations = 1000;
constexpr double kMaxCorrectedRatio = 0.7;

TEST(Asi, CorrectsNoisyInitialStates) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("asi_corrects");
  const TrainConfig config = NoisyConfig(walk_path, dir, true);
  const double clean_px = MeanBestStateErrorPx(config, "");
  BufferErrors errors = TrainAndMeasure(config, kIterations);
  std::printf(
      "best initial states, mean 2D error: noise-free %.2f px, as filled "
      "%.2f px, after %d iterations %.2f px (%.2fx)\n",
      clean_px, errors.as_filled_px, kIterations, errors.trained_px,
      errors.trained_px / errors.as_filled_px);
  // The trainer filled the buffers with noise: far from the reference that
  // the noise-free states match.
  EXPECT_LT(clean_px, 2.0);
  EXPECT_GT(errors.as_filled_px, 20.0);
  EXPECT_LT(errors.trained_px, kMaxCorrectedRatio * errors.as_filled_px);
  fs::remove_all(dir);
}

// Training without ASI leaves the buffers alone, however long it runs (a
// few iterations show it: nothing else writes to them).
TEST(Asi, WithoutAsiTheNoisyBuffersStayAsFilled) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  const std::string dir = testing::TempDir("asi_disabled");
  const TrainConfig config = NoisyConfig(walk_path, dir, false);
  BufferErrors errors = TrainAndMeasure(config, 50);
  EXPECT_GT(errors.as_filled_px, 20.0);
  EXPECT_EQ(errors.trained_px, errors.as_filled_px);
  fs::remove_all(dir);
}

// Six iterations of 6 environments x 8 steps under sinusoidal actions of
// `amplitude` (normalized units), every state offered to `asi`, each
// iteration ending with its update (rescoring every other iteration).
void RunCapturingIterations(const testing::WalkTask& task,
                            const AsiUpdater::Critic& critic, float amplitude,
                            AsiUpdater& asi) {
  VecEnv envs(task.character, task.reference, task.initial_states, task.options,
              6, 3, 2);
  envs.Reset();
  int64_t step = 0;
  for (int iteration = 1; iteration <= 6; ++iteration) {
    asi.BeginRollout();
    for (int t = 0; t < 8; ++t, ++step) {
      for (int i = 0; i < envs.num_envs() * envs.action_size(); ++i)
        envs.actions()[i] = amplitude * std::sin(0.1f * i + 0.3f * step);
      envs.Step();
      asi.Capture(envs, t);
    }
    asi.Update(critic, envs.num_envs() * 8);
  }
}

// Rescoring reuses the observation each entry was captured or last scored
// with, as long as the entry holds the same state: every score must be the
// critic's value of the entry's own observation from a view its buffer
// serves, also after captures replaced entries. The critic here is the sum
// of the raw observation, so a score names the observation it came from.
TEST(Asi, RescoringScoresEveryEntrysOwnObservation) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(walk_path, 2.0);
  AsiOptions options;
  options.capture_every_steps = 1;
  options.rescore_every_iterations = 2;
  options.rescore_max_entries_per_sample = 0;  // half the frames each time
  AsiUpdater asi(task.character, task.reference, task.initial_states,
                 task.options, options, 3, 2);
  const AsiUpdater::Critic critic = [](const torch::Tensor& raw) {
    return raw.to(torch::kDouble).sum(1);
  };
  RunCapturingIterations(task, critic, 0.3f, asi);

  // Every entry against its observations from each view of its buffer.
  const InitialStates& states = *task.initial_states;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0);
  std::vector<float> observation(env.observation_size());
  const int num_views = static_cast<int>(task.reference->views().size());
  int checked = 0;
  for (int b = 0; b < states.num_buffers(); ++b) {
    const StateBuffer& buffer = states.buffer(b);
    for (int f = 0; f < buffer.num_frames(); ++f) {
      for (int e = 0; e < buffer.size(f); ++e) {
        double closest = 1e300;
        for (int v = 0; v < num_views; ++v) {
          if (states.BufferOf(v) != b) continue;
          env.ResetTo(v, f, buffer.entry(f, e).state, observation.data());
          double sum = 0.0;
          for (float x : observation) sum += x;
          closest = std::min(closest, std::abs(sum - buffer.entry(f, e).score));
        }
        EXPECT_LT(closest, 1e-3) << "buffer " << b << " frame " << f;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 60);
}

// Rescoring takes the buffers' frames in turn: an Update rescores whole
// frames until it holds rescore_max_entries_per_sample x its samples
// entries, each entry once per sweep, so that long references (tens of
// thousands of frames) cost a bounded share of each iteration and are
// still all rescored within a number of Updates.
TEST(Asi, RescoringTakesTheFramesInTurnWithinItsCap) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(walk_path, 2.0);
  AsiOptions options;
  options.rescore_every_iterations = 1;  // a whole sweep, but for the cap
  options.rescore_max_entries_per_sample = 0.5;
  constexpr int64_t kSamples = 20;  // so 10 entries per Update
  AsiUpdater asi(task.character, task.reference, task.initial_states,
                 task.options, options, 3, 2);
  InitialStates& states = *task.initial_states;
  int64_t num_entries = 0;
  int max_per_frame = 0;
  for (int b = 0; b < states.num_buffers(); ++b) {
    StateBuffer& buffer = states.buffer(b);
    for (int f = 0; f < buffer.num_frames(); ++f) {
      for (int e = 0; e < buffer.size(f); ++e) buffer.Rescore(f, e, -1.0);
      num_entries += buffer.size(f);
      max_per_frame = std::max(max_per_frame, buffer.size(f));
    }
  }
  ASSERT_GT(num_entries, 40);
  auto num_rescored_entries = [&] {
    int64_t count = 0;
    for (int b = 0; b < states.num_buffers(); ++b) {
      const StateBuffer& buffer = states.buffer(b);
      for (int f = 0; f < buffer.num_frames(); ++f)
        for (int e = 0; e < buffer.size(f); ++e)
          count += buffer.entry(f, e).score == 7.0;
    }
    return count;
  };
  const AsiUpdater::Critic critic = [](const torch::Tensor& raw) {
    return torch::full({raw.size(0)}, 7.0, torch::kDouble);
  };

  int updates = 0;
  while (asi.num_entries_rescored() < num_entries) {
    const int64_t before = asi.num_entries_rescored();
    asi.Update(critic, kSamples);
    ++updates;
    // Whole frames until 10 entries are held: 10 to 10 + a frame's less one.
    EXPECT_GE(asi.num_entries_rescored() - before, 1);
    EXPECT_LE(asi.num_entries_rescored() - before, 10 + max_per_frame - 1);
    // Each entry once: none rescored twice before the sweep ends.
    EXPECT_EQ(num_rescored_entries(),
              std::min(asi.num_entries_rescored(), num_entries));
    ASSERT_LE(updates, num_entries) << "the sweep does not end";
  }
  EXPECT_EQ(num_rescored_entries(), num_entries);
  EXPECT_LE(updates, (num_entries + 9) / 10);
  EXPECT_GE(updates, num_entries / (10 + max_per_frame - 1));
}

// The worst keypoint's distance (px) of `state` at `frame` from the 2D of
// the nearest of its buffer's views.
double NearestViewWorstErrorPx(const testing::WalkTask& task, int buffer,
                               int frame, const SimState& state) {
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0);
  std::vector<float> observation(env.observation_size());
  const int num_keypoints = task.character->keypoint_layout().num_keypoints();
  double nearest = 1e300;
  for (size_t v = 0; v < task.reference->views().size(); ++v) {
    if (task.initial_states->BufferOf(static_cast<int>(v)) != buffer) continue;
    env.ResetTo(static_cast<int>(v), frame, state, observation.data());
    nearest = std::min(
        nearest, MeasureReprojection(env.projected_px().data(), env.in_front(),
                                     task.reference->views()[v].frame(frame),
                                     num_keypoints)
                     .max_px);
  }
  return nearest;
}

// With asi.max_entry_error_px, the buffers keep only states near their
// frame's 2D, however highly the critic scores the others: a state 1 m off
// (what a resumed run's buffers may hold) gives way to the frame's anchor
// at the next rescoring, and captures of characters that wander off (the
// sinusoidal actions below) never enter.
TEST(Asi, KeepsOnlyStatesNearTheirFrames2D) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(walk_path, 2.0);
  constexpr double kBoundPx = 30.0;
  constexpr int kFarFrame = 5;
  AsiOptions options;
  options.capture_every_steps = 1;
  options.rescore_every_iterations = 2;
  options.rescore_max_entries_per_sample = 0;
  options.max_entry_error_px = kBoundPx;
  AsiUpdater asi(task.character, task.reference, task.initial_states,
                 task.options, options, 3, 2);
  StateBuffer& buffer = task.initial_states->buffer(0);
  SimState far = buffer.entry(kFarFrame, 0).state;
  far.qpos[task.character->root_qpos_address()] += 1.0;
  ASSERT_TRUE(buffer.Insert(kFarFrame, far, 1e9));
  ASSERT_GT(NearestViewWorstErrorPx(task, 0, kFarFrame, far), 3 * kBoundPx);

  // A critic that prizes every state alike, far or near.
  const AsiUpdater::Critic critic = [](const torch::Tensor& raw) {
    return torch::full({raw.size(0)}, 100.0, torch::kDouble);
  };
  RunCapturingIterations(task, critic, 0.8f, asi);

  EXPECT_GE(asi.num_entries_replaced(), 1);
  const InitialStates& states = *task.initial_states;
  int checked = 0, visited = 0;
  for (int b = 0; b < states.num_buffers(); ++b) {
    const StateBuffer& kept = states.buffer(b);
    for (int f = 0; f < kept.num_frames(); ++f) {
      const SimState* anchor = kept.anchor(f);
      for (int e = 0; e < kept.size(f); ++e) {
        const SimState& state = kept.entry(f, e).state;
        EXPECT_NE(state.qpos, far.qpos) << "frame " << f;
        ++checked;
        if (anchor != nullptr && state.qpos == anchor->qpos) continue;
        ++visited;
        EXPECT_LE(NearestViewWorstErrorPx(task, b, f, state), kBoundPx)
            << "buffer " << b << " frame " << f << " entry " << e;
      }
    }
  }
  EXPECT_GT(checked, 60);
  EXPECT_GT(visited, 10);  // captures did enter, within the bound
}

}  // namespace
}  // namespace m2d
