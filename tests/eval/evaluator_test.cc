#include "eval/evaluator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "env/env_fixture.h"
#include "env/task.h"

namespace m2d {
namespace {

using testing::ZeroPolicy;

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";

ZeroPolicy MakeZeroPolicy(const testing::WalkTask& task) {
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0);
  return ZeroPolicy(env.observation_size(), env.action_size());
}

// Rollouts no frame can fail (1e6 px): each runs its length.
EvalOptions RunToLength(int episodes_per_view, double episode_s) {
  EvalOptions options;
  options.episodes_per_view = episodes_per_view;
  options.episode_s = episode_s;
  options.success_threshold_px = 1e6;
  return options;
}

// Two rollouts of at most 3 s (90 frames at 30 Hz) per view, judged by
// the 100-px default: the standing character fails the walk in each.
EvalOptions TwoShortRollouts() {
  EvalOptions options;
  options.episodes_per_view = 2;
  options.episode_s = 3.0;
  return options;
}

// `task`'s walk evaluated with its 3D truth.
std::vector<EvalRow> EvaluateWalk(Policy& policy, const testing::WalkTask& task,
                                  const EvalOptions& options) {
  return EvaluatePolicy(policy, task.character, task.reference,
                        task.initial_states, task.options, options,
                        {task.reference->bundles()[0].ground_truth});
}

TEST(EvaluatePolicy, AStandingPolicyFailsToTrackTheWalk) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 4.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  const EvalOptions options = TwoShortRollouts();
  std::vector<EvalRow> rows = EvaluateWalk(policy, task, options);

  const int episode_frames = 90;
  ASSERT_EQ(rows.size(), task.reference->views().size());
  for (const EvalRow& row : rows) {
    SCOPED_TRACE(row.view);
    EXPECT_EQ(row.bundle, "walk");
    EXPECT_EQ(row.episodes, 2);
    // The walk leaves the standing character behind: every rollout hits the
    // 100 px early exit long before the episode's end.
    EXPECT_EQ(row.succ, 0.0);
    EXPECT_GE(row.mean_frames, 1.0);
    EXPECT_LT(row.mean_frames, 0.5 * episode_frames);
    EXPECT_TRUE(std::isfinite(row.e2d_px));
    EXPECT_GT(row.e2d_px, 0.0);
    EXPECT_LT(row.e2d_px, options.success_threshold_px);
    // The bundle has 3D truth (from the motion) and no objects.
    EXPECT_TRUE(std::isfinite(row.e3d_mm));
    EXPECT_GT(row.e3d_mm, 0.0);
    EXPECT_GE(row.e3d_root_mm, 0.0);
    EXPECT_GT(row.e3d_pa_mm, 0.0);
    EXPECT_LE(row.e3d_pa_mm, row.e3d_root_mm);
    EXPECT_EQ(row.eo2d_px, -1.0);
    EXPECT_TRUE(std::isfinite(row.jitter));
    // Each rollout is reported: where it started and when it failed.
    ASSERT_EQ(row.rollouts.size(), 2u);
    double frames = 0;
    for (const EvalRollout& rollout : row.rollouts) {
      EXPECT_FALSE(rollout.succeeded);
      frames += rollout.frames;
    }
    EXPECT_DOUBLE_EQ(frames / 2, row.mean_frames);
    EXPECT_EQ(row.rollouts[0].start_frame, 0);
    EXPECT_GT(row.rollouts[1].start_frame, 0);
  }
  EvalRow all = AggregateRows(rows);
  EXPECT_TRUE(all.rollouts.empty());
  EXPECT_EQ(all.episodes, 2 * static_cast<int>(rows.size()));
  EXPECT_EQ(all.succ, 0.0);
}

