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
  EXPECT_FALSE(outcome.reference_ended);  // the time limit, not the clip
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
  EXPECT_TRUE(outcome.truncated);
  EXPECT_TRUE(outcome.reference_ended);
  EXPECT_EQ(steps, 3);
}

// first_frame_start_share sends that share of Resets to the clip's first
// frame and draws the rest uniformly, as share 0 draws them all.
TEST(TrackingEnv, AFirstFrameShareOfStartsBeginsAtTheClipsFirstFrame) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  const int num_start_frames = task.reference->views()[0].num_frames - 1;
  const int num_resets = 2000;
  std::vector<float> obs;
  auto first_frame_share = [&](double share, int* distinct_frames) {
    task.options.first_frame_start_share = share;
    TrackingEnv env(task.character, task.reference, task.initial_states,
                    task.options, 3);
    obs.resize(env.observation_size());
    std::vector<int> count(num_start_frames, 0);
    for (int i = 0; i < num_resets; ++i) {
      env.Reset(obs.data());
      ++count.at(env.episode().start_frame);
    }
    *distinct_frames = static_cast<int>(
        std::count_if(count.begin(), count.end(), [](int c) { return c > 0; }));
    return static_cast<double>(count[0]) / num_resets;
  };
  int distinct = 0;
  // Uniform: frame 0 about 1/60 of the starts, nearly every frame drawn.
  EXPECT_LT(first_frame_share(0.0, &distinct), 0.05);
  EXPECT_GT(distinct, num_start_frames * 9 / 10);
  // Half: 0.5 + 0.5/60 expected; 2000 draws give a sigma of 0.011.
  EXPECT_NEAR(first_frame_share(0.5, &distinct), 0.5 + 0.5 / num_start_frames,
              0.05);
  EXPECT_GT(distinct, num_start_frames * 9 / 10);
  EXPECT_DOUBLE_EQ(first_frame_share(1.0, &distinct), 1.0);
  EXPECT_EQ(distinct, 1);
  task.options.first_frame_start_share = 1.5;
  EXPECT_THROW(task.options.Validate(), ConfigError);
}

// env.pushes: the root is pushed with the configured force exactly during
// the scheduled steps, in a direction drawn per push; a state saved
// mid-push starts its episode unpushed; pushes move the character.
TEST(TrackingEnv, PushesActOnTheRootOnScheduleAndNoEpisodeStartsPushed) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  task.options.early_exit = false;
  const SimState start = task.initial_states->buffer(0).entry(0, 0).state;
  auto root_after = [&](const PushOptions& pushes, SimState* mid_push) {
    task.options.pushes = pushes;
    TrackingEnv env(task.character, task.reference, task.initial_states,
                    task.options, 9);
    std::vector<float> obs(env.observation_size()),
        action(env.action_size(), 0.0f);
    env.ResetTo(0, 0, start, obs.data());
    const int root = env.simulation().character().bodies()[0];
    std::vector<double> headings;
    for (int step = 0; step < 30; ++step) {
      env.Step(action.data(), obs.data());
      const double* force = env.simulation().data()->xfrc_applied + 6 * root;
      const double norm_n = std::hypot(force[0], force[1]);
      if (PushAtStep(step, 30.0, pushes) > 0) {
        EXPECT_NEAR(norm_n, pushes.force_n, 1e-9) << step;
        EXPECT_EQ(force[2], 0.0);
        headings.push_back(std::atan2(force[1], force[0]));
        if (mid_push != nullptr) *mid_push = env.simulation().Save();
      } else {
        EXPECT_EQ(norm_n, 0.0) << step;
      }
    }
    if (pushes.force_n > 0) {  // steps 15-20: one push, one direction
      EXPECT_EQ(headings.size(), 6u);
      EXPECT_EQ(headings.front(), headings.back());
    }
    return Eigen::Vector3d(env.simulation().data()->qpos);
  };
  SimState mid_push;
  const Eigen::Vector3d pushed = root_after({800.0, 0.5, 0.2}, &mid_push);
  const Eigen::Vector3d still = root_after({}, nullptr);
  EXPECT_GT((pushed - still).head<2>().norm(), 0.05);

  task.options.pushes = {800.0, 0.5, 0.2};
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 9);
  std::vector<float> obs(env.observation_size());
  env.ResetTo(0, 0, mid_push, obs.data());
  const int root = env.simulation().character().bodies()[0];
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(env.simulation().data()->xfrc_applied[6 * root + i], 0.0);
  task.options.pushes.duration_s = 0.6;  // longer than the period
  EXPECT_THROW(task.options.Validate(), ConfigError);
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

