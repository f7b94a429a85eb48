// A CI-sized learning run: a real PPO + ASI training on a 2-second walk seen
// from 4 views, with a fixed seed, that must cut the deterministic policy's
// 2D tracking error well below the untrained policy's.
#include <gtest/gtest.h>

#include <chrono>

#include "env/env_fixture.h"
#include "env/task.h"
#include "eval/evaluator.h"
#include "fit/fit.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "rl/torch_policy.h"
#include "rl/trainer.h"
#include "sim/object_replay.h"
#include "synthetic_motion.h"
#include "test_paths.h"

namespace m2d {
namespace {

// Calibrated on this machine (see the closing note of the learning issue).
// Measured first: 200k samples in 117 s; frames tracked before the 100 px
// early exit went from 10.2 (untrained) to 26.8 of 45, E2D from 26.4 to
// 19.9 px. Measured 2026-11-24: 33 s, frames 10.6 -> 21.8, E2D 27.0 ->
// 21.4 px. Since 2026-12-01 a clip's end is not bootstrapped
// (agent.bootstrap_at_reference_end; docs/training.md, "The clip's end"):
// frames 10.6 -> 17.9, E2D 27.0 -> 20.8 px at this seed (7); seeds 8, 9,
// 10 hold 24.2, 23.3, 20.3 frames (bootstrapped: 22.0, 24.2, 19.3, 26.6), so
// the bounds sit below the lowest seed, not at one seed's figure.
constexpr int64_t kTrainingSamples = 200'000;
constexpr double kMinSurvivalGain = 1.45;   // measured 1.69x (seed 7)
constexpr double kMinTrainedFrames = 15.5;  // measured 17.9-24.2 (seeds 7-10)

// Small networks and batches so that it learns in CI time.
void UseCiSizedLearning(const std::string& dir, TrainConfig* config) {
  config->model.encoder_hidden = {128};
  config->model.encoder_features = 64;
  config->model.policy_hidden = {256, 128};
  config->model.critic_hidden = {256, 128};
  config->ppo.num_envs = 32;
  config->ppo.steps_per_env = 32;
  config->ppo.minibatch_size = 256;
  config->ppo.learning_rate = 5e-4;
  config->run.run_dir = dir + "/run";
  config->run.seed = 7;
  config->run.total_samples = kTrainingSamples;
  config->Validate();
}

// The untrained and the trained policy (`checkpoint`) of `config`, each
// rolled out the same way on `bundle` with the config's sources.
struct BeforeAndAfter {
  EvalRow before, after;
};

BeforeAndAfter EvaluateBeforeAndAfter(
    const TrainConfig& config, const std::string& checkpoint,
    std::shared_ptr<const Character> character, const ReferenceBundle& bundle,
    const std::string& dir) {
  TrackingTaskOptions task_options;
  task_options.simulation = config.env.simulation;
  task_options.sources = config.data.sources();
  TrackingTask task = BuildTrackingTask(character, {bundle}, task_options);
  EvalOptions eval;
  eval.episodes_per_view = 3;
  eval.episode_s = 1.5;
  auto evaluate = [&](Policy& policy) {
    return AggregateRows(EvaluatePolicy(policy, character, task.reference,
                                        task.initial_states, config.env, eval));
  };
  TorchPolicy trained(checkpoint);
  TrainConfig untrained_config = config;
  untrained_config.run.run_dir = dir + "/untrained";
  Trainer untrained_trainer(untrained_config, false);
  untrained_trainer.SaveCheckpoint();
  TorchPolicy untrained(untrained_trainer.checkpoint_path());
  BeforeAndAfter result;
  result.before = evaluate(untrained);
  result.after = evaluate(trained);
  return result;
}

// Trains on 2 s of walking seen by 4 following views (with the collection
// and the update overlapped or not) and checks the policy learned.
struct LearningThresholds {
  double min_survival_gain;
  double min_trained_frames;
  // E2D averages the frames a rollout survived: a 3D tracker that survives
  // into the walk's harder frames need not lower it (the 2D trackers do).
  bool e2d_must_fall = true;
};

void ExpectTheWalkIsLearned(
    const std::string& name, bool overlap_update, TrainingPrecision precision,
    const LearningThresholds& thresholds,
    CollectionMode collection = CollectionMode::kBatched,
    TrackingTarget target = TrackingTarget::kImage2D) {
  const std::string walk_path =
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt");
  std::string dir = testing::TempDir(name);

  // The reference: 2 s of walking, 4 following views.
  TrainConfig config;
  config.data.character_config =
      testing::SourcePath("assets/characters/humanoid.yaml");
  auto character = LoadCharacterForSimulation(config.data.character_config,
                                              "flat", config.env.simulation);
  ReferenceBundle bundle = testing::MakeWalkBundle(walk_path, *character, 2.0);
  config.data.bundles = {dir + "/walk2s.json"};
  WriteBundle(config.data.bundles[0], bundle);

  config.ppo.overlap_update = overlap_update;
  config.ppo.training_precision = precision;
  config.ppo.collection = collection;
  config.env.target = target;
  // A 3D tracker ends its training episodes by its own 3D exit.
  if (target == TrackingTarget::kBody3D) config.env.early_exit = false;
  UseCiSizedLearning(dir, &config);

  Trainer trainer(config, /*resume=*/false);
  auto start = std::chrono::steady_clock::now();
  TrainSummary summary = trainer.Run(0, nullptr, nullptr);
  double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();

  // Evaluate the untrained and the trained policy the same way.
  const auto [before, after] = EvaluateBeforeAndAfter(
      config, summary.checkpoint_path, character, bundle, dir);

  std::printf("trained %lld samples in %.0f s (%.0f samples/s)\n",
              static_cast<long long>(summary.last.samples), seconds,
              summary.last.samples / seconds);
  std::printf(
      "untrained: Succ %.2f E2D %.1f px frames %.1f | trained: Succ %.2f E2D "
      "%.1f px frames %.1f\n",
      before.succ, before.e2d_px, before.mean_frames, after.succ, after.e2d_px,
      after.mean_frames);
  EXPECT_GT(after.mean_frames,
            before.mean_frames * thresholds.min_survival_gain);
  EXPECT_GT(after.mean_frames, thresholds.min_trained_frames);
  if (thresholds.e2d_must_fall) {
    EXPECT_LT(after.e2d_px, before.e2d_px);
  }
}

TEST(Learning, PpoCutsTheWalkTrackingErrorWithinMinutes) {
  ExpectTheWalkIsLearned("learning", /*overlap_update=*/false,
                         TrainingPrecision::kFp32,
                         {kMinSurvivalGain, kMinTrainedFrames});
}

// The same run with the update on a second thread, one batch behind the
// collection (agent.overlap_update). Measured 2026-11-24: frames 10.6 ->
// 18.3 (1.73x), E2D 27.0 -> 19.7 px, against 21.8 frames and 21.4 px
// sequentially at the same 200k samples: each update starts one update
// away from the policy that collected its batch, so the clip bites sooner.
// With a clip's end not bootstrapped (2026-12-01): 10.6 -> 16.3 frames.
constexpr double kMinOverlapSurvivalGain = 1.3;  // measured 1.73x, now 1.54x
constexpr double kMinOverlapTrainedFrames = 14;  // measured 18.3, now 16.3
TEST(Learning, AnOverlappedUpdateLearnsTheWalk) {
  ExpectTheWalkIsLearned("learning_overlap", /*overlap_update=*/true,
                         TrainingPrecision::kFp32,
                         {kMinOverlapSurvivalGain, kMinOverlapTrainedFrames});
}

// The same run with bfloat16 matrix products in collection and update
// (agent.training_precision: bf16). Measured 2026-11-24: frames 10.6 ->
// 20.8 (1.96x), E2D 27.0 -> 18.5 px, against 21.8 frames and 21.4 px in
// float32 at the same 200k samples and seed; with ASI's critic also in
// bfloat16, 25.4 frames and 20.0 px; with a clip's end not bootstrapped
// (2026-12-01, an Intel Xeon without bf16 units: 831 s), 22.5 frames.
constexpr double kMinBf16SurvivalGain = 1.6;    // measured 1.96x, 2.40x, 2.12x
constexpr double kMinBf16TrainedFrames = 18.0;  // measured 20.8, 25.4, 22.5
TEST(Learning, ABf16UpdateLearnsTheWalk) {
  ExpectTheWalkIsLearned("learning_bf16", /*overlap_update=*/false,
                         TrainingPrecision::kBf16,
                         {kMinBf16SurvivalGain, kMinBf16TrainedFrames});
}

// The same run collected per thread (agent.collection: per_thread): each
// env thread acts for its own 16 environments, and the observation
// normalizer takes in a rollout's observations after it. Measured
// 2026-11-24: frames 10.6 -> 23.9 (2.25x), E2D 27.0 -> 22.5 px, against
// 21.8 frames and 21.4 px batched at the same seed and samples; with a
// clip's end not bootstrapped (2026-12-01), 21.9 frames, E2D 20.4 px.
constexpr double kMinPerThreadSurvivalGain = 1.6;    // measured 2.25x, 2.07x
constexpr double kMinPerThreadTrainedFrames = 18.0;  // measured 23.9, 21.9
// The 3D-supervised baseline's task (env.target: body_3d): the same walk,
// followed in 3D from its truth with a DeepMimic-style reward, judged by
// the same 2D evaluation as the 2D tracker. Measured 2026-11-27 at the same
// seed and samples (51 s with a training on the other core), joints compared
// as rotations: frames tracked before the 100 px exit 10.6 -> 30.0 (2.8x),
// E2D 27.1 -> 30.9 px over those longer rollouts (hinge angles, 2026-11-24:
// 10.5 -> 22.9); with a clip's end not bootstrapped (2026-12-01), 10.6 ->
// 23.5 frames (2.2x).
TEST(Learning, A3dTrackerLearnsTheWalkFromItsTruth) {
  ExpectTheWalkIsLearned("learning_3d", /*overlap_update=*/false,
                         TrainingPrecision::kFp32,
                         {kMinSurvivalGain, kMinTrainedFrames,
                          /*e2d_must_fall=*/false},
                         CollectionMode::kBatched, TrackingTarget::kBody3D);
}

TEST(Learning, PerThreadCollectionLearnsTheWalk) {
  ExpectTheWalkIsLearned(
      "learning_per_thread", /*overlap_update=*/false, TrainingPrecision::kFp32,
      {kMinPerThreadSurvivalGain, kMinPerThreadTrainedFrames},
      CollectionMode::kPerThread);
}

// Trains `config` CI-sized for `samples` from 2D only on `fitted` (written
// as `stem`.json; every episode starts from the fit's poses and projects
// with its cameras) and evaluates the untrained and the trained policy the
// same way, printing both after `label`.
BeforeAndAfter TrainAndEvaluateFrom2d(
    const std::string& label, const std::string& stem,
    const ReferenceBundle& fitted, std::shared_ptr<const Character> character,
    const std::string& dir, TrainConfig config, int64_t samples) {
  config.data.bundles = {dir + "/" + stem + ".json"};
  WriteBundle(config.data.bundles[0], fitted);
  config.data.initial_states = InitialStateSource::kEstimate;
  config.data.cameras = CameraSource::kEstimate;
  UseCiSizedLearning(dir, &config);
  config.run.total_samples = samples;
  Trainer trainer(config, /*resume=*/false);
  TrainSummary summary = trainer.Run(0, nullptr, nullptr);
  const BeforeAndAfter result = EvaluateBeforeAndAfter(
      config, summary.checkpoint_path, character, fitted, dir);
  std::printf(
      "%s: untrained: Succ %.2f E2D %.1f px frames %.1f | trained: Succ %.2f "
      "E2D %.1f px frames %.1f\n",
      label.c_str(), result.before.succ, result.before.e2d_px,
      result.before.mean_frames, result.after.succ, result.after.e2d_px,
      result.after.mean_frames);
  return result;
}

// `config` trains `character_asset` (a path under the repository) in
// `scene`; returns that character, loaded for the config's simulation.
std::shared_ptr<const Character> UseCharacter(
    const std::string& character_asset, const std::string& scene,
    TrainConfig* config) {
  config->data.character_config = testing::SourcePath(character_asset);
  config->data.scene = scene;
  return LoadCharacterForSimulation(config->data.character_config, scene,
                                    config->env.simulation);
}

// Calibrated on this machine (issue 11): the same run from 2D only — the
// bundle stripped of its 3D truth and cameras, then fitted; training and
// evaluation start from the fitted poses and project with the fitted
// cameras. Measured (4 views, moving cameras, 200k samples): frames before
// the early exit 10.7 -> 14.3 of 45, E2D 30.6 -> 19.8 px. Less than from
// 3D truth: the fit keeps the walker's travel out of its following cameras
// (docs/fit.md, "Known limits"), so the starts ask for a walk in place.
// With a clip's end not bootstrapped (2026-12-01): 10.9 -> 18.7 frames,
// E2D 28.7 -> 21.2 px.
constexpr double kMin2dSurvivalGain = 1.15;  // measured 1.34x, now 1.72x
constexpr double kMax2dErrorRatio = 0.85;    // measured 0.65, now 0.74

TEST(Learning, PpoLearnsTheWalkFromAStrippedAndFittedBundle) {
  const std::string walk_path =
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt");
  std::string dir = testing::TempDir("learning2d");

  // What a user has: 2 s of walking in 4 following views, no 3D, no
  // cameras. The fit estimates both.
  TrainConfig config;
  config.data.character_config =
      testing::SourcePath("assets/characters/humanoid.yaml");
  auto character = LoadCharacterForSimulation(config.data.character_config,
                                              "flat", config.env.simulation);
  ReferenceBundle stripped =
      StripBundle(testing::MakeWalkBundle(walk_path, *character, 2.0));
  ASSERT_FALSE(stripped.ground_truth.has_value());
  FitOptions fit;
  fit.camera_motion = CameraMotion::kMoving;
  fit.num_threads = 2;
  ReferenceBundle fitted = FitBundle(stripped, *character, fit, "walk2s");
  const auto [before, after] =
      TrainAndEvaluateFrom2d("from 2D only", "walk2s_fitted", fitted, character,
                             dir, config, kTrainingSamples);
  EXPECT_GT(after.mean_frames, before.mean_frames * kMin2dSurvivalGain);
  EXPECT_LT(after.e2d_px, before.e2d_px * kMax2dErrorRatio);
}

// The dog from 2D only (docs/quadruped.md): the synthetic trot (the dog3d
// clips stay in ../shared) seen as AP-10K keypoints by 2 static views,
// stripped, fitted with the dog character, trained and evaluated on the
// fit's starts and cameras. Calibrated 2026-11-30 (seed 7, beside a
// training): 200k samples gave frames 3.3 -> 3.8, too faint to test; 400k
// (142 s) gives 3.3 -> 5.2 frames before the 100 px exit, E2D 24.6 -> 23.0
// px over those longer rollouts, so only the survival is asserted (as for
// the 3D tracker above). With a clip's end not bootstrapped (2026-12-01;
// the dog's 2-s clips end often, docs/training.md "The clip's end"): 3.3
// -> 6.2 frames, E2D 24.6 -> 23.1 px.
constexpr int64_t kDogTrainingSamples = 400'000;
constexpr double kMinDogSurvivalGain = 1.3;  // measured 1.58x, now 1.88x

TEST(Learning, PpoLearnsTheDogsTrotFromAStrippedAndFittedBundle) {
  std::string dir = testing::TempDir("learning_dog");
  TrainConfig config;
  auto character = UseCharacter("assets/characters/dog.yaml", "flat", &config);
  BundleFromMotionOptions bundle_options;
  bundle_options.duration_s = 2.0;
  bundle_options.rig.num_views = 2;
  bundle_options.rig.elevation_deg = 10.0;
  bundle_options.rig.distance_m = 4.0;
  bundle_options.rig.focal_px = 1400.0;
  bundle_options.rig.target_m = {0.0, 0.0, 0.4};
  bundle_options.aim = RigAim::kPathMiddle;
  ReferenceBundle stripped = StripBundle(MakeBundleFromMotion(
      testing::SyntheticTrot(character->shared_skeleton(),
                             character->keypoint_map(), 2.0),
      character->keypoint_map(), bundle_options, "trot"));
  FitOptions fit;
  fit.fixed_focal_px = 1400.0;
  fit.num_threads = 2;
  ReferenceBundle fitted = FitBundle(stripped, *character, fit, "trot");
  const auto [before, after] =
      TrainAndEvaluateFrom2d("dog from 2D only", "trot_fitted", fitted,
                             character, dir, config, kDogTrainingSamples);
  EXPECT_GT(after.mean_frames, before.mean_frames * kMinDogSurvivalGain);
}

// The ball (docs/ball.md): 2 s of the walk with a ball in its path, the
// ball's motion simulated with the walk replayed, seen by 2 static views,
// stripped to the 2D of the walker and the ball, fitted (the ball put on
// the floor under the fitted cameras), trained and evaluated on the fit's
// starts and cameras with the ball's 2D term in the reward. Calibrated
// 2026-11-30 (seed 7, beside a training; 84 s): frames before the 100 px
// exit 15.2 -> 26.2, E2D 29.7 -> 29.4 px. Only the survival is asserted:
// the ball's 2D error (EO2D) rose 43 -> 91 px because the trained walker
// lives past the kick (frame 11), where the untrained one had fallen
// before the ball moved, so the two average different frames. Whether the
// ball follows its reference is the long training's measure (docs/ball.md).
// With a clip's end not bootstrapped (2026-12-01): 15.2 -> 27.5 frames.
constexpr int64_t kBallTrainingSamples = 200'000;
constexpr double kMinBallSurvivalGain = 1.3;  // measured 1.72x, now 1.81x

// What a user of the ball has: 2 s of the walk with a ball kicked along,
// seen by 2 static views as 2D (the walker's keypoints and the ball's
// centre), fitted: the person, and the ball on the floor under the fitted
// cameras.
ReferenceBundle FittedWalkWithBall(const Character& character) {
  const Motion3D walk = ReadDeepMimicMotion(
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt"),
      character.shared_skeleton());
  BundleFromMotionOptions bundle_options;
  bundle_options.duration_s = 2.0;
  bundle_options.rig.num_views = 2;
  bundle_options.rig.distance_m = 6.0;
  bundle_options.aim = RigAim::kPathMiddle;
  const Motion3D sampled = SampleMotionForBundle(walk, bundle_options);
  const BallPlacement placement = PlaceBallInFootPath(
      character, sampled, character.free_objects()[0].radius_m);
  const ReferenceBundle stripped = StripBundle(MakeBundleFromMotion(
      walk, character.keypoint_map(), bundle_options, "walk_ball",
      ReplayObjectsAlongMotion(character, sampled, {placement.center_m})));
  EXPECT_EQ(stripped.views[0].clip.objects.size(), 1u);
  FitOptions fit;
  fit.fixed_focal_px = 1000.0;
  fit.num_threads = 2;
  return FitBundle(stripped, character, fit, "walk_ball");
}

TEST(Learning, PpoLearnsToWalkAndKickTheBallFromAStrippedAndFittedBundle) {
  std::string dir = testing::TempDir("learning_ball");
  TrainConfig config;
  config.env.reward.object_weight = 0.5;
  auto character =
      UseCharacter("assets/characters/humanoid.yaml", "ball", &config);
  const auto [before, after] =
      TrainAndEvaluateFrom2d("walk and kick from 2D only", "walk_ball_fitted",
                             FittedWalkWithBall(*character), character, dir,
                             config, kBallTrainingSamples);
  std::printf("EO2D %.1f -> %.1f px\n", before.eo2d_px, after.eo2d_px);
  EXPECT_GT(after.mean_frames, before.mean_frames * kMinBallSurvivalGain);
}

// The two-stage baseline with the ball (configs/ball_sfv.yaml): the same
// fitted bundle, imitated as 3D (target body_3d: the fit's person and its
// ball, a term on the ball's world position), judged by the same 2D
// evaluation. Calibrated 2026-11-30 (seed 7, 200k samples beside a
// training; 89 s): frames before the 100 px exit 15.2 -> 25.3, E2D 29.6 ->
// 31.8 px and EO2D 43 -> 78 px over those longer rollouts (as the 2D
// tracker's above), so only the survival is asserted.
// With a clip's end not bootstrapped (2026-12-01): 15.2 -> 28.3 frames.
constexpr double kMinBallSfvSurvivalGain = 1.3;  // measured 1.66x, now 1.86x

TEST(Learning, TheTwoStageBaselineLearnsToWalkWithTheBallFromTheFitsThreeD) {
  std::string dir = testing::TempDir("learning_ball_sfv");
  TrainConfig config;
  config.env.target = TrackingTarget::kBody3D;
  config.env.early_exit = false;  // the 3D exit ends its episodes
  config.env.reward_3d.object_weight = 0.5;
  auto character =
      UseCharacter("assets/characters/humanoid.yaml", "ball", &config);
  const auto [before, after] = TrainAndEvaluateFrom2d(
      "Sfv* with the ball", "walk_ball_fitted", FittedWalkWithBall(*character),
      character, dir, config, kBallTrainingSamples);
  std::printf("EO2D %.1f -> %.1f px\n", before.eo2d_px, after.eo2d_px);
  EXPECT_GT(after.mean_frames, before.mean_frames * kMinBallSfvSurvivalGain);
}

}  // namespace
}  // namespace m2d