TEST(EvaluatePolicy, RecordedFramesShowWhereAndOnWhichKeypointRolloutsFail) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 4.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  EvalOptions options = TwoShortRollouts();
  const std::vector<EvalRow> plain = EvaluateWalk(policy, task, options);
  options.record_frames = true;
  const std::vector<EvalRow> rows = EvaluateWalk(policy, task, options);
  ASSERT_EQ(rows.size(), plain.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    SCOPED_TRACE(rows[r].view);
    // Recording changes nothing measured.
    EXPECT_DOUBLE_EQ(rows[r].e2d_px, plain[r].e2d_px);
    EXPECT_DOUBLE_EQ(rows[r].e3d_pa_mm, plain[r].e3d_pa_mm);
    for (size_t e = 0; e < rows[r].rollouts.size(); ++e) {
      const EvalRollout& rollout = rows[r].rollouts[e];
      EXPECT_TRUE(plain[r].rollouts[e].trace.empty());
      EXPECT_EQ(plain[r].rollouts[e].end, rollout.end);
      // One record per step, of consecutive reference frames; the standing
      // character fails the walk by early exit at the last one, and only
      // there is a keypoint off by more than the threshold.
      ASSERT_EQ(static_cast<int>(rollout.trace.size()), rollout.frames);
      EXPECT_EQ(rollout.end, RolloutEnd::kEarlyExit);
      double sum_mean_px = 0;
      for (size_t k = 0; k < rollout.trace.size(); ++k) {
        const EvalFrame& frame = rollout.trace[k];
        EXPECT_EQ(frame.frame, rollout.start_frame + static_cast<int>(k) + 1);
        EXPECT_EQ(frame.keypoints_present, 17);
        EXPECT_LE(frame.mean_px, frame.worst_px);
        EXPECT_GE(frame.worst_keypoint, 0);
        EXPECT_LT(frame.worst_keypoint, 17);
        EXPECT_GT(frame.pa_mm, 0.0);  // with the truth
        EXPECT_EQ(frame.worst_px > options.success_threshold_px,
                  k + 1 == rollout.trace.size());
        sum_mean_px += frame.mean_px;
      }
      EXPECT_NEAR(sum_mean_px / rollout.frames, rollout.e2d_px, 1e-9);
      EXPECT_EQ(rollout.last_worst_keypoint,
                rollout.trace.back().worst_keypoint);
    }
  }
  // A rollout no frame can fail, longer than the clip, ends at its end.
  for (const EvalRow& row : EvaluateWalk(policy, task, RunToLength(1, 10.0))) {
    ASSERT_EQ(row.rollouts.size(), 1u);
    EXPECT_EQ(row.rollouts[0].end, RolloutEnd::kClipEnd);
    EXPECT_EQ(row.rollouts[0].frames,
              task.reference->bundles()[0].num_frames() - 1);
  }
}

TEST(EvaluatePolicy, TheMeanKeypointRuleFailsNoRolloutEarlier) {
  // A frame's mean error never exceeds its worst keypoint's, so judged by
  // the mean every rollout lasts at least as long; the standing character
  // loses a limb's keypoint past 100 px before the frame's mean, so some
  // last longer.
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 4.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  auto rows_by = [&](FrameErrorMeasure measure) {
    EvalOptions options = TwoShortRollouts();
    options.success_measure = measure;
    return EvaluatePolicy(policy, task.character, task.reference,
                          task.initial_states, task.options, options);
  };
  const std::vector<EvalRow> by_worst = rows_by(FrameErrorMeasure::kWorst);
  const std::vector<EvalRow> by_mean = rows_by(FrameErrorMeasure::kMean);
  ASSERT_EQ(by_worst.size(), by_mean.size());
  int frames_by_worst = 0, frames_by_mean = 0;
  for (size_t r = 0; r < by_worst.size(); ++r) {
    ASSERT_EQ(by_worst[r].rollouts.size(), by_mean[r].rollouts.size());
    for (size_t k = 0; k < by_worst[r].rollouts.size(); ++k) {
      EXPECT_EQ(by_worst[r].rollouts[k].start_frame,
                by_mean[r].rollouts[k].start_frame);
      EXPECT_GE(by_mean[r].rollouts[k].frames, by_worst[r].rollouts[k].frames);
      frames_by_worst += by_worst[r].rollouts[k].frames;
      frames_by_mean += by_mean[r].rollouts[k].frames;
    }
  }
  EXPECT_GT(frames_by_mean, frames_by_worst);
}

