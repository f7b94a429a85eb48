// The tracking task with an object: a ball tracked in 2D next to the walker,
// and the starts that place it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "env/tracking_env.h"
#include "env_fixture.h"

namespace m2d {
namespace {

TEST(TrackingEnvWithObject, ObservesTheBallAndRewardsItsTracking) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  options.reward.object_weight = 0.5;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      options.simulation);
  ASSERT_EQ(character->free_objects().size(), 1u);
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 2.0);

  // The ball resting where the scene puts it, in the 2D and the truth.
  const Eigen::Vector3d ball_m = testing::AddRestingBall(*character, &bundle);
  auto reference = TrackingReference::Prepare({bundle}, *character,
                                              options.simulation.control_hz);
  EXPECT_EQ(reference->num_object_points(), 1);
  EXPECT_EQ(reference->num_points(), 18);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  TrackingEnv env(character, reference, states, options, 3);
  EXPECT_EQ(env.layout().num_objects, 1);
  EXPECT_EQ(env.observation_size(),
            env.layout().proprioception_size() + 6 +
                (1 + options.num_future_frames) * 18 * 3);
  std::vector<float> obs(env.observation_size()),
      action(env.action_size(), 0.0f);
  env.ResetTo(0, 0, states->buffer(0).entry(0, 0).state, obs.data());
  // Object state: the ball's position relative to the root, heading frame.
  const float* object = obs.data() + env.layout().proprioception_size();
  Eigen::Vector3d root(env.simulation().data()->qpos[0],
                       env.simulation().data()->qpos[1],
                       env.simulation().data()->qpos[2]);
  EXPECT_NEAR(Eigen::Vector3d(object[0], object[1], object[2]).norm(),
              (ball_m - root).norm(), 1e-3);
  StepOutcome outcome = env.Step(action.data(), obs.data());
  // The ball has not moved, so its 2D term is nearly perfect.
  EXPECT_GT(outcome.terms.object, 0.9);
  EXPECT_NEAR(outcome.terms.total,
              outcome.terms.pose + 0.5 * outcome.terms.object +
                  options.reward.energy_weight * outcome.terms.energy,
              1e-9);
}

TEST(TrackingEnvWithObject, AnUnknownObjectNameIsRejected) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  auto character = testing::LoadHumanoid(options.simulation);  // flat: no ball
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 1.0);
  for (ReferenceView& view : bundle.views) {
    view.clip.objects.push_back(
        {"ball", std::vector<Keypoint2D>(view.clip.num_frames(), {1, 1, 1})});
  }
  EXPECT_THROW(TrackingReference::Prepare({bundle}, *character, 30.0),
               InputError);
}

// A gliding humanoid and a ball kicked along +x at 0.3 s (3 m/s, rolling),
// seen by 2 static views, with an estimate of each view in a world of its
// own (the truth turned and shifted, as mimic2d fit's worlds are).
ReferenceBundle GlidingWithRollingBall(const Character& character) {
  const Pose3D standing = QposToPose(character, character.model()->qpos0);
  BundleFromMotionOptions options;
  options.rig.num_views = 2;
  ReferenceBundle bundle = MakeBundleFromMotion(
      testing::GlidingMotion(character.shared_skeleton(), standing, 1.0),
      character.keypoint_map(), options, "gliding",
      {testing::RollingBallTrack(31, 30.0, 0.3, 3.0, 0.11, 1.5, 1.0)});
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{0.4, {1.0, 2.0, 0.0}}, {-1.1, {0.0, -3.0, 0.0}}});
  return bundle;
}

