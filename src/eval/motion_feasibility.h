// eval: whether a 3D reference motion is physically possible for a
// character — the joint torques and the external force that following it
// exactly would take (MuJoCo's inverse dynamics), against the actuators'
// torque limits and what a floor can push. It separates "the tracker has not
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
};

// One frame: the worst hinge and the external force.
struct FrameDemand {
  double worst_torque_ratio = 0.0;  // max over measured hinges |tau| / limit
  int worst_hinge = -1;             // index into MotionFeasibility::hinges
  bool touching = false;            // some body within contact_height_m
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
  // Frames the floor cannot explain: a force in flight, a pull or a slip.
  int FramesFloorCannotExplain() const;
  int AirborneFrames() const;
  // Mean |external force| over the frames nothing touches, in body weights
  // (0 in a true ballistic flight); 0 without such frames.
  double MeanForceInFlightBodyWeights() const;
  // The measured hinge with the largest peak_ratio; null if none was.
  const HingeDemand* WorstHinge() const;
  // A few lines: torque limits, the floor, the worst hinges.
  std::string BriefReport() const;
};

// Inverse dynamics of `poses` (the character's skeleton, at `fps`) on the
// character's model, contacts and joint limits off: accelerations and
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