TEST(EvaluatePolicy, AGenerousThresholdLetsEveryEpisodeRunItsLength) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  std::vector<EvalRow> rows = EvaluateWalk(policy, task, RunToLength(3, 0.5));
  ASSERT_EQ(rows.size(), task.reference->views().size());
  for (const EvalRow& row : rows) {
    SCOPED_TRACE(row.view);
    EXPECT_EQ(row.succ, 1.0);
    EXPECT_EQ(row.mean_frames, 15.0);  // 0.5 s at 30 Hz, truncated
    EXPECT_TRUE(std::isfinite(row.e2d_px));
    EXPECT_GT(row.e2d_px, 0.0);
    // Starts spread from the first frame to the last that leaves a whole
    // episode (61 frames: 0, 22, 45).
    ASSERT_EQ(row.rollouts.size(), 3u);
    const int starts[] = {0, 22, 45};
    for (int e = 0; e < 3; ++e) {
      EXPECT_EQ(row.rollouts[e].start_frame, starts[e]);
      EXPECT_EQ(row.rollouts[e].frames, 15);
      EXPECT_TRUE(row.rollouts[e].succeeded);
      // The last start's episode ends on the clip's last frame: the clip's
      // end, which also ends the task.
      EXPECT_EQ(row.rollouts[e].end,
                e < 2 ? RolloutEnd::kTimeLimit : RolloutEnd::kClipEnd);
    }
  }
  // The policy ignores what it observes, so every view rolls out the same
  // motion from the same start frames: the 3D metrics, which never look
  // through a camera, agree across views.
  for (const EvalRow& row : rows) {
    EXPECT_DOUBLE_EQ(row.e3d_mm, rows[0].e3d_mm);
    EXPECT_DOUBLE_EQ(row.jitter, rows[0].jitter);
  }
  EXPECT_GT(rows[0].e3d_mm, 0.0);
  EvalRow all = AggregateRows(rows);
  EXPECT_EQ(all.succ, 1.0);
  EXPECT_EQ(all.mean_frames, 15.0);
}

// Found by fuzzing: a reference whose keypoints are all missing after frame
// 2 evaluated to Succ 100 %, E2D 0. Frames without reference keypoints
// cannot be judged; a rollout made mostly of them is no success, and E2D
// averages only the frames it could measure.
TEST(EvaluatePolicy, AMissingReferenceIsNoSuccess) {
  M2D_REQUIRE_SHARED(path, kWalk);
  auto character = testing::LoadHumanoid(SimulationOptions());
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 2.0);
  for (ReferenceView& view : bundle.views) {
    for (int t = 3; t < view.clip.num_frames(); ++t) {
      for (int j = 0; j < view.clip.keypoints.num_keypoints(); ++j)
        view.clip.keypoints.at(t, j) = Keypoint2D();
    }
  }
  TrackingTaskOptions task_options;
  TrackingTask task = BuildTrackingTask(character, {bundle}, task_options);
  TrackingEnvOptions env_options;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  env_options, 0);
  ZeroPolicy policy(env.observation_size(), env.action_size());
  EvalOptions options;
  options.episodes_per_view = 1;
  options.episode_s = 1.0;
  options.success_threshold_px = 1e6;  // no measured frame can fail
  const std::vector<EvalRow> rows =
      EvaluatePolicy(policy, task.character, task.reference,
                     task.initial_states, env_options, options);
  ASSERT_FALSE(rows.empty());
  for (const EvalRow& row : rows) {
    SCOPED_TRACE(row.view);
    EXPECT_EQ(row.succ, 0.0);
    EXPECT_GT(row.e2d_px, 0.0);  // the two measured frames, not 0
  }
}