// Zero-shot multi-view: an environment observing views {1, 2} writes the
// proprioception once and then each view's block exactly as a one-view
// environment on that view would; a frame's worst error is the worse view's.
TEST(TrackingEnv, KViewsAreObservedAsTheirOneViewBlocksSideBySide) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  TrackingEnv both(task.character, task.reference, task.initial_states,
                   task.options, 1, 2);
  TrackingEnv first(task.character, task.reference, task.initial_states,
                    task.options, 1);
  TrackingEnv second(task.character, task.reference, task.initial_states,
                     task.options, 1);
  const ObservationLayout& layout = first.layout();
  ASSERT_EQ(both.observation_size(),
            layout.view_offset() + 2 * layout.view_size());
  std::vector<float> obs_both(both.observation_size()),
      obs_first(first.observation_size()),
      obs_second(second.observation_size());
  std::vector<float> action(first.action_size());
  const SimState& start = task.initial_states->buffer(0).entry(5, 0).state;
  both.ResetToViews({1, 2}, 5, start, obs_both.data());
  first.ResetTo(1, 5, start, obs_first.data());
  second.ResetTo(2, 5, start, obs_second.data());
  for (int step = 0; step < 8; ++step) {
    const int base = layout.view_offset(), block = layout.view_size();
    for (int i = 0; i < base + block; ++i)
      ASSERT_EQ(obs_both[i], obs_first[i]) << "step " << step << ", " << i;
    for (int i = 0; i < block; ++i) {
      ASSERT_EQ(obs_both[base + block + i], obs_second[base + i])
          << "step " << step << ", " << i;
    }
    for (size_t i = 0; i < action.size(); ++i)
      action[i] = 0.1f * std::sin(0.3f * i + step);
    StepOutcome a = both.Step(action.data(), obs_both.data());
    StepOutcome b = first.Step(action.data(), obs_first.data());
    StepOutcome c = second.Step(action.data(), obs_second.data());
    EXPECT_DOUBLE_EQ(a.error.max_px, std::max(b.error.max_px, c.error.max_px));
    EXPECT_NEAR(a.error.mean_px, 0.5 * (b.error.mean_px + c.error.mean_px),
                1e-9);
    if (a.terminated || a.truncated) break;
  }
  // K views must be views of one bundle, and as many as the env observes.
  EXPECT_THROW(both.ResetToViews({1}, 5, start, obs_both.data()), ConfigError);
  EXPECT_THROW(both.ResetTo(1, 5, start, obs_both.data()), ConfigError);
}

