// tests: the inverse-dynamics feasibility of a reference motion
// (eval/motion_feasibility.h): standing, a ballistic flight and a hover, an
// arm swung slowly and too fast, a knee bent past its range, limbs folded
// through the body, and the DeepMimic walk at its own pace and five times
// faster, under either reading of the torque limits.
#include "eval/motion_feasibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include "common/error.h"
#include "motion/motion_io.h"
#include "sim/pose_mapping.h"
#include "sim/simulation.h"
#include "test_paths.h"

namespace m2d {
namespace {

constexpr double kFps = 30.0;

std::shared_ptr<const Character> Humanoid() {
  static std::shared_ptr<const Character> character =
      LoadCharacterForSimulation(
          testing::SourcePath("assets/characters/humanoid.yaml"), "flat",
          SimulationOptions());
  return character;
}

// The character's standing qpos, feet on the floor.
std::vector<double> StandingQpos(std::shared_ptr<const Character> character) {
  Simulation simulation(character, SimulationOptions());
  simulation.Reset();
  const mjData* d = simulation.data();
  return std::vector<double>(d->qpos, d->qpos + character->model()->nq);
}

int HingeOfActuator(const Character& character, const std::string& name) {
  for (size_t h = 0; h < character.hinges().size(); ++h) {
    const char* actuator = mj_id2name(character.model(), mjOBJ_ACTUATOR,
                                      character.hinges()[h].actuator_id);
    if (actuator && name == actuator) return static_cast<int>(h);
  }
  ADD_FAILURE() << "no actuator " << name;
  return 0;
}

// Standing, raised by `height_m(t)` and with the right shoulder's y hinge at
// `shoulder_rad(t)`, for `num_frames` frames at kFps.
template <typename Height, typename Shoulder>
std::vector<Pose3D> StandingMotion(const Character& character, int num_frames,
                                   Height height_m, Shoulder shoulder_rad) {
  std::vector<double> qpos = StandingQpos(Humanoid());
  const double ground_z = qpos[character.root_qpos_address() + 2];
  const int shoulder =
      character.hinges()[HingeOfActuator(character, "right_shoulder_y")]
          .qpos_address;
  std::vector<Pose3D> poses;
  for (int t = 0; t < num_frames; ++t) {
    const double time_s = t / kFps;
    qpos[character.root_qpos_address() + 2] = ground_z + height_m(time_s);
    qpos[shoulder] = shoulder_rad(time_s);
    poses.push_back(QposToPose(character, qpos.data()));
  }
  return poses;
}

TEST(MotionFeasibility, StandingStillTakesTheBodyWeightFromTheFloor) {
  auto character = Humanoid();
  const std::vector<Pose3D> poses = StandingMotion(
      *character, 10, [](double) { return 0.0; }, [](double) { return 0.0; });
  const MotionFeasibility result =
      MeasureMotionFeasibility(*character, poses, kFps, FeasibilityOptions());

  ASSERT_EQ(result.num_frames, 10);
  EXPECT_GT(result.body_weight_n, 300.0);  // a 40-90 kg humanoid
  EXPECT_LT(result.body_weight_n, 900.0);
  EXPECT_EQ(result.AirborneFrames(), 0);
  EXPECT_EQ(result.FramesFloorCannotExplain(), 0);
  EXPECT_EQ(result.FramesOverTorqueLimit(), 0);
  EXPECT_EQ(result.FramesOutOfRange(), 0);
  EXPECT_EQ(result.FramesSelfPenetrating(), 0);
  EXPECT_EQ(result.DeepestSelfPenetration(), nullptr);
  for (const FrameDemand& frame : result.frames) {
    EXPECT_NEAR(frame.external_force_n.z(), result.body_weight_n,
                1e-6 * result.body_weight_n);
    EXPECT_NEAR(frame.external_force_n.head<2>().norm(), 0.0, 1e-6);
  }
  // The arms are measured (holding themselves up takes a little torque);
  // the legs stand on the floor, so their torques are not known.
  const HingeDemand& shoulder =
      result.hinges[HingeOfActuator(*character, "right_shoulder_y")];
  EXPECT_EQ(shoulder.frames_measured, 10);
  EXPECT_LT(shoulder.peak_nm, 0.2 * shoulder.limit_nm);
  EXPECT_DOUBLE_EQ(shoulder.limit_nm, 100.0);
  EXPECT_EQ(
      result.hinges[HingeOfActuator(*character, "right_knee")].frames_measured,
      0);
}

TEST(MotionFeasibility, ABallisticFlightNeedsNoForceAndAHoverIsCaught) {
  auto character = Humanoid();
  const double g = 9.81;
  // Thrown up at 2 m/s from 1 m: the parabola of gravity alone (central
  // differences are exact on a quadratic).
  const std::vector<Pose3D> thrown = StandingMotion(
      *character, 12, [g](double t) { return 1.0 + 2.0 * t - 0.5 * g * t * t; },
      [](double) { return 0.0; });
  const MotionFeasibility flight =
      MeasureMotionFeasibility(*character, thrown, kFps, FeasibilityOptions());
  EXPECT_EQ(flight.AirborneFrames(), 12);
  EXPECT_LT(flight.MeanForceInFlightBodyWeights(), 1e-3);
  EXPECT_EQ(flight.FramesFloorCannotExplain(), 0);
  // In the air every hinge is measured, legs included.
  EXPECT_EQ(
      flight.hinges[HingeOfActuator(*character, "right_knee")].frames_measured,
      12);

  const std::vector<Pose3D> hovering = StandingMotion(
      *character, 12, [](double) { return 1.0; }, [](double) { return 0.0; });
  const MotionFeasibility hover = MeasureMotionFeasibility(
      *character, hovering, kFps, FeasibilityOptions());
  EXPECT_NEAR(hover.MeanForceInFlightBodyWeights(), 1.0, 1e-6);
  EXPECT_EQ(hover.FramesFloorCannotExplain(), 12);
  EXPECT_TRUE(hover.frames[5].force_in_flight);
  EXPECT_NE(hover.BriefReport().find("12 force in flight"), std::string::npos)
      << hover.BriefReport();
}

TEST(MotionFeasibility, AnArmSwungTooFastIsOverItsTorqueLimit) {
  auto character = Humanoid();
  const int shoulder = HingeOfActuator(*character, "right_shoulder_y");
  // 0.3 rad at 2 rad/s takes little; 1 rad at 30 rad/s (the damping alone
  // asks 40 N m s x 30 rad/s) is far past the shoulder's 100 N m.
  const auto in_the_air = [](double) { return 1.0; };
  const MotionFeasibility slow = MeasureMotionFeasibility(
      *character,
      StandingMotion(*character, 30, in_the_air,
                     [](double t) { return -0.3 * std::sin(2.0 * t); }),
      kFps, FeasibilityOptions());
  const MotionFeasibility fast = MeasureMotionFeasibility(
      *character,
      StandingMotion(*character, 30, in_the_air,
                     [](double t) { return -1.0 * std::sin(30.0 * t); }),
      kFps, FeasibilityOptions());
  EXPECT_EQ(slow.hinges[shoulder].frames_over_limit, 0);
  EXPECT_EQ(slow.FramesOverTorqueLimit(), 0);
  EXPECT_GT(fast.hinges[shoulder].frames_over_limit, 20);
  EXPECT_GT(fast.hinges[shoulder].peak_nm, 3.0 * slow.hinges[shoulder].peak_nm);
  EXPECT_GT(fast.FramesOverTorqueLimit(), 20);
  EXPECT_EQ(fast.frames[10].worst_hinge, shoulder);
  EXPECT_NE(fast.BriefReport().find("right_shoulder_y"), std::string::npos);
}

TEST(MotionFeasibility, AKneeBentBackwardsIsOutOfItsRange) {
  auto character = Humanoid();
  const int knee = HingeOfActuator(*character, "right_knee");
  // The knee's range is 0-160 degrees; from frame 5 on it is bent 0.5 rad
  // the wrong way, which no solution of the rotation puts in range.
  std::vector<double> qpos = StandingQpos(character);
  std::vector<Pose3D> poses;
  for (int t = 0; t < 10; ++t) {
    qpos[character->hinges()[knee].qpos_address] = t < 5 ? 0.3 : -0.5;
    poses.push_back(QposToPose(*character, qpos.data()));
  }
  const MotionFeasibility result =
      MeasureMotionFeasibility(*character, poses, kFps, FeasibilityOptions());
  EXPECT_EQ(result.FramesOutOfRange(), 5);
  EXPECT_EQ(result.hinges[knee].frames_out_of_range, 5);
  EXPECT_NEAR(result.hinges[knee].peak_range_excess_rad, 0.5, 1e-6);
  EXPECT_EQ(result.hinges[knee].peak_range_frame, 5);
  EXPECT_EQ(result.frames[4].worst_range_hinge, -1);
  EXPECT_EQ(result.frames[7].worst_range_hinge, knee);
  EXPECT_EQ(result.WorstRangeHinge(), &result.hinges[knee]);
  EXPECT_NE(result.BriefReport().find("out of a joint range: 5 frames"),
            std::string::npos)
      << result.BriefReport();

  // Within the tolerance (recorded motion resting on a range's end) it is
  // not counted, though the excess is kept.
  FeasibilityOptions tolerant;
  tolerant.range_tolerance_rad = 0.6;
  EXPECT_EQ(MeasureMotionFeasibility(*character, poses, kFps, tolerant)
                .FramesOutOfRange(),
            0);
}

// Random angles within the ranges fold limbs through each other and the
// trunk: the self-overlap is found and its geoms named.
TEST(MotionFeasibility, LimbsFoldedThroughTheBodyOverlapIt) {
  auto character = Humanoid();
  std::vector<double> qpos = StandingQpos(character);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Pose3D> poses;
  for (int t = 0; t < 20; ++t) {
    for (const ActuatedHinge& hinge : character->hinges()) {
      qpos[hinge.qpos_address] =
          hinge.range_low_rad +
          unit(rng) * (hinge.range_high_rad - hinge.range_low_rad);
    }
    qpos[character->root_qpos_address() + 2] = 1.5;  // clear of the floor
    poses.push_back(QposToPose(*character, qpos.data()));
  }
  const MotionFeasibility result =
      MeasureMotionFeasibility(*character, poses, kFps, FeasibilityOptions());
  EXPECT_GT(result.FramesSelfPenetrating(), 3);
  const FrameDemand* deepest = result.DeepestSelfPenetration();
  ASSERT_NE(deepest, nullptr);
  EXPECT_GT(deepest->self_penetration_m, 0.02);
  EXPECT_NE(deepest->self_contact.find('/'), std::string::npos);
  EXPECT_NE(result.BriefReport().find("self-penetrating"), std::string::npos);
  // Within their ranges every frame is in reach.
  EXPECT_EQ(result.FramesOutOfReach(), 0);
}

// The largest peak torque / limit over the measured hinges.
double PeakRatio(const MotionFeasibility& result) {
  const HingeDemand* worst = result.WorstHinge();
  return worst ? worst->peak_ratio : 0.0;
}

// Under a limit on the whole PD (DeepMimic's) the walk is within reach and
// five times faster it is not; under the servo limit the joints' damping
// already puts the walk's swinging ankles past theirs.
TEST(MotionFeasibility,
     TheWalkAtItsPaceFitsThePdLimitsAndFiveTimesFasterDoesNot) {
  auto character = Humanoid();
  const Motion3D motion = ReadDeepMimicMotion(
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt"),
      character->shared_skeleton());
  std::vector<Pose3D> walk;
  for (int t = 0; t < 36; ++t) walk.push_back(SamplePose(motion, t / kFps));
  std::vector<Pose3D> hurried;
  for (int t = 0; t < 12; ++t)
    hurried.push_back(SamplePose(motion, 5.0 * t / kFps));

  FeasibilityOptions pd;
  pd.torque_limit = TorqueLimit::kPd;
  const MotionFeasibility at_pace =
      MeasureMotionFeasibility(*character, walk, kFps, pd);
  const MotionFeasibility fast =
      MeasureMotionFeasibility(*character, hurried, kFps, pd);
  const MotionFeasibility servo =
      MeasureMotionFeasibility(*character, walk, kFps, FeasibilityOptions());
  EXPECT_LE(at_pace.FramesOverTorqueLimit(), 1) << at_pace.BriefReport();
  EXPECT_LE(at_pace.FramesFloorCannotExplain(), 2) << at_pace.BriefReport();
  // Hurried, the arms and the trunk need several times their torque and
  // the feet slip.
  EXPECT_GT(PeakRatio(fast), 2.0 * PeakRatio(at_pace))
      << at_pace.BriefReport() << fast.BriefReport();
  EXPECT_GE(fast.FramesFloorCannotExplain(), 6) << fast.BriefReport();
  EXPECT_GE(servo.FramesOverTorqueLimit(), 9) << servo.BriefReport();
  // The damping only adds: no hinge needs less under the servo limit.
  for (size_t h = 0; h < servo.hinges.size(); ++h) {
    EXPECT_GE(servo.hinges[h].frames_over_limit,
              at_pace.hinges[h].frames_over_limit);
  }
  EXPECT_LE(at_pace.AirborneFrames(), 2);  // a walk keeps a foot down
}

TEST(MotionFeasibility, BadInputIsNamed) {
  auto character = Humanoid();
  const auto zero = [](double) { return 0.0; };
  const std::vector<Pose3D> two = StandingMotion(*character, 2, zero, zero);
  EXPECT_THROW(
      MeasureMotionFeasibility(*character, two, kFps, FeasibilityOptions()),
      InputError);
  std::vector<Pose3D> with_nan = StandingMotion(*character, 5, zero, zero);
  with_nan[3].root_position_m.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    MeasureMotionFeasibility(*character, with_nan, kFps, FeasibilityOptions());
    ADD_FAILURE() << "a NaN pose was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("frame 3"), std::string::npos)
        << error.what();
  }
  FeasibilityOptions negative;
  negative.contact_height_m = -0.1;
  EXPECT_THROW(negative.Validate(), ConfigError);
  negative = FeasibilityOptions();
  negative.friction_coefficient = std::nan("");
  EXPECT_THROW(negative.Validate(), ConfigError);
}

}  // namespace
}  // namespace m2d
