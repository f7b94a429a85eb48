// tests: stepping the humanoid — long rollouts without NaN, PD holding and
// step responses, bit-exact save/restore, divergence detection, keypoints,
// contacts and torques.
#include "sim/simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <thread>

#include "common/error.h"
#include "sim/pose_mapping.h"
#include "sim_test_util.h"

namespace m2d {
namespace {

using testing::ActionsForAngles;
using testing::HingeAngles;
using testing::LoadHumanoid;
using testing::StandingActions;

bool StateIsFinite(const Simulation& sim) {
  for (int i = 0; i < sim.model()->nq; ++i) {
    if (!std::isfinite(sim.data()->qpos[i])) return false;
  }
  for (int i = 0; i < sim.model()->nv; ++i) {
    if (!std::isfinite(sim.data()->qvel[i])) return false;
  }
  return true;
}

struct RolloutCounts {
  int divergences = 0;
  int falls = 0;
  int episodes = 0;
  bool saw_non_finite = false;
};

// `steps` control steps with actions from `policy`; an episode ends on
// divergence, a fall (a body other than the feet on the ground) or after
// 10 s, and the simulation is reset.
template <typename Policy>
RolloutCounts Rollout(Simulation* sim, int steps, Policy policy) {
  RolloutCounts counts;
  std::vector<float> actions(sim->character().num_actions());
  int episode_length = 0;
  for (int t = 0; t < steps; ++t) {
    policy(&actions);
    const StepResult result = sim->Step(actions.data());
    ++episode_length;
    if (!result.diverged() && !StateIsFinite(*sim))
      counts.saw_non_finite = true;
    const bool fell = sim->UnexpectedGroundContact();
    if (result.diverged() || fell || episode_length >= 300) {
      counts.divergences += result.diverged();
      counts.falls += fell && !result.diverged();
      ++counts.episodes;
      sim->Reset();
      episode_length = 0;
    }
  }
  return counts;
}

TEST(SimulationTest, ZeroActionRollout10kStepsNeverProducesNan) {
  Simulation sim(LoadHumanoid("flat"), SimulationOptions());
  const RolloutCounts counts = Rollout(&sim, 10000, [](std::vector<float>* a) {
    std::fill(a->begin(), a->end(), 0.0f);
  });
  EXPECT_EQ(counts.divergences, 0);
  EXPECT_FALSE(counts.saw_non_finite);
  std::printf(
      "zero actions, 10000 steps: %d episodes, %d falls, %d divergences\n",
      counts.episodes, counts.falls, counts.divergences);
}

TEST(SimulationTest, RandomActionRollout10kStepsNeverProducesNan) {
  for (const char* scene : {"flat", "ball", "flat pd"}) {
    SimulationOptions options;
    if (std::string(scene) == "flat pd")
      options.torque_limit = TorqueLimit::kPd;
    Simulation sim(
        LoadHumanoid(
            std::string(scene).substr(0, 4) == "ball" ? "ball" : "flat",
            options),
        options);
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    const RolloutCounts counts =
        Rollout(&sim, 10000, [&](std::vector<float>* a) {
          for (float& x : *a) x = uniform(rng);
        });
    EXPECT_EQ(counts.divergences, 0) << scene;
    EXPECT_FALSE(counts.saw_non_finite) << scene;
    std::printf(
        "%s, uniform random actions, 10000 steps: %d episodes, %d falls, "
        "%d divergences\n",
        scene, counts.episodes, counts.falls, counts.divergences);
  }
}

// With gravity and contacts off, only joint forces act: a pose held with
// its own angles as PD targets and zero velocity stays exactly still.
TEST(SimulationTest, PdHoldsAPoseStillWithoutExternalForces) {
  auto character = LoadHumanoid("floating");
  Simulation sim(character, SimulationOptions());
  std::mt19937 rng(5);
  std::vector<double> angles;
  for (const ActuatedHinge& hinge : character->hinges()) {
    std::uniform_real_distribution<double> in_range(hinge.range_low_rad + 0.1,
                                                    hinge.range_high_rad - 0.1);
    angles.push_back(in_range(rng));
  }
  mjData* d = sim.mutable_data();
  for (int i = 0; i < character->num_actions(); ++i) {
    d->qpos[character->hinges()[i].qpos_address] = angles[i];
  }
  sim.Refresh();
  const std::vector<float> hold = ActionsForAngles(*character, angles);
  double max_speed = 0.0;
  for (int t = 0; t < 300; ++t) {
    ASSERT_FALSE(sim.Step(hold.data()).diverged());
    for (int i = 0; i < sim.model()->nv; ++i) {
      max_speed = std::max(max_speed, std::abs(d->qvel[i]));
    }
  }
  const std::vector<double> after = HingeAngles(sim);
  for (int i = 0; i < character->num_actions(); ++i) {
    EXPECT_NEAR(after[i], angles[i], 1e-5) << i;
  }
  EXPECT_LT(max_speed, 1e-4);
}

// Standing on the floor under gravity: PD holds the standing pose for 10 s.
TEST(SimulationTest, PdHoldsStandingOnTheFloor) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  const double standing_height_m = sim.data()->qpos[2];
  const std::vector<float> stand = StandingActions(*character);
  for (int t = 0; t < 300; ++t) ASSERT_FALSE(sim.Step(stand.data()).diverged());
  EXPECT_NEAR(sim.data()->qpos[2], standing_height_m, 0.01);
  EXPECT_FALSE(sim.UnexpectedGroundContact());
  for (double angle : HingeAngles(sim)) EXPECT_NEAR(angle, 0.0, 0.05);
  // Holding the body up takes torque (knees, hips, ankles) and little power.
  double total_torque = 0.0;
  for (double torque : sim.mean_torques_nm()) total_torque += std::abs(torque);
  EXPECT_GT(total_torque, 1.0);
}

// The dog on its four straight legs: PD holds it standing, paws on the
// floor, for 10 s.
TEST(SimulationTest, PdHoldsTheDogStandingOnTheFloor) {
  auto character = testing::LoadDog("flat");
  Simulation sim(character, SimulationOptions());
  const double standing_height_m = sim.data()->qpos[2];
  const std::vector<float> stand = StandingActions(*character);
  for (int t = 0; t < 300; ++t) ASSERT_FALSE(sim.Step(stand.data()).diverged());
  EXPECT_NEAR(sim.data()->qpos[2], standing_height_m, 0.02);
  EXPECT_FALSE(sim.UnexpectedGroundContact());
  // The tail's soft servos (kp 20 and 10 N m/rad) let it sag 0.06 rad.
  for (double angle : HingeAngles(sim)) EXPECT_NEAR(angle, 0.0, 0.1);
}

// Random step changes of the PD targets (0.4 rad around standing) converge
// without oscillation at every substep count, even one (30 Hz physics).
TEST(SimulationTest, StepResponseConvergesAtEverySubstepCount) {
  for (int run = 0; run < 12; ++run) {
    const int substeps = 1 + run % 6;
    SimulationOptions options;
    options.physics_substeps = substeps;
    options.torque_limit = run < 6 ? TorqueLimit::kServo : TorqueLimit::kPd;
    auto character = LoadHumanoid("floating", options);
    Simulation sim(character, options);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> offset(-0.4, 0.4);
    for (int trial = 0; trial < 10; ++trial) {
      sim.Reset();
      std::vector<double> targets;
      for (const ActuatedHinge& hinge : character->hinges()) {
        targets.push_back(std::clamp(offset(rng), hinge.range_low_rad + 0.1,
                                     hinge.range_high_rad - 0.1));
      }
      const std::vector<float> actions = ActionsForAngles(*character, targets);
      double worst_overshoot = 0.0;
      for (int t = 0; t < 60; ++t) {
        ASSERT_FALSE(sim.Step(actions.data()).diverged()) << substeps;
        const std::vector<double> angles = HingeAngles(sim);
        for (size_t i = 0; i < angles.size(); ++i) {
          // Overshoot past the target, relative to the step size.
          const double step = targets[i];
          if (std::abs(step) > 0.05) {
            worst_overshoot =
                std::max(worst_overshoot, (angles[i] - targets[i]) / step);
          }
        }
      }
      const std::vector<double> angles = HingeAngles(sim);
      for (size_t i = 0; i < angles.size(); ++i) {
        EXPECT_NEAR(angles[i], targets[i], 1e-3) << "substeps " << substeps;
      }
      // Joint coupling gives some overshoot (measured at most 19%); an
      // unstable or underdamped loop would ring far past the target.
      EXPECT_LT(worst_overshoot, 0.3) << "substeps " << substeps;
    }
  }
}

// The elbow flung from one end of its range toward the other (floating
// scene, the rest held): under kServo the joint's damping, beyond the
// elbow's 60 N m, holds it near limit / kd = 2 rad/s; under kPd the limit
// bounds the whole PD and the elbow goes several times faster, its torque
// (servo + damping + the damping's cancellation) at the limit meanwhile.
TEST(SimulationTest, APdTorqueLimitLetsAJointMoveFasterThanItsDampingAllows) {
  double peak_speed_rad_s[2] = {0.0, 0.0};
  for (TorqueLimit limit : {TorqueLimit::kServo, TorqueLimit::kPd}) {
    SimulationOptions options;
    options.torque_limit = limit;
    auto character = LoadHumanoid("floating", options);
    Simulation sim(character, options);
    int elbow = -1;
    for (int i = 0; i < character->num_actions(); ++i) {
      const char* name = mj_id2name(character->model(), mjOBJ_JOINT,
                                    character->hinges()[i].joint_id);
      if (std::string(name) == "right_elbow") elbow = i;
    }
    ASSERT_GE(elbow, 0);
    const ActuatedHinge& hinge = character->hinges()[elbow];
    EXPECT_DOUBLE_EQ(hinge.kp_nm_per_rad, 300.0);
    EXPECT_DOUBLE_EQ(hinge.kd_nm_s_per_rad, 30.0);
    EXPECT_DOUBLE_EQ(hinge.torque_high_nm, 60.0);
    sim.mutable_data()->qpos[hinge.qpos_address] = hinge.range_low_rad + 0.05;
    sim.Refresh();
    std::vector<double> targets(character->num_actions(), 0.0);
    targets[elbow] = hinge.range_high_rad - 0.05;
    const std::vector<float> actions = ActionsForAngles(*character, targets);
    double& peak = peak_speed_rad_s[limit == TorqueLimit::kPd];
    for (int t = 0; t < 60; ++t) {
      ASSERT_FALSE(sim.Step(actions.data()).diverged()) << SettingName(limit);
      const double speed = std::abs(sim.data()->qvel[hinge.dof_address]);
      peak = std::max(peak, speed);
      EXPECT_LE(std::abs(sim.mean_torques_nm()[elbow]), 60.0 * 1.001)
          << SettingName(limit) << " step " << t;
    }
    // Both arrive (the servo limit slowly).
    EXPECT_NEAR(HingeAngles(sim)[elbow], targets[elbow], 0.02)
        << SettingName(limit);
  }
  EXPECT_LT(peak_speed_rad_s[0], 2.2);
  EXPECT_GT(peak_speed_rad_s[1], 3.0 * peak_speed_rad_s[0]);
  std::printf("elbow's peak speed: servo limit %.2f rad/s, pd limit %.2f\n",
              peak_speed_rad_s[0], peak_speed_rad_s[1]);
}

// Within the limits the two are one controller: small steps of the targets
// give the same states, bit for bit.
TEST(SimulationTest, WithinItsLimitsAPdLimitChangesNothing) {
  std::vector<std::vector<double>> qpos_after;
  for (TorqueLimit limit : {TorqueLimit::kServo, TorqueLimit::kPd}) {
    SimulationOptions options;
    options.torque_limit = limit;
    auto character = LoadHumanoid("floating", options);
    Simulation sim(character, options);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> offset(-0.03, 0.03);
    std::vector<double> targets;
    for (int i = 0; i < character->num_actions(); ++i) {
      targets.push_back(offset(rng));
    }
    const std::vector<float> actions = ActionsForAngles(*character, targets);
    for (int t = 0; t < 30; ++t)
      ASSERT_FALSE(sim.Step(actions.data()).diverged());
    qpos_after.emplace_back(sim.data()->qpos,
                            sim.data()->qpos + character->model()->nq);
  }
  EXPECT_EQ(qpos_after[0], qpos_after[1]);
}

// Why position servos with joint damping: MuJoCo's Euler integrator treats
// damping implicitly. The same gains applied as explicit torques
// (tau = kp (q* - q) - kd qdot, computed before each physics step) blow up
// or end in a torque-limited oscillation at 120 Hz.
TEST(SimulationTest, ExplicitPdWithTheSameGainsFailsAtTheDefaultRate) {
  SimulationOptions options;
  auto character = LoadHumanoid("floating", options);
  MujocoModelPtr explicit_model(mj_copyModel(nullptr, character->model()));
  mjModel* m = explicit_model.get();
  std::vector<double> kp, kd;
  for (const ActuatedHinge& hinge : character->hinges()) {
    kp.push_back(m->actuator_gainprm[hinge.actuator_id * mjNGAIN]);
    kd.push_back(m->dof_damping[hinge.dof_address]);
    m->dof_damping[hinge.dof_address] = 0.0;
    m->actuator_gainprm[hinge.actuator_id * mjNGAIN] = 1.0;  // a torque motor
    m->actuator_biasprm[hinge.actuator_id * mjNBIAS + 1] = 0.0;
  }
  MujocoDataPtr d = MakeMujocoData(m);
  std::vector<double> targets;
  for (const ActuatedHinge& hinge : character->hinges()) {
    targets.push_back(
        std::clamp(0.2, hinge.range_low_rad + 0.1, hinge.range_high_rad - 0.1));
  }
  double worst_error = 0.0;
  for (int t = 0; t < 60 * options.physics_substeps; ++t) {
    for (size_t i = 0; i < kp.size(); ++i) {
      const ActuatedHinge& hinge = character->hinges()[i];
      d->ctrl[hinge.actuator_id] =
          kp[i] * (targets[i] - d->qpos[hinge.qpos_address]) -
          kd[i] * d->qvel[hinge.dof_address];
    }
    mj_step(m, d.get());
  }
  for (size_t i = 0; i < kp.size(); ++i) {
    const double q = d->qpos[character->hinges()[i].qpos_address];
    worst_error = std::max(worst_error,
                           std::isfinite(q) ? std::abs(q - targets[i]) : 1e9);
  }
  const bool blew_up = d->warning[mjWARN_BADQACC].number > 0 ||
                       d->warning[mjWARN_BADQVEL].number > 0;
  EXPECT_TRUE(blew_up || worst_error > 0.1) << worst_error;

  // Our servos reach the same targets.
  Simulation sim(character, options);
  const std::vector<float> actions = ActionsForAngles(*character, targets);
  for (int t = 0; t < 60; ++t)
    ASSERT_FALSE(sim.Step(actions.data()).diverged());
  const std::vector<double> angles = HingeAngles(sim);
  for (size_t i = 0; i < angles.size(); ++i)
    EXPECT_NEAR(angles[i], targets[i], 1e-3);
}

TEST(SimulationTest, SaveRestoreReproducesTrajectoriesBitExactly) {
  auto character = LoadHumanoid("ball");
  Simulation sim(character, SimulationOptions());
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<std::vector<float>> actions(
      150, std::vector<float>(character->num_actions()));
  for (auto& a : actions) {
    for (float& x : a) x = 0.5f * uniform(rng);
  }
  for (int t = 0; t < 50; ++t) sim.Step(actions[t].data());
  // A push, so the applied forces are part of what must be restored.
  sim.mutable_data()->xfrc_applied[6 * character->root_body()] = 80.0;
  const SimState saved = sim.Save();

  auto run = [&](Simulation* s) {
    std::vector<double> trajectory;
    for (int t = 50; t < 150; ++t) {
      s->Step(actions[t].data());
      trajectory.insert(trajectory.end(), s->data()->qpos,
                        s->data()->qpos + s->model()->nq);
      trajectory.insert(trajectory.end(), s->data()->qvel,
                        s->data()->qvel + s->model()->nv);
    }
    return trajectory;
  };
  const std::vector<double> first = run(&sim);
  sim.Restore(saved);
  EXPECT_EQ(sim.data()->time, saved.time_s);
  const std::vector<double> second = run(&sim);
  ASSERT_EQ(first.size(), second.size());
  EXPECT_EQ(
      std::memcmp(first.data(), second.data(), sizeof(double) * first.size()),
      0);

  // Another simulation of the same character continues identically too.
  Simulation other(character, SimulationOptions());
  other.Restore(saved);
  const std::vector<double> third = run(&other);
  EXPECT_EQ(
      std::memcmp(first.data(), third.data(), sizeof(double) * first.size()),
      0);
}

// Simulations on different threads share one immutable model and give the
// same trajectories as when run one after another.
TEST(SimulationTest, ThreadsShareOneCharacterModel) {
  auto character = LoadHumanoid("ball");
  auto run = [&](unsigned seed, std::vector<double>* qpos_out) {
    Simulation sim(character, SimulationOptions());
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    std::vector<float> actions(character->num_actions());
    for (int t = 0; t < 300; ++t) {
      for (float& a : actions) a = uniform(rng);
      if (sim.Step(actions.data()).diverged()) sim.Reset();
    }
    qpos_out->assign(sim.data()->qpos, sim.data()->qpos + sim.model()->nq);
  };
  std::vector<double> sequential_a, sequential_b, threaded_a, threaded_b;
  run(1, &sequential_a);
  run(2, &sequential_b);
  std::thread first(run, 1u, &threaded_a);
  std::thread second(run, 2u, &threaded_b);
  first.join();
  second.join();
  EXPECT_EQ(sequential_a, threaded_a);
  EXPECT_EQ(sequential_b, threaded_b);
  EXPECT_NE(sequential_a, sequential_b);
}

TEST(SimulationTest, RestoreRejectsAStateOfAnotherModel) {
  Simulation flat(LoadHumanoid("flat"), SimulationOptions());
  Simulation ball(LoadHumanoid("ball"), SimulationOptions());
  EXPECT_THROW(flat.Restore(ball.Save()), InputError);
}

TEST(SimulationTest, AbsurdVelocityIsReportedAsDivergedAndRecoverable) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  const std::vector<float> stand = StandingActions(*character);
  const SimState good = sim.Save();