// A policy that never saw the truth (estimated cameras and starts) is
// still measured against it when it is handed to the evaluator: no global
// E3D (the worlds differ), root-relative E3D after the best yaw, PA-MPJPE.
// Without the truth, no E3D at all. No shared data: a gliding pose.
TEST(EvaluatePolicy, HiddenTruthMeasuresAPolicyOfEstimatedWorlds) {
  TrackingEnvOptions env_options;
  auto character = testing::LoadHumanoid(env_options.simulation);
  ReferenceBundle bundle = testing::MakeGlidingBundle(*character, 1.0);
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{1.2, {2.0, 1.0, 0.0}}, {-0.5, {-1.0, 0.5, 0.0}}});
  const std::optional<GroundTruth3D> hidden = bundle.ground_truth;
  TrackingTaskOptions task_options;
  task_options.simulation = env_options.simulation;
  EvalOptions options;
  options.episodes_per_view = 2;
  options.episode_s = 0.3;
  options.success_threshold_px = 1e6;

  auto evaluate = [&](const TaskSources& sources, bool with_truth) {
    task_options.sources = sources;
    TrackingTask task = BuildTrackingTask(character, {bundle}, task_options);
    TrackingEnv env(task.character, task.reference, task.initial_states,
                    env_options, 0);
    ZeroPolicy policy(env.observation_size(), env.action_size());
    std::vector<std::optional<GroundTruth3D>> truth;
    if (with_truth) truth.push_back(hidden);
    return EvaluatePolicy(policy, task.character, task.reference,
                          task.initial_states, env_options, options, truth);
  };
  const TaskSources estimate{InitialStateSource::kEstimate,
                             CameraSource::kEstimate};
  std::vector<EvalRow> estimated = evaluate(estimate, true);
  std::vector<EvalRow> truth = evaluate(TaskSources(), true);
  ASSERT_EQ(estimated.size(), 2u);
  for (size_t v = 0; v < estimated.size(); ++v) {
    SCOPED_TRACE(estimated[v].view);
    EXPECT_EQ(estimated[v].e3d_mm, -1.0);
    EXPECT_GT(truth[v].e3d_mm, 0.0);
    // The same physics in a turned world: the aligned errors agree, up to
    // the falling body amplifying rounding and the estimate's lift out of
    // the floor (measured: 5.5 and 2.9 mm of about 175 and 95 mm).
    EXPECT_NEAR(estimated[v].e3d_root_mm, truth[v].e3d_root_mm,
                0.1 * truth[v].e3d_root_mm);
    EXPECT_NEAR(estimated[v].e3d_pa_mm, truth[v].e3d_pa_mm,
                0.1 * truth[v].e3d_pa_mm);
    EXPECT_GE(estimated[v].e3d_pa_mm, 0.0);
  }
  for (const EvalRow& row : evaluate(estimate, false)) {
    EXPECT_EQ(row.e3d_mm, -1.0);
    EXPECT_EQ(row.e3d_root_mm, -1.0);
    EXPECT_EQ(row.e3d_pa_mm, -1.0);
  }
}

TEST(EvaluatePolicy, APolicyForAnotherEnvironmentIsRejected) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 1.0);
  ZeroPolicy right = MakeZeroPolicy(task);
  ZeroPolicy wrong(right.observation_size() + 1, right.action_size());
  try {
    EvaluatePolicy(wrong, task.character, task.reference, task.initial_states,
                   task.options, EvalOptions());
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "policy");
    EXPECT_NE(
        error.problem().find(std::to_string(right.observation_size() + 1)),
        std::string::npos);
  }
}

TEST(EvaluatePolicy, InvalidOptionsAreRejected) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 1.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  EvalOptions options;
  options.episodes_per_view = 0;
  EXPECT_THROW(EvaluatePolicy(policy, task.character, task.reference,
                              task.initial_states, task.options, options),
               ConfigError);
}

// A policy trained with a stricter (or looser) early exit, with pushes or
// with a 3D exit is judged by the success rule alone: the rule's threshold
// and measure, the evaluation's length, no pushes unless asked for; the
// rest (simulation, horizon, reward) is the training's.
TEST(EvaluatePolicy, EveryPolicyIsJudgedByTheSuccessRuleNotItsTrainingExit) {
  TrackingEnvOptions trained;
  trained.early_exit = false;
  trained.early_exit_max_error_px = 50.0;
  trained.early_exit_measure = FrameErrorMeasure::kMean;
  trained.pushes.force_n = 100.0;
  trained.reward_3d.early_exit_max_error_m = 0.5;
  trained.num_future_frames = 7;
  trained.max_episode_s = 10.0;
  EvalOptions options;
  options.episode_s = 60.0;
  const TrackingEnvOptions judged = JudgedEnvOptions(trained, options);
  EXPECT_TRUE(judged.early_exit);
  EXPECT_EQ(judged.early_exit_max_error_px, 100.0);
  EXPECT_EQ(judged.early_exit_measure, FrameErrorMeasure::kWorst);
  EXPECT_EQ(judged.pushes.force_n, 0.0);
  EXPECT_EQ(judged.reward_3d.early_exit_max_error_m, 0.0);
  EXPECT_EQ(judged.max_episode_s, 60.0);
  EXPECT_EQ(judged.num_future_frames, 7);
  options.success_threshold_px = 80.0;
  options.success_measure = FrameErrorMeasure::kMean;
  options.pushes.force_n = 300.0;
  const TrackingEnvOptions asked = JudgedEnvOptions(trained, options);
  EXPECT_EQ(asked.early_exit_max_error_px, 80.0);
  EXPECT_EQ(asked.early_exit_measure, FrameErrorMeasure::kMean);
  EXPECT_EQ(asked.pushes.force_n, 300.0);
}