TEST(TrackingEnvWithObject, StartsPlaceTheBallFromEachSource) {
  SimulationOptions simulation;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      simulation);
  const FreeObject& ball = character->free_objects()[0];
  const ReferenceBundle bundle = GlidingWithRollingBall(*character);
  const std::vector<Eigen::Vector3d>& truth =
      bundle.ground_truth->objects[0].positions_m;
  // Buffer `b`'s ball at frame t: position and linear velocity.
  auto ball_at = [&](const InitialStates& states, int b, int t) {
    const SimState& state = states.buffer(b).entry(t, 0).state;
    return std::make_pair(
        Eigen::Vector3d(state.qpos.data() + ball.qpos_address),
        Eigen::Vector3d(state.qvel.data() + ball.dof_address));
  };
  auto starts = [&](InitialStateSource source, CameraSource cameras) {
    TaskSources sources;
    sources.initial_states = source;
    sources.cameras = cameras;
    auto reference = TrackingReference::Prepare({bundle}, *character,
                                                simulation.control_hz, sources);
    return std::make_shared<InitialStates>(*reference, character, simulation,
                                           StateBufferOptions());
  };

  // Truth: the truth's ball, at rest before the kick, rolling after it at
  // 3 m/s (spinning at v / r about y).
  auto from_truth = starts(InitialStateSource::kTruth, CameraSource::kTruth);
  for (int t : {0, 5, 20}) {
    const auto [position, velocity] = ball_at(*from_truth, 0, t);
    EXPECT_LT((position - truth[t]).norm(), 1e-9) << t;
  }
  EXPECT_LT(ball_at(*from_truth, 0, 5).second.norm(), 1e-9);
  EXPECT_NEAR(ball_at(*from_truth, 0, 20).second.x(), 3.0, 1e-9);
  const SimState& rolling = from_truth->buffer(0).entry(20, 0).state;
  EXPECT_NEAR(rolling.qvel[ball.dof_address + 4], 3.0 / 0.11, 1e-9);

  // Estimate: each view's ball, in that view's world.
  auto from_estimate =
      starts(InitialStateSource::kEstimate, CameraSource::kEstimate);
  const std::vector<testing::WorldChange> changes = {{0.4, {1.0, 2.0, 0.0}},
                                                     {-1.1, {0.0, -3.0, 0.0}}};
  for (int view = 0; view < 2; ++view) {
    for (int t : {0, 20}) {
      EXPECT_LT((ball_at(*from_estimate, view, t).first -
                 changes[view].Point(truth[t]))
                    .norm(),
                1e-9);
    }
  }

  // Default: the first view's 2D put on the floor through its camera; a
  // rolling ball's centre exactly wherever the view sees it (it leaves the
  // image at 3 m/s: then it rolls on, slowing, as RollingObjectFromPixels
  // says).
  auto from_default =
      starts(InitialStateSource::kDefault, CameraSource::kTruth);
  int seen_rolling = 0;
  for (int t = 0; t < bundle.num_frames(); ++t) {
    if (!bundle.views[0].clip.objects[0].points[t].IsPresent()) continue;
    EXPECT_LT((ball_at(*from_default, 0, t).first - truth[t]).norm(), 1e-6)
        << t;
    seen_rolling += t > 9;
  }
  EXPECT_GT(seen_rolling, 3);
}

// The paper's "w/ Rnd." as a setting: every start moves the ball (only) by
// an offset uniform in the square, drawn from the environment's seed; the
// buffer's state stays as it was; no square, no move; bundles without an
// object refuse the setting.
TEST(TrackingEnvWithObject, MovedStartsOffsetTheBallWithinItsSquare) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  options.object_start_square_m = 1.0;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      options.simulation);
  const FreeObject& ball = character->free_objects()[0];
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 1.0);
  testing::AddRestingBall(*character, &bundle);
  auto reference = TrackingReference::Prepare({bundle}, *character,
                                              options.simulation.control_hz);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  const SimState& start = states->buffer(0).entry(0, 0).state;
  const std::vector<double> start_qpos = start.qpos;
  std::vector<float> obs;
  // The ball's offset from the start state, and the largest change
  // elsewhere in qpos, after one ResetTo.
  auto reset_offset = [&](TrackingEnv& env, double* other_change) {
    obs.resize(env.observation_size());
    env.ResetTo(0, 0, start, obs.data());
    const double* qpos = env.simulation().data()->qpos;
    *other_change = 0;
    for (size_t i = 0; i < start_qpos.size(); ++i) {
      if (i == size_t(ball.qpos_address) || i == size_t(ball.qpos_address) + 1)
        continue;
      *other_change =
          std::max(*other_change, std::abs(qpos[i] - start_qpos[i]));
    }
    return Eigen::Vector2d(
        qpos[ball.qpos_address] - start_qpos[ball.qpos_address],
        qpos[ball.qpos_address + 1] - start_qpos[ball.qpos_address + 1]);
  };

  TrackingEnv env(character, reference, states, options, 3);
  Eigen::Vector2d low(1, 1), high(-1, -1);
  for (int i = 0; i < 200; ++i) {
    double other_change = 0;
    const Eigen::Vector2d offset = reset_offset(env, &other_change);
    EXPECT_EQ(other_change, 0.0);
    low = low.cwiseMin(offset);
    high = high.cwiseMax(offset);
  }
  EXPECT_GE(low.minCoeff(), -0.5);
  EXPECT_LE(high.maxCoeff(), 0.5);
  EXPECT_LT(low.maxCoeff(), -0.4);  // the square is covered, not a corner
  EXPECT_GT(high.minCoeff(), 0.4);
  EXPECT_EQ(states->buffer(0).entry(0, 0).state.qpos, start_qpos);
  double other_change = 0;
  TrackingEnv same_seed(character, reference, states, options, 3);
  TrackingEnv again(character, reference, states, options, 3);
  EXPECT_EQ(reset_offset(same_seed, &other_change),
            reset_offset(again, &other_change));

  options.object_start_square_m = 0.0;
  TrackingEnv unmoved(character, reference, states, options, 3);
  EXPECT_EQ(reset_offset(unmoved, &other_change), Eigen::Vector2d::Zero());

  options.object_start_square_m = 1.0;
  testing::WalkTask no_ball = testing::MakeWalkTask(path, 1.0);
  try {
    TrackingEnv refused(no_ball.character, no_ball.reference,
                        no_ball.initial_states, options, 3);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("track none"), std::string::npos)
        << error.what();
  }
}