  sim.mutable_data()->qvel[character->hinges()[3].dof_address] = 1e4;
  sim.Refresh();
  EXPECT_TRUE(sim.diverged());
  EXPECT_EQ(sim.divergence(), Divergence::kExcessiveSpeed);
  // Stepping a diverged simulation does nothing but report it.
  const double time_before = sim.data()->time;
  EXPECT_TRUE(sim.Step(stand.data()).diverged());
  EXPECT_EQ(sim.data()->time, time_before);

  sim.Restore(good);
  EXPECT_FALSE(sim.diverged());
  EXPECT_FALSE(sim.Step(stand.data()).diverged());
}

TEST(SimulationTest, NanStateIsReportedAsDiverged) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  sim.mutable_data()->qvel[10] = std::nan("");
  sim.Refresh();
  EXPECT_TRUE(sim.diverged());
  sim.Reset();
  EXPECT_FALSE(sim.diverged());
  sim.mutable_data()->qpos[3] = std::nan("");
  sim.Refresh();
  EXPECT_TRUE(sim.diverged());
  sim.Reset();
  EXPECT_FALSE(sim.diverged());
}

TEST(SimulationTest, BlowUpDuringAStepIsCaught) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  // An absurd external force (1e9 N on the pelvis) launches the body.
  sim.mutable_data()->xfrc_applied[6 * character->root_body() + 2] = 1e9;
  const std::vector<float> stand = StandingActions(*character);
  const StepResult result = sim.Step(stand.data());
  EXPECT_TRUE(result.diverged());
  EXPECT_NE(result.divergence, Divergence::kNone);
  sim.Reset();
  EXPECT_FALSE(sim.Step(stand.data()).diverged());
}