// Pushes start every every_s into an episode (not at its start) and last
// duration_s, whole control steps at the control rate.
TEST(EvaluatePolicy, PushesFollowTheirScheduleInControlSteps) {
  PushOptions pushes;
  EXPECT_EQ(PushAtStep(60, 30.0, pushes), 0);  // no force: no push
  pushes.force_n = 300.0;                      // every 2 s for 0.2 s
  EXPECT_EQ(PushAtStep(0, 30.0, pushes), 0);
  EXPECT_EQ(PushAtStep(59, 30.0, pushes), 0);
  for (int step = 60; step < 66; ++step)
    EXPECT_EQ(PushAtStep(step, 30.0, pushes), 1) << step;
  EXPECT_EQ(PushAtStep(66, 30.0, pushes), 0);
  EXPECT_EQ(PushAtStep(119, 30.0, pushes), 0);
  EXPECT_EQ(PushAtStep(120, 30.0, pushes), 2);
  pushes.duration_s = pushes.every_s;  // one push after another
  EXPECT_EQ(PushAtStep(119, 30.0, pushes), 1);
  EXPECT_EQ(PushAtStep(120, 30.0, pushes), 2);
  EvalOptions options;
  options.pushes = pushes;
  options.pushes.duration_s = 3.0;  // longer than the period
  EXPECT_THROW(options.Validate(), ConfigError);
  options.pushes.duration_s = 0.2;
  options.pushes.force_n = -1.0;
  EXPECT_THROW(options.Validate(), ConfigError);
  options.pushes.force_n = 0.0;
  options.object_start_square_m = std::nan("");
  EXPECT_THROW(options.Validate(), ConfigError);
}

// A policy that ignores what it sees rolls the same motion out in every
// view (AGenerousThreshold... above); pushed, each rollout goes its own way
// (a direction drawn per push), farther from the truth, and the same seed
// repeats the evaluation exactly.
TEST(EvaluatePolicy, PushesMoveTheCharacterAndRepeatForASeed) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  ZeroPolicy policy = MakeZeroPolicy(task);
  EvalOptions options = RunToLength(1, 1.5);
  auto evaluate = [&](const EvalOptions& eval_options) {
    return EvaluateWalk(policy, task, eval_options);
  };
  const std::vector<EvalRow> still = evaluate(options);
  options.pushes.force_n = 1000.0;
  options.pushes.every_s = 0.5;
  const std::vector<EvalRow> pushed = evaluate(options);
  const std::vector<EvalRow> again = evaluate(options);
  ASSERT_EQ(pushed.size(), 4u);
  double e3d_still = 0, e3d_pushed = 0;
  for (size_t r = 0; r < pushed.size(); ++r) {
    EXPECT_DOUBLE_EQ(still[r].e3d_mm, still[0].e3d_mm);
    EXPECT_DOUBLE_EQ(again[r].e3d_mm, pushed[r].e3d_mm);
    EXPECT_DOUBLE_EQ(again[r].jitter, pushed[r].jitter);
    if (r > 0) {
      EXPECT_NE(pushed[r].e3d_mm, pushed[0].e3d_mm);
    }
    e3d_still += still[r].e3d_mm;
    e3d_pushed += pushed[r].e3d_mm;
  }
  EXPECT_GT(e3d_pushed, 1.2 * e3d_still);
  options.perturbation_seed = 2;
  EXPECT_NE(evaluate(options)[0].e3d_mm, pushed[0].e3d_mm);
}

// The ball's start moved within a 1 m square (the paper's "w/ Rnd."): the
// resting ball no longer sits where its 2D shows it, so EO2D rises from
// nearly 0; bundles without an object refuse the option.
TEST(EvaluatePolicy, ObjectStartsMoveWithinTheirSquare) {
  M2D_REQUIRE_SHARED(path, kWalk);
  SimulationOptions simulation;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      simulation);
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 1.0);
  testing::AddRestingBall(*character, &bundle);
  TrackingTask task =
      BuildTrackingTask(character, {bundle}, TrackingTaskOptions());
  TrackingEnvOptions env_options;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  env_options, 0);
  ZeroPolicy policy(env.observation_size(), env.action_size());
  EvalOptions options = RunToLength(1, 0.3);
  auto eo2d = [&](double square_m) {
    options.object_start_square_m = square_m;
    return AggregateRows(EvaluatePolicy(policy, task.character, task.reference,
                                        task.initial_states, env_options,
                                        options))
        .eo2d_px;
  };
  const double in_place = eo2d(0.0);
  EXPECT_LT(in_place, 1.0);
  EXPECT_GT(eo2d(1.0), in_place + 5.0);

  M2D_REQUIRE_SHARED(walk, kWalk);
  testing::WalkTask no_ball = testing::MakeWalkTask(walk, 1.0);
  ZeroPolicy walker = MakeZeroPolicy(no_ball);
  try {
    EvaluatePolicy(walker, no_ball.character, no_ball.reference,
                   no_ball.initial_states, no_ball.options, options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(error.problem().find("track an object"), std::string::npos)
        << error.what();
  }
}

