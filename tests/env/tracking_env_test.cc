#include "env/tracking_env.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

#include "common/error.h"
#include "env/vec_env.h"
#include "env_fixture.h"

namespace m2d {
namespace {

// Kinematic replay: the character posed at each ground-truth frame projects
// onto the 2D reference of every view, so early exit never fires.
TEST(TrackingEnv, ReplayedTruthMatchesTheReferenceAndNeverExitsEarly) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 10.0);
  Simulation simulation(task.character, task.options.simulation);
  const ReferenceBundle& bundle = task.reference->bundles()[0];
  const int num_keypoints = 17;
  std::vector<double> xyz(3 * num_keypoints), xy(2 * num_keypoints);
  bool in_front[17];
  double worst_px = 0.0;
  for (const TrackedView& view : task.reference->views()) {
    for (int t = 0; t < view.num_frames; ++t) {
      simulation.SetPose(bundle.ground_truth->poses[t]);
      simulation.KeypointPositions(xyz.data());
      for (int j = 0; j < num_keypoints; ++j) {
        Projection p = bundle.views[view.view].CameraAt(t).Project(
            {xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]});
        xy[2 * j] = p.pixel_px.x();
        xy[2 * j + 1] = p.pixel_px.y();
        in_front[j] = p.in_front;
      }
      ReprojectionError error = MeasureReprojection(
          xy.data(), in_front, view.frame(t), num_keypoints);
      worst_px = std::max(worst_px, error.max_px);
      ASSERT_FALSE(ShouldExitEarly(error, task.options.early_exit_max_error_px))
          << "frame " << t;
    }
  }
  EXPECT_LT(worst_px, 1.0);  // sites equal the FK keypoints within 1 mm
}

// A deliberately wrong reference (the walk shown 200 px to the right and
// upside down) ends episodes at once; the true one does not at the start.
TEST(TrackingEnv, EarlyExitFiresOnAWrongReference) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  auto character = testing::LoadHumanoid(options.simulation);
  ReferenceBundle truth = testing::MakeWalkBundle(path, *character, 2.0);
  ReferenceBundle wrong = truth;
  for (ReferenceView& view : wrong.views) {
    for (int t = 0; t < view.clip.num_frames(); ++t) {
      for (int j = 0; j < 17; ++j) {
        Keypoint2D& k = view.clip.keypoints.at(t, j);
        k.x_px += 200.0;
        k.y_px = view.clip.image_height_px - k.y_px;
      }
    }
  }
  std::vector<ReferenceBundle> bundles = {truth, wrong};
  auto reference = TrackingReference::Prepare(bundles, *character,
                                              options.simulation.control_hz);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  TrackingEnv env(character, reference, states, options, 7);
  std::vector<float> obs(env.observation_size()),
      action(env.action_size(), 0.0f);
  const int num_views = static_cast<int>(truth.views.size());
  for (int view = 0; view < num_views; ++view) {
    env.ResetTo(view, 0, states->buffer(0).entry(0, 0).state, obs.data());
    StepOutcome outcome = env.Step(action.data(), obs.data());
    EXPECT_FALSE(outcome.terminated) << "true reference, view " << view;
    EXPECT_LT(outcome.error.max_px, 60.0);
    EXPECT_GT(outcome.reward, 0.3f);
    env.ResetTo(num_views + view, 0, states->buffer(1).entry(0, 0).state,
                obs.data());
    outcome = env.Step(action.data(), obs.data());
    EXPECT_TRUE(outcome.terminated) << "wrong reference, view " << view;
    EXPECT_TRUE(env.episode().failed);
  }
}

TEST(TrackingEnv, EpisodesAreTruncatedAtTheTimeLimitAndAtTheClipEnd) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  task.options.early_exit = false;
  task.options.max_episode_s = 0.5;  // 15 steps
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 1);
  std::vector<float> obs(env.observation_size()),
      action(env.action_size(), 0.0f);
  env.ResetTo(0, 0, task.initial_states->buffer(0).entry(0, 0).state,
              obs.data());
  int steps = 0;
  StepOutcome outcome;
  do {
    outcome = env.Step(action.data(), obs.data());
    ++steps;
  } while (!outcome.truncated && !outcome.terminated);
  EXPECT_TRUE(outcome.truncated);
  EXPECT_EQ(steps, 15);
  int last = task.reference->views()[0].num_frames - 1;
  env.ResetTo(0, last - 3,
              task.initial_states->buffer(0).entry(last - 3, 0).state,
              obs.data());
  steps = 0;
  do {
    outcome = env.Step(action.data(), obs.data());
    ++steps;
  } while (!outcome.truncated && !outcome.terminated);
  EXPECT_EQ(steps, 3);
}