// Training's reference noise: an episode observes and is rewarded against
// its view's 2D with detector noise of the asked size, drawn afresh for
// each episode and reproducible from the seed; the shared reference, and an
// environment that was not asked (evaluation), see the 2D as given.
TEST(TrackingEnv, ReferenceNoiseCorruptsEachEpisodesOwnCopy) {
  TrackingTask task = testing::MakeGlidingTask(/*num_views=*/1);
  TrackingEnvOptions options;
  options.early_exit = false;  // every frame of the clip is reached
  options.training_reference_noise_px = 4.0;
  options.training_reference_drop = 0.1;
  TrackingEnv clean(task.character, task.reference, task.initial_states,
                    options, /*seed=*/7);
  TrackingEnv noisy(task.character, task.reference, task.initial_states,
                    options, /*seed=*/7);
  TrackingEnv again(task.character, task.reference, task.initial_states,
                    options, /*seed=*/7);
  noisy.SetReferenceNoise(options.training_reference_noise());
  again.SetReferenceNoise(options.training_reference_noise());
  const TrackedView& given = task.reference->views()[0];
  const std::vector<Keypoint2D> given_points = given.points;
  const SimState& start = task.initial_states->buffer(0).entry(0, 0).state;
  std::vector<float> obs_clean(clean.observation_size()),
      obs_noisy(noisy.observation_size()), obs_again(again.observation_size());
  std::vector<float> action(clean.action_size(), 0.0f);
  clean.ResetTo(0, 0, start, obs_clean.data());
  noisy.ResetTo(0, 0, start, obs_noisy.data());
  again.ResetTo(0, 0, start, obs_again.data());
  EXPECT_NE(obs_clean, obs_noisy);  // the future reference frames differ
  EXPECT_EQ(obs_noisy, obs_again);  // reproducible from the seed
  bool rewards_differ = false;
  for (int step = 0; step < given.num_frames - 1; ++step) {
    StepOutcome a = clean.Step(action.data(), obs_clean.data());
    StepOutcome b = noisy.Step(action.data(), obs_noisy.data());
    StepOutcome c = again.Step(action.data(), obs_again.data());
    ASSERT_FALSE(a.diverged || b.diverged);
    rewards_differ |= a.reward != b.reward;  // the same physics, other 2D
    EXPECT_EQ(b.reward, c.reward);
    if (a.truncated) break;
  }
  EXPECT_TRUE(rewards_differ);
  // Over the clip: the noise's size and the share of misses.
  const TrackedView& seen = noisy.view();
  ASSERT_EQ(seen.num_frames, given.num_frames);
  int present = 0, missed = 0;
  double sum_sq_px = 0.0;
  for (int t = 0; t < given.num_frames; ++t) {
    for (int j = 0; j < given.num_points; ++j) {
      const Keypoint2D& truth = given.frame(t)[j];
      const Keypoint2D& corrupted = seen.frame(t)[j];
      if (!truth.IsPresent()) continue;
      EXPECT_EQ(clean.view().frame(t)[j].x_px, truth.x_px);
      ++present;
      if (!corrupted.IsPresent()) {
        ++missed;
        continue;
      }
      sum_sq_px += std::pow(corrupted.x_px - truth.x_px, 2) +
                   std::pow(corrupted.y_px - truth.y_px, 2);
    }
  }
  ASSERT_GT(present, 400);
  EXPECT_NEAR(static_cast<double>(missed) / present, 0.1, 0.04);
  EXPECT_NEAR(std::sqrt(sum_sq_px / (2.0 * (present - missed))), 4.0, 0.5);
  // The shared reference is untouched; the next episode draws new noise.
  for (size_t i = 0; i < given_points.size(); ++i)
    ASSERT_EQ(given.points[i].x_px, given_points[i].x_px);
  const Keypoint2D first = seen.frame(0)[0];
  noisy.ResetTo(0, 0, start, obs_noisy.data());
  EXPECT_NE(noisy.view().frame(0)[0].x_px, first.x_px);
  // Turned off, the next episode sees the 2D as given.
  noisy.SetReferenceNoise(ReferenceNoise());
  noisy.ResetTo(0, 0, start, obs_noisy.data());
  clean.ResetTo(0, 0, start, obs_clean.data());
  EXPECT_EQ(obs_noisy, obs_clean);
  EXPECT_EQ(&noisy.view(), &given);
}