// Zero-shot multi-view: K = 3 rolls each of the walk's 4 views out with the
// two next ones, named together; with a policy that ignores what it sees,
// the 3D outcome equals the one-view evaluation's from the same starts. A
// view set needs one world: per-view estimated cameras are refused, a rig's
// estimate is not.
TEST(EvaluatePolicy, KViewsAreRolledOutTogetherInTheTrueCamerasWorld) {
  M2D_REQUIRE_SHARED(path, kWalk);
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  EvalOptions options;
  options.episodes_per_view = 2;
  options.episode_s = 0.5;
  options.success_threshold_px = 1e6;
  ZeroPolicy one_view = MakeZeroPolicy(task);
  std::vector<EvalRow> single = EvaluatePolicy(
      one_view, task.character, task.reference, task.initial_states,
      task.options, options, {task.reference->bundles()[0].ground_truth});
  options.num_views = 3;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0, 3);
  ZeroPolicy three_views(env.observation_size(), env.action_size());
  std::vector<EvalRow> rows = EvaluatePolicy(
      three_views, task.character, task.reference, task.initial_states,
      task.options, options, {task.reference->bundles()[0].ground_truth});
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].view, "view0+view1+view2");
  EXPECT_EQ(rows[3].view, "view3+view0+view1");
  for (size_t v = 0; v < rows.size(); ++v) {
    EXPECT_EQ(rows[v].succ, 1.0);
    EXPECT_DOUBLE_EQ(rows[v].e3d_mm, single[v].e3d_mm);
    EXPECT_TRUE(std::isfinite(rows[v].e2d_px));
  }
  // The policy must take K blocks; more views than a bundle has: nothing.
  EXPECT_THROW(EvaluatePolicy(one_view, task.character, task.reference,
                              task.initial_states, task.options, options),
               InputError);
  options.num_views = 5;
  EXPECT_THROW(EvaluatePolicy(three_views, task.character, task.reference,
                              task.initial_states, task.options, options),
               InputError);

  TrackingEnvOptions env_options;
  auto character = testing::LoadHumanoid(env_options.simulation);
  ReferenceBundle bundle = testing::MakeGlidingBundle(*character, 1.0);
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{1.2, {2.0, 1.0, 0.0}}, {-0.5, {-1.0, 0.5, 0.0}}});
  TrackingTaskOptions task_options;
  task_options.simulation = env_options.simulation;
  task_options.sources = {InitialStateSource::kEstimate,
                          CameraSource::kEstimate};
  TrackingTask estimated = BuildTrackingTask(character, {bundle}, task_options);
  TrackingEnv pair_env(estimated.character, estimated.reference,
                       estimated.initial_states, env_options, 0, 2);
  ZeroPolicy pair(pair_env.observation_size(), pair_env.action_size());
  options.num_views = 2;
  EXPECT_THROW(EvaluatePolicy(pair, estimated.character, estimated.reference,
                              estimated.initial_states, env_options, options),
               ConfigError);
  // A rig's estimate (`fit --rig`) is one world: its views go together.
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{1.2, {2.0, 1.0, 0.0}}, {1.2, {2.0, 1.0, 0.0}}});
  bundle.estimate_one_world = true;
  TrackingTask rig = BuildTrackingTask(character, {bundle}, task_options);
  const std::vector<EvalRow> rig_rows =
      EvaluatePolicy(pair, rig.character, rig.reference, rig.initial_states,
                     env_options, options);
  ASSERT_EQ(rig_rows.size(), 2u);
  EXPECT_EQ(rig_rows[0].view,
            bundle.views[0].name + "+" + bundle.views[1].name);
  EXPECT_TRUE(std::isfinite(rig_rows[0].e2d_px));
}

}  // namespace
}  // namespace m2d