TEST(SimulationTest, NanActionsHoldTheRangeCentre) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  std::vector<float> actions(character->num_actions(), std::nanf(""));
  actions[0] = 5.0f;  // clipped to 1
  std::vector<double> targets(character->num_actions());
  sim.ActionsToTargets(actions.data(), targets.data());
  EXPECT_DOUBLE_EQ(targets[0], character->hinges()[0].range_high_rad);
  EXPECT_DOUBLE_EQ(targets[1], character->hinges()[1].target_mid_rad);
  EXPECT_FALSE(sim.Step(actions.data()).diverged());
  EXPECT_TRUE(StateIsFinite(sim));
}

TEST(SimulationTest, MujocoErrorsThrowInsteadOfExiting) {
  InstallMujocoErrorHandlers();
  EXPECT_THROW(mju_error("deliberate test error"), MujocoError);
}

TEST(SimulationTest, KeypointsAreTheSkeletonKeypointsOfTheSetPose) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  Pose3D pose = QposToPose(*character, character->model()->qpos0);
  pose.root_position_m = Eigen::Vector3d(1.0, -2.0, 0.9);
  pose.local_rotations[0] = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  pose.local_rotations[character->skeleton().IndexOf("left_elbow")] =
      Eigen::AngleAxisd(0.8,
                        character->skeleton()
                            .joints[character->skeleton().IndexOf("left_elbow")]
                            .axis);
  sim.SetPose(pose);
  std::vector<double> keypoints(3 * 17);
  sim.KeypointPositions(keypoints.data());
  const std::vector<Eigen::Vector3d> expected =
      KeypointPositions(character->skeleton(), character->keypoint_map(), pose);
  for (int k = 0; k < 17; ++k) {
    EXPECT_LT((Eigen::Vector3d(&keypoints[3 * k]) - expected[k]).norm(), 1e-9)
        << k;
  }
}