// The two-stage baseline with a ball (target body_3d): the initial states'
// motion carries the ball's 3D, the 3D block observes it after the body's
// keypoints, and the reward's object term scores its world position.
TEST(TrackingEnvWithObject, TheThreeDTargetObservesAndRewardsTheBall) {
  TrackingEnvOptions options;
  options.target = TrackingTarget::kBody3D;
  options.reward_3d.object_weight = 0.5;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      options.simulation);
  const FreeObject& ball = character->free_objects()[0];
  const ReferenceBundle bundle = GlidingWithRollingBall(*character);
  const std::vector<Eigen::Vector3d>& truth =
      bundle.ground_truth->objects[0].positions_m;
  TaskSources sources;  // the truth's starts and cameras
  auto reference = TrackingReference::Prepare(
      {bundle}, *character, options.simulation.control_hz, sources);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  for (int t : {0, 20, 30}) {
    ASSERT_EQ(states->motion(0)[t].object_positions_m.size(), 1u);
    EXPECT_LT((states->motion(0)[t].object_positions_m[0] - truth[t]).norm(),
              1e-12);
  }
  TrackingEnv env(character, reference, states, options, 5);
  std::vector<float> obs(env.observation_size()),
      action(env.action_size(), 0.0f);

  // Rolling at 3 m/s from frame 20: the ball is the block's 18th point, now
  // and in the next reference frame, at its distance from the root.
  const int frame = 20;
  env.ResetTo(0, frame, states->buffer(0).entry(frame, 0).state, obs.data());
  const Eigen::Vector3d root(env.simulation().data()->qpos);
  const int stride = 18 * ObservationLayout::kPointFeatures;
  const float* now = obs.data() + env.layout().view_offset() + 17 * 3;
  const float* next = now + stride;
  EXPECT_NEAR(Eigen::Vector3d(now[0], now[1], now[2]).norm(),
              (truth[frame] - root).norm(), 1e-4);
  EXPECT_NEAR(Eigen::Vector3d(next[0], next[1], next[2]).norm(),
              (truth[frame + 1] - root).norm(), 1e-4);
  StepOutcome outcome = env.Step(action.data(), obs.data());
  EXPECT_GT(outcome.terms.object, 0.95);  // it rolls on as its reference
  EXPECT_NEAR(outcome.terms.total,
              outcome.terms.pose + 0.5 * outcome.terms.object +
                  options.reward.energy_weight * outcome.terms.energy,
              1e-9);

  // The same start with the ball 0.3 m behind: exp(-5 * 0.09) = 0.64.
  SimState behind = states->buffer(0).entry(frame, 0).state;
  behind.qpos[ball.qpos_address] -= 0.3;
  env.ResetTo(0, frame, behind, obs.data());
  outcome = env.Step(action.data(), obs.data());
  EXPECT_NEAR(outcome.terms.object, std::exp(-0.45), 0.05);
  EXPECT_FALSE(outcome.terminated);  // the exit watches the body only
}

TEST(TrackingEnvWithObject, StartsWithoutTheBallsThreeDAreNamedErrors) {
  SimulationOptions simulation;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      simulation);
  ReferenceBundle bundle = GlidingWithRollingBall(*character);
  bundle.ground_truth->objects.clear();
  (*bundle.estimate)[1].objects.clear();
  auto expect_error = [&](InitialStateSource source, CameraSource cameras,
                          const std::string& needle) {
    TaskSources sources;
    sources.initial_states = source;
    sources.cameras = cameras;
    try {
      TrackingReference::Prepare({bundle}, *character, simulation.control_hz,
                                 sources);
      ADD_FAILURE() << "expected InputError with " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("gliding"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
          << e.what();
    }
  };
  expect_error(InitialStateSource::kTruth, CameraSource::kTruth,
               "truth needs the 3D of object 'ball'");
  expect_error(InitialStateSource::kEstimate, CameraSource::kEstimate,
               "the estimate of view " + bundle.views[1].name +
                   " has no 3D of object 'ball'");
  // The default starts need no 3D of the ball: they place it from the 2D.
  TaskSources sources;
  sources.initial_states = InitialStateSource::kDefault;
  EXPECT_NO_THROW(TrackingReference::Prepare({bundle}, *character,
                                             simulation.control_hz, sources));
}

}  // namespace
}  // namespace m2d
