// sim: free objects (a ball) moved by a motion replayed kinematically. The
// character follows the motion exactly, as if infinitely strong; the objects
// answer through MuJoCo's contacts. How a motion captured without a ball
// gets a ball's 3D truth that agrees with it (a kick, a dribble's touch).
#ifndef MIMIC2D_SIM_OBJECT_REPLAY_H_
#define MIMIC2D_SIM_OBJECT_REPLAY_H_

#include <Eigen/Core>
#include <vector>

#include "motion/bundle.h"
#include "motion/motion3d.h"
#include "sim/character.h"

namespace m2d {

// Where a ball is put in the way of a kick.
struct BallPlacement {
  int frame = -1;      // the motion frame the foot is fastest near the floor
  int foot_body = -1;  // model body id of that foot (a ground-contact body)
  double foot_speed_m_s = 0.0;        // its horizontal speed then
  Eigen::Vector3d center_m{0, 0, 0};  // the ball's centre, resting on the floor
};

// A ball of `radius_m` put where a foot kicks: over the frames of `motion`,
// the ground-contact body (foot, paw) whose origin is within
// `max_foot_height_m` of the floor and moves fastest horizontally; the ball
// rests on the floor `lead_m` ahead of that foot along its motion, so that
// the foot runs into it. InputError when no foot comes that low.
BallPlacement PlaceBallInFootPath(const Character& character,
                                  const Motion3D& motion, double radius_m,
                                  double max_foot_height_m = 0.3,
                                  double lead_m = 0.15);

// Replays `motion` with every free object of the character's scene starting
// at rest at `starts_m` (one per Character::free_objects(), same order):
// at each physics step the character is put in the motion's pose at that
// time (poses interpolated between frames) moving at the motion's rates,
// and the world steps; the objects' centres are read at every frame of the
// motion. Returns one track per object, named after its body. The
// character's own state after each step is discarded, so contacts push the
// objects and never the character. InputError when the motion's frame
// period is not a whole number of physics steps.
std::vector<ObjectTrack3D> ReplayObjectsAlongMotion(
    const Character& character, const Motion3D& motion,
    const std::vector<Eigen::Vector3d>& starts_m);

}  // namespace m2d

#endif  // MIMIC2D_SIM_OBJECT_REPLAY_H_
