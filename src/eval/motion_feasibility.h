// eval: whether a 3D reference motion is physically possible for a
// character — the joint torques and the external force that following it
// exactly would take (MuJoCo's inverse dynamics), against the actuators'
// torque limits and what a floor can push; and whether its poses are within
// the joint ranges (or reach their keypoints from within them) and keep the
// character's own geoms apart. It separates "the tracker has not
// learned this" from "no controller of this character can do this", and
// measures how infeasible a fit's 3D is beside the truth (the paper's point
// against the two-stage baseline). `mimic2d clip feasibility` prints it.
#ifndef MIMIC2D_EVAL_MOTION_FEASIBILITY_H_
#define MIMIC2D_EVAL_MOTION_FEASIBILITY_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "motion/motion3d.h"
#include "sim/character.h"
#include "sim/simulation.h"

namespace m2d {

struct FeasibilityOptions {
  // A body whose lowest collision point is below this height may be
  // touching the floor (m): recorded motion hovers and sinks by a few cm.
  double contact_height_m = 0.05;
  // Coulomb friction of the feet on the floor (MuJoCo's default 1).
  double friction_coefficient = 1.0;
  // Force errors smaller than this share of the body weight are finite-
  // difference noise, not a violation (a pull, a slip, a force in flight).
  double force_tolerance_body_weights = 0.1;
  // What the torque limits bound (SimulationOptions::torque_limit): under
  // kServo the actuator must also overcome the joint's damping.
  TorqueLimit torque_limit = TorqueLimit::kServo;
  // A hinge angle this far past its MJCF range counts as out of range (rad):
  // recorded motion rests on the ends of the ranges it was fitted within.
  double range_tolerance_rad = 0.035;  // 2 degrees
  // A frame is out of the character's reach when the nearest pose within
  // every joint range (a 3D keypoint fit, fit/retarget.h) leaves a body
  // keypoint further than this from the pose's own (m). A hinge past its
  // range need not be: near a ball joint's gimbal lock (a leg raised 90
  // degrees) another combination of its three angles turns it the same way.
  double reach_tolerance_m = 0.05;
  // Two of the character's own collision geoms overlapping by more than
  // this count as interpenetrating (m): MuJoCo's contacts push them apart
  // as soon as the pose is simulated.
  double penetration_tolerance_m = 0.01;

  // ConfigError naming the field.
  void Validate() const;
};

// One actuated hinge over a clip.
struct HingeDemand {
  std::string actuator;   // the MJCF actuator's name
  double limit_nm = 0.0;  // its limit toward positive torque (forcerange[1])
  // Frames whose demand does not depend on how the floor pushes: no body
  // below the hinge may be touching it (arms, trunk, a leg in swing).
  int frames_measured = 0;
  int frames_over_limit = 0;  // of those, demand above the limit
  double peak_nm = 0.0;       // largest |torque| over the measured frames
  // Largest |torque| / the limit in its direction, and its frame.
  double peak_ratio = 0.0;
  int peak_frame = -1;
  // The joint's angle against its range, in every frame (the floor does not
  // widen a range): the solution of each frame's rotation nearest the
  // ranges (PoseToQpos), so a frame out of range has no in-range solution.
  int frames_out_of_range = 0;  // past the range by > range_tolerance_rad
  double peak_range_excess_rad = 0.0;  // furthest past the range
  int peak_range_frame = -1;
};

// One frame: the worst hinge and the external force.
struct FrameDemand {
  double worst_torque_ratio = 0.0;  // max over measured hinges |tau| / limit
  int worst_hinge = -1;             // index into MotionFeasibility::hinges
  double worst_range_excess_rad = 0.0;  // max over hinges, angle past range
  int worst_range_hinge = -1;           // index into hinges; -1 if in range
  // How far the nearest pose within the ranges leaves the body keypoint it
  // moves most (m): 0 when the pose itself is within them.
  double reach_error_m = 0.0;
  // The deepest overlap of two of the character's own geoms (m, >= 0) and
  // their names ("a/b"); empty when none overlap.
  double self_penetration_m = 0.0;
  std::string self_contact;
  bool touching = false;  // some body within contact_height_m
  // The total external force that moving exactly so takes (N, world):
  // m (a_com - g). Only the floor can give it.
  Eigen::Vector3d external_force_n = Eigen::Vector3d::Zero();
  bool force_in_flight = false;  // needed while nothing touches the floor
  bool pulls_floor = false;      // touching, but the floor would have to pull
  bool slips = false;            // touching, outside the friction cone
};

struct MotionFeasibility {
  int num_frames = 0;
  double fps = 0.0;
  double body_weight_n = 0.0;  // total mass x g
  std::vector<HingeDemand> hinges;
  std::vector<FrameDemand> frames;

  // Frames in which some measured hinge needs more than its limit.
  int FramesOverTorqueLimit() const;
  // Frames in which some hinge is past its range by more than the tolerance
  // (FeasibilityOptions::range_tolerance_rad, kept here).
  int FramesOutOfRange() const;
  double range_tolerance_rad = 0.0;
  // Frames whose reach_error_m is above reach_tolerance_m (kept here), and
  // the largest reach_error_m.
  int FramesOutOfReach() const;
  double WorstReachErrorM() const;
  double reach_tolerance_m = 0.0;
  // Frames whose self_penetration_m is above penetration_tolerance_m (kept
  // here), and the deepest overlap with its frame.
  int FramesSelfPenetrating() const;
  double penetration_tolerance_m = 0.0;
  const FrameDemand* DeepestSelfPenetration() const;
  // Frames the floor cannot explain: a force in flight, a pull or a slip.
  int FramesFloorCannotExplain() const;
  int AirborneFrames() const;
  // Mean |external force| over the frames nothing touches, in body weights
  // (0 in a true ballistic flight); 0 without such frames.
  double MeanForceInFlightBodyWeights() const;
  // The measured hinge with the largest peak_ratio; null if none was.
  const HingeDemand* WorstHinge() const;
  // The hinge furthest past its range; null if every angle is in range.
  const HingeDemand* WorstRangeHinge() const;
  // A few lines: torque limits, the floor, the worst hinges.
  std::string BriefReport() const;
};

// Inverse dynamics of `poses` (the character's skeleton, at `fps`) on the
// character's model, contacts and joint limits off (the angles are checked
// against the joint ranges on their own): accelerations and
// velocities by central differences of the poses (each joint's Euler
// solution kept continuous, PosesToQposAlongClip), then per frame the
// generalized forces that produce them. Needs at least 3 frames; InputError
// otherwise or on a non-finite pose.
MotionFeasibility MeasureMotionFeasibility(const Character& character,
                                           const std::vector<Pose3D>& poses,
                                           double fps,
                                           const FeasibilityOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_MOTION_FEASIBILITY_H_