TEST(SimulationTest, ContactQueriesSeeFeetOnTheFloorAndFalls) {
  auto character = LoadHumanoid("flat");
  Simulation sim(character, SimulationOptions());
  const std::vector<float> stand = StandingActions(*character);
  for (int t = 0; t < 10; ++t) sim.Step(stand.data());
  EXPECT_TRUE(sim.BodyTouchesGround(character->BodyId("left_foot")));
  EXPECT_TRUE(sim.BodyTouchesGround(character->BodyId("right_foot")));
  EXPECT_FALSE(sim.BodyTouchesGround(character->BodyId("pelvis")));
  EXPECT_FALSE(sim.UnexpectedGroundContact());
  std::vector<uint8_t> touching;
  sim.GroundContacts(&touching);
  int count = 0;
  for (uint8_t t : touching) count += t;
  EXPECT_EQ(count, 2);

  // Lying face up on the floor: the torso touches the ground.
  Pose3D lying = QposToPose(*character, character->model()->qpos0);
  lying.root_position_m = Eigen::Vector3d(0, 0, 0.1);
  lying.local_rotations[0] =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY());
  sim.SetPose(lying);
  EXPECT_TRUE(sim.UnexpectedGroundContact());
  EXPECT_TRUE(sim.BodyTouchesGround(character->BodyId("torso")));
}

