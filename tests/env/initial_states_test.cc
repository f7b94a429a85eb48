// Initial-state buffers: noise-free states are the ground-truth poses;
// Noisy S.I. perturbs the hinge angles once, by the asked sigma, within the
// joint ranges and without putting the character into the floor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "common/error.h"
#include "env/reference.h"
#include "env/reward.h"
#include "env_fixture.h"

namespace m2d {
namespace {

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";

std::shared_ptr<const TrackingReference> WalkReference(
    const std::string& walk_path, const Character& character,
    const SimulationOptions& options) {
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(testing::MakeWalkBundle(walk_path, character, 2.0));
  return TrackingReference::Prepare(std::move(bundles), character,
                                    options.control_hz);
}

// How deep (m, >= 0) the character's deepest contact with the ground is in
// `state`.
double FloorPenetrationM(Simulation& simulation, const SimState& state) {
  simulation.Restore(state);
  const mjModel* m = simulation.model();
  const mjData* d = simulation.data();
  double deepest_m = 0.0;
  for (int c = 0; c < d->ncon; ++c) {
    const int body1 = m->geom_bodyid[d->contact[c].geom1];
    const int body2 = m->geom_bodyid[d->contact[c].geom2];
    const bool with_ground = body1 == 0 || body2 == 0;
    const bool with_character = simulation.character().IsCharacterBody(body1) ||
                                simulation.character().IsCharacterBody(body2);
    if (with_ground && with_character)
      deepest_m = std::max(deepest_m, -d->contact[c].dist);
  }
  return deepest_m;
}

TEST(InitialStates, WithoutNoiseHoldTheGroundTruthPoses) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  SimulationOptions options;
  auto character = testing::LoadHumanoid(options);
  auto reference = WalkReference(walk_path, *character, options);
  InitialStates by_default(*reference, character, options,
                           StateBufferOptions());
  InitialStates zero_sigma(*reference, character, options, StateBufferOptions(),
                           0.0, /*noise_seed=*/99);
  Simulation simulation(character, options);
  const std::vector<Pose3D>& poses =
      reference->bundles()[0].ground_truth->poses;
  const StateBuffer& buffer = by_default.buffer(0);
  ASSERT_EQ(buffer.num_frames(), static_cast<int>(poses.size()));
  for (int t = 0; t < buffer.num_frames(); ++t) {
    ASSERT_EQ(buffer.size(t), 1);
    ASSERT_EQ(zero_sigma.buffer(0).size(t), 1);
    const SimState& state = buffer.entry(t, 0).state;
    EXPECT_EQ(state.qpos, zero_sigma.buffer(0).entry(t, 0).state.qpos);
    EXPECT_EQ(state.qvel, zero_sigma.buffer(0).entry(t, 0).state.qvel);
    simulation.SetPose(poses[t]);
    for (int k = 0; k < character->model()->nq; ++k)
      ASSERT_EQ(state.qpos[k], simulation.data()->qpos[k]) << t << " " << k;
  }
}

// The kick's truth picks the other Euler solution of a ball joint at a few
// frames where nothing moves. Compared as rotations (3D tracking's pose
// term) the two solutions are the same pose; and each buffered state's
// joint angular velocities agree with the rotations' central differences,
// the switch frames and those near gimbal lock included (hinge rates are
// the Euler solution's the state is set in, mapped from the angular
// velocity).
TEST(InitialStates, ATruthThatSwitchesEulerSolutionsMovesAsItsRotationsDo) {
  M2D_REQUIRE_SHARED(kick_path, "deepmimic/motions/humanoid3d_kick.txt");
  SimulationOptions options;
  auto character = testing::LoadHumanoid(options);
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(testing::MakeWalkBundle(kick_path, *character, 2.0));
  auto reference = TrackingReference::Prepare(std::move(bundles), *character,
                                              options.control_hz);
  const std::vector<Pose3D>& poses =
      reference->bundles()[0].ground_truth->poses;
  const std::vector<std::vector<double>> along =
      PosesToQposAlongClip(*character, poses);

  // Frame by frame against along the clip: hinges far apart, rotations not.
  Simulation simulation(character, options);
  std::vector<double> keypoints_xyz(
      3 * character->keypoint_layout().num_keypoints());
  BodyTarget3D per_frame_body, along_body;
  double largest_hinge_gap_rad = 0.0, largest_rotation_sq_rad2 = 0.0;
  for (size_t t = 0; t < poses.size(); ++t) {
    simulation.SetPose(poses[t]);
    simulation.KeypointPositions(keypoints_xyz.data());
    ReadBodyTarget(simulation, keypoints_xyz.data(), &per_frame_body);
    for (const ActuatedHinge& hinge : character->hinges()) {
      largest_hinge_gap_rad =
          std::max(largest_hinge_gap_rad,
                   std::abs(simulation.data()->qpos[hinge.qpos_address] -
                            along[t][hinge.qpos_address]));
    }
    std::copy(along[t].begin(), along[t].end(),
              simulation.mutable_data()->qpos);
    simulation.Refresh();
    simulation.KeypointPositions(keypoints_xyz.data());
    ReadBodyTarget(simulation, keypoints_xyz.data(), &along_body);
    largest_rotation_sq_rad2 = std::max(
        largest_rotation_sq_rad2,
        MeasureTracking3D(per_frame_body, along_body).joint_rotation_sq_rad2);
  }
  EXPECT_GT(largest_hinge_gap_rad, 2.0);
  EXPECT_LT(largest_rotation_sq_rad2, 1e-16);

  // Buffered velocities against the rotations' central differences:
  // R(t+1) R(t-1)^-1 = exp(2 dt [w]x) with w in the parent's axes.
  InitialStates states(*reference, character, options, StateBufferOptions());
  const std::vector<BodyTarget3D>& motion = states.motion(0);
  const double dt_s = 1.0 / options.control_hz;
  double largest_gap_rad_s = 0.0, largest_speed_rad_s = 0.0;
  for (size_t t = 1; t + 1 < motion.size(); ++t) {
    for (size_t j = 0; j < motion[t].joint_rotations.size(); ++j) {
      const Eigen::AngleAxisd turn(
          motion[t + 1].joint_rotations[j] *
          motion[t - 1].joint_rotations[j].conjugate());
      const Eigen::Vector3d differenced =
          turn.axis() * turn.angle() / (2.0 * dt_s);
      const Eigen::Vector3d& measured =
          motion[t].joint_angular_velocities_rad_s[j];
      largest_gap_rad_s =
          std::max(largest_gap_rad_s, (measured - differenced).norm());
      largest_speed_rad_s = std::max(largest_speed_rad_s, measured.norm());
    }
  }
  std::printf(
      "kick: joint speeds up to %.1f rad/s, at most %.3f rad/s off "
      "the rotations' central differences\n",
      largest_speed_rad_s, largest_gap_rad_s);
  EXPECT_GT(largest_speed_rad_s, 5.0);
  EXPECT_LT(largest_gap_rad_s, 0.5);  // measured 0.22; 6.7 with Euler
                                      // differences taken frame by frame
}

TEST(InitialStates, NoisySIPerturbsHingesBySigmaOnceAndKeepsFeetOnTheFloor) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  SimulationOptions options;
  auto character = testing::LoadHumanoid(options);
  auto reference = WalkReference(walk_path, *character, options);
  InitialStates clean(*reference, character, options, StateBufferOptions());
  Simulation simulation(character, options);
  double clean_penetration_m = 0.0;
  for (int t = 0; t < clean.buffer(0).num_frames(); ++t) {
    clean_penetration_m = std::max(
        clean_penetration_m,
        FloorPenetrationM(simulation, clean.buffer(0).entry(t, 0).state));
  }