// Zero and random actions for 10 000 control steps each (4 envs): no NaN in
// any observation or reward, no crash; episodes end and restart.
TEST(VecEnv, ZeroAndRandomActionRolloutsStayFinite) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 4.0);
  for (bool random_actions : {false, true}) {
    VecEnv envs(task.character, task.reference, task.initial_states,
                task.options, 4, 11, 2);
    envs.Reset();
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    std::vector<FinishedEpisode> finished;
    for (int step = 0; step < 2500; ++step) {
      for (int i = 0; i < envs.num_envs() * envs.action_size(); ++i) {
        envs.actions()[i] = random_actions ? uniform(rng) : 0.0f;
      }
      envs.Step(&finished);
      for (int i = 0; i < envs.num_envs() * envs.observation_size(); ++i) {
        ASSERT_TRUE(std::isfinite(envs.observations()[i])) << "step " << step;
      }
      for (int i = 0; i < envs.num_envs(); ++i)
        ASSERT_TRUE(std::isfinite(envs.rewards()[i]));
    }
    EXPECT_GT(finished.size(), 4u) << (random_actions ? "random" : "zero");
  }
}

// Environment i is seeded seed + i, so one or two threads give the same run,
// and so do two threads each stepping its own share (StepRange, as the
// per-thread collector does).
TEST(VecEnv, ResultsDoNotDependOnTheThreadCountOrTheShares) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  std::vector<std::vector<float>> runs;
  for (int threads : {1, 2, 0}) {  // 0: two shares on two std::threads
    VecEnv envs(task.character, task.reference, task.initial_states,
                task.options, 6, 3, std::max(threads, 1));
    envs.Reset();
    std::vector<FinishedEpisode> finished, first_share, second_share;
    for (int step = 0; step < 60; ++step) {
      for (int i = 0; i < envs.num_envs() * envs.action_size(); ++i) {
        envs.actions()[i] = 0.3f * std::sin(0.1f * (i + step));
      }
      if (threads > 0) {
        envs.Step(&finished);
      } else {
        std::thread first([&] { envs.StepRange(0, 2, &first_share); });
        envs.StepRange(2, 6, &second_share);
        first.join();
      }
    }
    if (threads == 0) {
      finished = first_share;
      finished.insert(finished.end(), second_share.begin(), second_share.end());
    }
    std::vector<float> run(
        envs.observations(),
        envs.observations() + envs.num_envs() * envs.observation_size());
    for (const FinishedEpisode& episode : finished) {
      run.push_back(static_cast<float>(episode.env));
      run.push_back(static_cast<float>(episode.stats.steps));
    }
    runs.push_back(run);
  }
  EXPECT_EQ(runs[0], runs[1]);
  // The shares report their episodes in share order, not step order.
  std::sort(runs[0].begin(), runs[0].end());
  std::sort(runs[2].begin(), runs[2].end());
  EXPECT_EQ(runs[0], runs[2]);
}

// ASI keeps the observation a state was captured with and scores it again
// later instead of restoring it: the two must be the same observation.
TEST(TrackingEnv, AStateRestoredIsObservedAsItWasAfterItsStep) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  TrackingEnv stepped(task.character, task.reference, task.initial_states,
                      task.options, 4);
  TrackingEnv restored(task.character, task.reference, task.initial_states,
                       task.options, 5);
  std::vector<float> observation(stepped.observation_size()),
      observed_again(stepped.observation_size()), action(stepped.action_size());
  const int view = 1;
  stepped.ResetTo(view, 3, task.initial_states->buffer(0).entry(3, 0).state,
                  observation.data());
  int steps = 0;
  for (; steps < 12; ++steps) {
    for (size_t i = 0; i < action.size(); ++i)
      action[i] = 0.05f * std::sin(0.7f * i + steps);
    StepOutcome outcome = stepped.Step(action.data(), observation.data());
    if (outcome.terminated || outcome.truncated) break;
    restored.ResetTo(view, stepped.frame(), stepped.simulation().Save(),
                     observed_again.data());
    for (size_t i = 0; i < observation.size(); ++i) {
      ASSERT_NEAR(observed_again[i], observation[i], 1e-5)
          << "step " << steps << ", element " << i;
    }
  }
  EXPECT_GE(steps, 6);
}

TEST(TrackingEnv, BundleAtTheWrongRateIsRejected) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  auto character = testing::LoadHumanoid(options.simulation);
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 1.0);
  bundle.fps = 25.0;
  std::vector<ReferenceBundle> bundles = {bundle};
  EXPECT_THROW(TrackingReference::Prepare(bundles, *character, 30.0),
               InputError);
}

}  // namespace
}  // namespace m2d