TEST(SimulationTest, SetPoseLeavesTheBallAlone) {
  auto character = LoadHumanoid("ball");
  Simulation sim(character, SimulationOptions());
  const FreeObject& ball = character->free_objects()[0];
  mjData* d = sim.mutable_data();
  d->qpos[ball.qpos_address] = 2.0;
  d->qvel[ball.dof_address] = 1.5;
  sim.Refresh();
  Pose3D pose = QposToPose(*character, character->model()->qpos0);
  std::vector<double> qvel(sim.model()->nv, 0.3);
  sim.SetPose(pose, qvel.data());
  EXPECT_EQ(d->qpos[ball.qpos_address], 2.0);
  EXPECT_EQ(d->qvel[ball.dof_address], 1.5);
  EXPECT_EQ(d->qvel[character->root_dof_address()], 0.3);
}

TEST(SimulationTest, BallRollsToAStopWithoutBouncingHigher) {
  auto character = LoadHumanoid("ball");
  Simulation sim(character, SimulationOptions());
  const FreeObject& ball = character->free_objects()[0];
  mjData* d = sim.mutable_data();
  // Dropped from 1 m far from the character.
  d->qpos[ball.qpos_address] = 3.0;
  d->qpos[ball.qpos_address + 2] = 1.11;
  sim.Refresh();
  const std::vector<float> stand = StandingActions(*character);
  double highest_after_impact = 0.0;
  bool landed = false;
  for (int t = 0; t < 60; ++t) {
    ASSERT_FALSE(sim.Step(stand.data()).diverged());
    landed = landed || sim.data()->qvel[ball.dof_address + 2] > 0;
    if (landed)
      highest_after_impact =
          std::max(highest_after_impact, d->qpos[ball.qpos_address + 2]);
  }
  EXPECT_LT(highest_after_impact, 1.11);
  EXPECT_NEAR(d->qpos[ball.qpos_address + 2], 0.11, 0.01);
  // Rolling at 3 m/s: slows down by rolling friction.
  d->qvel[ball.dof_address] = 3.0;
  d->qvel[ball.dof_address + 4] = 3.0 / 0.11;
  sim.Refresh();
  for (int t = 0; t < 60; ++t) ASSERT_FALSE(sim.Step(stand.data()).diverged());
  const double speed = d->qvel[ball.dof_address];
  EXPECT_GT(speed, 1.0);
  EXPECT_LT(speed, 2.8);
}

// Simulation::Step against raw mj_step is a speed figure, not a test: it
// is measured by bench/env_bench.cc (BM_SimulationStep against
// BM_BarePhysicsStep, the same run) and docs/simulation.md reports it.

}  // namespace
}  // namespace m2d