// The 3D baselines' target: from the reference's own state the character is
// on its 3D reference (every reward term near its weight), observes its own
// and the reference's keypoints relative to its root, and a character that
// stands while the reference walks away ends by the 3D exit.
TEST(TrackingEnv, ABody3DTargetFollowsTheInitialStatesMotion) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 3.0);
  TrackingEnvOptions options = task.options;
  options.target = TrackingTarget::kBody3D;
  options.early_exit = false;  // the 2D exit off: only the 3D one
  TrackingEnv env(task.character, task.reference, task.initial_states, options,
                  1);
  std::vector<float> observation(env.observation_size());
  const int frame = 10;
  const std::vector<BodyTarget3D>& motion = task.initial_states->motion(0);
  env.ResetTo(0, frame, *task.initial_states->buffer(0).anchor(frame),
              observation.data());
  // The current block is the character's keypoints, the l = 1 block the
  // reference's next frame, both about the character's root and heading.
  const ObservationLayout& layout = env.layout();
  const Eigen::Vector3d root = motion[frame].root_position_m;
  const Eigen::Quaterniond to_heading =
      InverseHeadingRotation(motion[frame].root_orientation);
  std::vector<float> expected(layout.view_size());
  WriteRootRelativePoints(motion[frame].keypoints_m.data(), 17, root,
                          to_heading, expected.data());
  WriteRootRelativePoints(motion[frame + 1].keypoints_m.data(), 17, root,
                          to_heading, expected.data() + 17 * 3);
  for (int i = 0; i < 2 * 17 * 3; ++i)
    EXPECT_NEAR(observation[layout.view_offset() + i], expected[i], 1e-5) << i;

  // Zero actions (PD targets mid-range): the first step is still close to
  // the reference; then the walker leaves the stander behind.
  std::vector<float> action(env.action_size(), 0.0f);
  StepOutcome outcome = env.Step(action.data(), observation.data());
  EXPECT_GT(outcome.terms.pose, 0.5);
  int steps = 1;
  while (!outcome.terminated && !outcome.truncated) {
    outcome = env.Step(action.data(), observation.data());
    ++steps;
  }
  EXPECT_TRUE(outcome.terminated);
  EXPECT_LT(steps, 60);

  // No 3D reference from a placed default pose; no objects or K views.
  EXPECT_THROW(TrackingEnv(task.character, task.reference, task.initial_states,
                           options, 1, 2),
               ConfigError);
}

// Asymmetric actor-critic: with critic_observes_3d the observation gains the
// critic-only block (the initial states' 3D reference and the camera) in
// front of the views, and everything the policy reads stays as it was.
// Without a 3D reference (a streamed rollout has no initial states) the
// block is zeros.
TEST(TrackingEnv, TheCriticOnlyBlockAddsTheReferenceAndCameraAndNothingElse) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 3.0);
  TrackingEnvOptions options = task.options;
  options.critic_observes_3d = true;
  TrackingEnv plain(task.character, task.reference, task.initial_states,
                    task.options, 1);
  TrackingEnv asymmetric(task.character, task.reference, task.initial_states,
                         options, 1);
  const ObservationLayout& layout = asymmetric.layout();
  ASSERT_EQ(layout.critic_only_size, CriticOnlySize(17));
  ASSERT_EQ(asymmetric.observation_size(),
            plain.observation_size() + CriticOnlySize(17));

  const int frame = 12;
  const SimState& start = *task.initial_states->buffer(0).anchor(frame);
  std::vector<float> a(plain.observation_size()),
      b(asymmetric.observation_size());
  plain.ResetTo(0, frame, start, a.data());
  asymmetric.ResetTo(0, frame, start, b.data());
  std::vector<float> action(plain.action_size(), 0.1f);
  plain.Step(action.data(), a.data());
  asymmetric.Step(action.data(), b.data());
  const int base = layout.actor_base_size();
  for (int i = 0; i < base; ++i) ASSERT_EQ(a[i], b[i]) << i;
  for (int i = 0; i < plain.layout().view_size(); ++i)
    ASSERT_EQ(a[base + i], b[layout.view_offset() + i]) << i;

  // The block, from the simulated root after the step (frame + 1).
  const Simulation& simulation = asymmetric.simulation();
  const int root_id = task.character->bodies()[0];
  const mjData* data = simulation.data();
  BodyKinematics root;
  root.positions_m = {Eigen::Vector3d(data->xpos + 3 * root_id)};
  root.orientations = {Eigen::Quaterniond(
      data->xquat[4 * root_id], data->xquat[4 * root_id + 1],
      data->xquat[4 * root_id + 2], data->xquat[4 * root_id + 3])};
  const std::vector<BodyTarget3D>& motion = task.initial_states->motion(0);
  const TrackedView& view = task.reference->views()[0];
  const PinholeCamera& camera =
      task.reference->bundles()[view.bundle].views[view.view].CameraAt(frame +
                                                                       1);
  std::vector<float> expected(CriticOnlySize(17));
  WriteCriticOnlyInputs(
      root, motion[frame + 1].keypoints_m.data(),
      motion[frame + 2].keypoints_m.data(), 17, camera.CenterWorld(),
      camera.rotation_world_to_camera().transpose(), expected.data());
  for (int i = 0; i < CriticOnlySize(17); ++i)
    EXPECT_NEAR(b[base + i], expected[i], 1e-5) << i;

  TrackingEnv streamed(task.character, task.reference, nullptr, options, 1);
  std::vector<float> c(streamed.observation_size(), 1.0f);
  streamed.ResetTo(0, frame, start, c.data());
  for (int i = 0; i < CriticOnlySize(17); ++i) EXPECT_EQ(c[base + i], 0.0f);
}