  constexpr double kSigmaRad = 0.5;  // the paper's Noisy S.I.
  InitialStates noisy(*reference, character, options, StateBufferOptions(),
                      kSigmaRad, /*noise_seed=*/7);
  const int root = character->root_qpos_address();
  // Clamping to the joint range shrinks the spread of angles near a limit:
  // the sigma is measured on angles at least 2 sigma inside both limits
  // (measured: 474 of 1708 angles, std 0.504 rad, mean -0.010 rad).
  double sum = 0.0, sum_squares = 0.0;
  int count = 0, changed = 0, total = 0;
  double noisy_penetration_m = 0.0;
  const std::vector<float> zero_actions(character->num_actions(), 0.0f);
  for (int t = 0; t < noisy.buffer(0).num_frames(); ++t) {
    ASSERT_EQ(noisy.buffer(0).size(t), 1);
    const SimState& before = clean.buffer(0).entry(t, 0).state;
    const SimState& after = noisy.buffer(0).entry(t, 0).state;
    for (const ActuatedHinge& hinge : character->hinges()) {
      const double clean_rad = before.qpos[hinge.qpos_address];
      const double noisy_rad = after.qpos[hinge.qpos_address];
      EXPECT_GE(noisy_rad, hinge.range_low_rad);
      EXPECT_LE(noisy_rad, hinge.range_high_rad);
      ++total;
      if (noisy_rad != clean_rad) ++changed;
      if (clean_rad - hinge.range_low_rad >= 2 * kSigmaRad &&
          hinge.range_high_rad - clean_rad >= 2 * kSigmaRad) {
        sum += noisy_rad - clean_rad;
        sum_squares += (noisy_rad - clean_rad) * (noisy_rad - clean_rad);
        ++count;
      }
    }
    // The root only moves vertically (out of the floor); it keeps its
    // horizontal place, its orientation and every velocity.
    for (int k : {0, 1, 3, 4, 5, 6})
      EXPECT_EQ(after.qpos[root + k], before.qpos[root + k]) << t;
    EXPECT_EQ(after.qvel, before.qvel) << t;
    noisy_penetration_m =
        std::max(noisy_penetration_m, FloorPenetrationM(simulation, after));
    // The physics takes it from there.
    EXPECT_FALSE(simulation.Step(zero_actions.data()).diverged()) << t;
  }
  EXPECT_EQ(changed, total);  // every hinge of every frame
  ASSERT_GT(count, 300);
  const double mean_rad = sum / count;
  const double std_rad = std::sqrt(sum_squares / count - mean_rad * mean_rad);
  EXPECT_NEAR(mean_rad, 0.0, 0.1);
  EXPECT_NEAR(std_rad, kSigmaRad, 0.2 * kSigmaRad);
  // No deeper in the floor than the ground truth itself, give or take 1 cm
  // (measured: 5.3 mm for both; 6.3 cm without the vertical correction).
  EXPECT_LT(noisy_penetration_m, clean_penetration_m + 0.01)
      << "ground truth: " << clean_penetration_m << " m";
  EXPECT_LT(noisy_penetration_m, 0.02);