// camera follows_character: the camera moves with the simulated root's
// offset from the reference motion's root, so a character displaced on the
// ground is seen, rewarded and judged exactly as where it was (its path over
// the ground is not in the 2D); recorded cameras see the displacement. A
// streamed rollout's env has no motion to follow from.
TEST(TrackingEnv, AFollowingCameraSeesADisplacedCharacterAsIfItWereNot) {
  const PinholeCamera recorded =
      PinholeCamera::LookAt(Intrinsics{1000, 1000, 960, 540, 1920, 1080},
                            {4, 0, 1.5}, {0, 0, 1}, {0, 0, 1});
  const PinholeCamera moved =
      CameraFollowingCharacter(recorded, {1.0, 2.0, 0.9}, {1.5, 1.0, 0.7});
  EXPECT_LT((moved.CenterWorld() - recorded.CenterWorld() -
             Eigen::Vector3d(0.5, -1.0, 0.0))
                .norm(),
            1e-12);  // horizontal only: a root that sinks does not lower it

  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 3.0);
  TrackingEnvOptions following_options = task.options;
  following_options.camera = EpisodeCamera::kFollowsCharacter;
  TrackingEnv recorded_env(task.character, task.reference, task.initial_states,
                           task.options, 1);
  TrackingEnv following(task.character, task.reference, task.initial_states,
                        following_options, 1);
  TrackingEnv following_displaced(task.character, task.reference,
                                  task.initial_states, following_options, 1);
  const int frame = 12;
  const SimState& start = *task.initial_states->buffer(0).anchor(frame);
  SimState displaced = start;
  const int root = task.character->root_qpos_address();
  displaced.qpos[root] += 0.4;
  displaced.qpos[root + 1] -= 0.3;

  // At the start the root is the reference's: both cameras are the recorded.
  std::vector<float> a(recorded_env.observation_size()),
      b(following.observation_size()), c(following.observation_size());
  recorded_env.ResetTo(0, frame, start, a.data());
  following.ResetTo(0, frame, start, b.data());
  following_displaced.ResetTo(0, frame, displaced, c.data());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(b[i], a[i]) << i;
    ASSERT_NEAR(c[i], a[i], 1e-4) << i;
  }
  EXPECT_LT(
      (following_displaced.camera().CenterWorld() -
       recorded_env.camera().CenterWorld() - Eigen::Vector3d(0.4, -0.3, 0.0))
          .norm(),
      1e-9);
  std::vector<float> action(recorded_env.action_size(), 0.1f);
  for (int step = 0; step < 5; ++step) {
    StepOutcome expected = following.Step(action.data(), b.data());
    StepOutcome outcome = following_displaced.Step(action.data(), c.data());
    ASSERT_FALSE(expected.terminated);
    ASSERT_FALSE(outcome.terminated);
    // Flat ground: the physics is the same up to rounding.
    EXPECT_NEAR(outcome.reward, expected.reward, 1e-4) << step;
    EXPECT_NEAR(outcome.error.mean_px, expected.error.mean_px, 1e-3) << step;
    for (size_t i = 0; i < b.size(); ++i)
      ASSERT_NEAR(c[i], b[i], 1e-3) << "step " << step << ", input " << i;
  }

  // Recorded cameras see the displacement (0.5 m at 4.5 m: about 100 px).
  recorded_env.ResetTo(0, frame, displaced, a.data());
  StepOutcome outcome = recorded_env.Step(action.data(), a.data());
  EXPECT_TRUE(outcome.terminated || outcome.error.mean_px > 30.0);

  EXPECT_THROW(TrackingEnv(task.character, task.reference, nullptr,
                           following_options, 1),
               ConfigError);
}