  // The noise is drawn once, from the seed: the same seed gives the same
  // states, another seed other ones.
  InitialStates same(*reference, character, options, StateBufferOptions(),
                     kSigmaRad, 7);
  InitialStates other(*reference, character, options, StateBufferOptions(),
                      kSigmaRad, 8);
  EXPECT_EQ(same.buffer(0).entry(5, 0).state.qpos,
            noisy.buffer(0).entry(5, 0).state.qpos);
  EXPECT_NE(other.buffer(0).entry(5, 0).state.qpos,
            noisy.buffer(0).entry(5, 0).state.qpos);
  EXPECT_THROW(InitialStates(*reference, character, options,
                             StateBufferOptions(), -0.1, 7),
               ConfigError);
}

// Episodes start from the buffer's state as it is: the environment adds no
// noise of its own, whatever initial_state_noise_rad says.
TEST(InitialStates, EpisodesStartFromTheBufferedStateUnchanged) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  TrackingEnvOptions env_options;
  env_options.initial_state_noise_rad = 0.5;
  auto character = testing::LoadHumanoid(env_options.simulation);
  auto reference = WalkReference(walk_path, *character, env_options.simulation);
  auto states = std::make_shared<InitialStates>(*reference, character,
                                                env_options.simulation,
                                                StateBufferOptions(), 0.5, 3);
  TrackingEnv env(character, reference, states, env_options, 1);
  std::vector<float> observation(env.observation_size());
  const SimState& state = states->buffer(0).entry(10, 0).state;
  env.ResetTo(0, 10, state, observation.data());
  // Equal up to rounding: MuJoCo renormalizes the root quaternion in place
  // on every forward pass, which can move its last bit.
  const std::vector<double> restored = env.simulation().Save().qpos;
  ASSERT_EQ(restored.size(), state.qpos.size());
  for (size_t i = 0; i < restored.size(); ++i)
    EXPECT_NEAR(restored[i], state.qpos[i], 1e-12) << i;
}

// EstimatedState is the state InitialStates fills from a view's estimate
// (here the truth's poses and cameras posing as one), and lifts a pose
// sunk into the floor out of it.
TEST(InitialStates, AnEstimatedStateIsTheBufferFilledFromTheEstimate) {
  M2D_REQUIRE_SHARED(walk_path, kWalk);
  SimulationOptions options;
  auto character = testing::LoadHumanoid(options);
  ReferenceBundle bundle = testing::MakeWalkBundle(walk_path, *character, 1.0);
  std::vector<ViewEstimate> estimate(bundle.views.size());
  for (size_t v = 0; v < bundle.views.size(); ++v) {
    estimate[v].cameras = bundle.views[v].cameras;
    estimate[v].skeleton_name = character->skeleton().name;
    estimate[v].poses = bundle.ground_truth->poses;
    estimate[v].residual_px.assign(bundle.num_frames(), 0.0);
  }
  bundle.estimate = estimate;
  const std::vector<Pose3D> poses = bundle.ground_truth->poses;
  TaskSources sources;
  sources.initial_states = InitialStateSource::kEstimate;
  sources.cameras = CameraSource::kEstimate;
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(std::move(bundle));
  auto reference = TrackingReference::Prepare(std::move(bundles), *character,
                                              options.control_hz, sources);
  InitialStates states(*reference, character, options, StateBufferOptions());
  for (int t : {0, 7, static_cast<int>(poses.size()) - 1}) {
    const SimState state = EstimatedState(character, options, poses, t);
    const SimState& filled = states.buffer(0).entry(t, 0).state;
    EXPECT_EQ(state.qpos, filled.qpos) << t;
    EXPECT_EQ(state.qvel, filled.qvel) << t;
  }
  // Moving: frame 7's root velocity is the poses' central difference.
  const SimState middle = EstimatedState(character, options, poses, 7);
  const int root = character->root_qpos_address();
  const double vx_m_s =
      (poses[8].root_position_m.x() - poses[6].root_position_m.x()) *
      options.control_hz / 2.0;
  EXPECT_NEAR(middle.qvel[character->root_dof_address()], vx_m_s, 1e-9);
  EXPECT_GT(std::abs(vx_m_s), 0.3);  // the walk moves

  // Sunk 10 cm: lifted until its lowest point is on the floor.
  std::vector<Pose3D> sunk = poses;
  sunk[3].root_position_m.z() -= 0.1;
  Simulation simulation(character, options);
  simulation.Restore(EstimatedState(character, options, sunk, 3));
  EXPECT_NEAR(LowestCharacterPointZ(simulation), 0.0, 1e-9);
  EXPECT_NEAR(simulation.data()->qpos[root + 2],
              EstimatedState(character, options, poses, 3).qpos[root + 2],
              0.1 + 1e-9);
  EXPECT_THROW(
      EstimatedState(character, options, poses, static_cast<int>(poses.size())),
      ConfigError);
}

TEST(InitialStates, EpisodesStartOnViewsInProportionToTheirWeights) {
  TrackingTask task = testing::MakeGlidingTask(/*num_views=*/3);
  InitialStates& states = *task.initial_states;
  ASSERT_EQ(states.num_views(), 3);

  // Uniform until weights are set: the draws of a plain uniform integer.
  std::mt19937_64 rng(5), same(5);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(states.DrawView(rng),
              std::uniform_int_distribution<int>(0, 2)(same));
  }
  // Weighted: in proportion, never a zero-weight view.
  states.SetViewWeights({0.0, 3.0, 1.0});
  std::vector<int> counts(3, 0);
  for (int i = 0; i < 4000; ++i) ++counts[states.DrawView(rng)];
  EXPECT_EQ(counts[0], 0);
  EXPECT_NEAR(counts[1] / 4000.0, 0.75, 0.03);
  EXPECT_NEAR(counts[2] / 4000.0, 0.25, 0.03);
  // The environments' episodes follow them.
  states.SetViewWeights({0.0, 0.0, 1.0});
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  TrackingEnvOptions(), /*seed=*/3);
  std::vector<float> observation(env.observation_size());
  for (int i = 0; i < 20; ++i) {
    env.Reset(observation.data());
    EXPECT_EQ(env.episode().view_index, 2);
  }
  // Refused, the weights left as they were.
  EXPECT_THROW(states.SetViewWeights({1.0, 1.0}), ConfigError);
  EXPECT_THROW(states.SetViewWeights({1.0, -1.0, 1.0}), ConfigError);
  EXPECT_THROW(states.SetViewWeights({1.0, NAN, 1.0}), ConfigError);
  EXPECT_THROW(states.SetViewWeights({0.0, 0.0, 0.0}), ConfigError);
  EXPECT_EQ(states.DrawView(rng), 2);
}

}  // namespace
}  // namespace m2d