// A camera that dollies from the start (generate --policy's) is the
// following camera at the start frame and from there moves with the
// simulated root alone: the following camera keeps each frame's offset from
// the reference's root (here gliding on under static cameras), the dolly
// keeps the start frame's.
TEST(TrackingEnv, ADollyFromStartKeepsTheStartFramesCameraAndMovesWithTheRoot) {
  TrackingTask task = testing::MakeGlidingTask(/*num_views=*/1, 2.0);
  TrackingEnvOptions following_options;
  following_options.early_exit = false;  // the frames are compared, not judged
  following_options.camera = EpisodeCamera::kFollowsCharacter;
  TrackingEnvOptions dolly_options = following_options;
  dolly_options.camera = EpisodeCamera::kDolliesFromStart;
  TrackingEnv following(task.character, task.reference, task.initial_states,
                        following_options, 1);
  TrackingEnv dolly(task.character, task.reference, task.initial_states,
                    dolly_options, 1);
  const int start_frame = 5;
  const int root = task.character->root_qpos_address();
  auto reference_root = [&](int frame) {
    const SimState& state = *task.initial_states->buffer(0).anchor(frame);
    return Eigen::Vector3d(state.qpos[root], state.qpos[root + 1], 0.0);
  };
  SimState start = *task.initial_states->buffer(0).anchor(start_frame);
  start.qpos[root] += 0.2;  // a start off the reference's root
  std::vector<float> a(following.observation_size()),
      b(dolly.observation_size());
  following.ResetTo(0, start_frame, start, a.data());
  dolly.ResetTo(0, start_frame, start, b.data());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(b[i], a[i]) << i;
  const PinholeCamera start_camera = dolly.camera();

  std::vector<float> action(following.action_size(), 0.0f);
  for (int step = 1; step <= 15; ++step) {
    // The same actions from the same state: one simulation, two cameras.
    following.Step(action.data(), a.data());
    dolly.Step(action.data(), b.data());
    const Eigen::Vector3d glided_m =
        reference_root(start_frame + step) - reference_root(start_frame);
    EXPECT_LT((dolly.camera().CenterWorld() - following.camera().CenterWorld() -
               glided_m)
                  .norm(),
              1e-9)
        << step;
    EXPECT_EQ(dolly.camera().rotation_world_to_camera(),
              start_camera.rotation_world_to_camera());
  }
  // 0.5 m/s for 0.5 s: the two views differ by a quarter metre.
  EXPECT_NEAR(
      (dolly.camera().CenterWorld() - following.camera().CenterWorld()).norm(),
      0.25, 0.01);
  EXPECT_THROW(
      TrackingEnv(task.character, task.reference, nullptr, dolly_options, 1),
      ConfigError);
}

}  // namespace
}  // namespace m2d
