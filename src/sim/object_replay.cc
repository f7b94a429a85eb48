#include "sim/object_replay.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <string>

#include "common/error.h"
#include "sim/mujoco_handles.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

// World positions of every ground-contact body's origin at each frame of
// `motion` (forward kinematics only).
std::vector<std::vector<Eigen::Vector3d>> FootPositions(
    const Character& character, const Motion3D& motion) {
  const mjModel* model = character.model();
  MujocoDataPtr data = MakeMujocoData(model);
  std::vector<std::vector<Eigen::Vector3d>> feet;
  for (const Pose3D& pose : motion.frames) {
    PoseToQpos(character, pose, data->qpos);
    mj_kinematics(model, data.get());
    std::vector<Eigen::Vector3d> frame;
    for (int body : character.ground_contact_bodies()) {
      frame.emplace_back(data->xpos[3 * body], data->xpos[3 * body + 1],
                         data->xpos[3 * body + 2]);
    }
    feet.push_back(std::move(frame));
  }
  return feet;
}

}  // namespace

BallPlacement PlaceBallInFootPath(const Character& character,
                                  const Motion3D& motion, double radius_m,
                                  double max_foot_height_m, double lead_m) {
  // Outline: foot origins per frame by forward kinematics; their horizontal
  // speed by central differences; the fastest foot-frame pair near the
  // floor; the ball `lead_m` ahead of it, resting on the floor.
  const std::vector<std::vector<Eigen::Vector3d>> feet =
      FootPositions(character, motion);
  const int num_frames = motion.num_frames();
  BallPlacement best;
  for (int t = 1; t + 1 < num_frames; ++t) {
    for (size_t f = 0; f < feet[t].size(); ++f) {
      if (feet[t][f].z() > max_foot_height_m) continue;
      Eigen::Vector2d velocity =
          (feet[t + 1][f] - feet[t - 1][f]).head<2>() * (0.5 * motion.fps);
      if (velocity.norm() <= best.foot_speed_m_s) continue;
      best.frame = t;
      best.foot_body = character.ground_contact_bodies()[f];
      best.foot_speed_m_s = velocity.norm();
      const Eigen::Vector2d ahead =
          feet[t][f].head<2>() + lead_m * velocity.normalized();
      best.center_m = {ahead.x(), ahead.y(), radius_m};
    }
  }
  if (best.frame < 0) {
    throw InputError(character.model_path(),
                     "no foot of the motion moves within " +
                         std::to_string(max_foot_height_m) +
                         " m of the floor: nowhere to put a ball to kick");
  }
  return best;
}

std::vector<ObjectTrack3D> ReplayObjectsAlongMotion(
    const Character& character, const Motion3D& motion,
    const std::vector<Eigen::Vector3d>& starts_m) {
  // Outline: per frame interval, per physics step: the character at the
  // interpolated pose with the interval's rates, the objects as the last
  // step left them; one step; the objects' centres read at every frame.
  const mjModel* model = character.model();
  const std::vector<FreeObject>& objects = character.free_objects();
  if (starts_m.size() != objects.size()) {
    throw InputError(character.model_path(),
                     std::to_string(starts_m.size()) + " object starts for " +
                         std::to_string(objects.size()) + " free objects");
  }
  const double frame_s = 1.0 / motion.fps;
  const int steps_per_frame =
      static_cast<int>(std::lround(frame_s / model->opt.timestep));
  if (steps_per_frame < 1 ||
      std::abs(steps_per_frame * model->opt.timestep - frame_s) > 1e-9) {
    throw InputError(character.model_path(),
                     "a frame of " + std::to_string(motion.fps) +
                         " fps is not a whole number of physics steps of " +
                         std::to_string(model->opt.timestep) + " s");
  }

  MujocoDataPtr data = MakeMujocoData(model);
  mju_zero(data->qvel, model->nv);
  for (size_t o = 0; o < objects.size(); ++o) {
    double* qpos = data->qpos + objects[o].qpos_address;
    mju_copy3(qpos, starts_m[o].data());
    qpos[3] = 1.0;
    qpos[4] = qpos[5] = qpos[6] = 0.0;
  }
  std::vector<ObjectTrack3D> tracks(objects.size());
  for (size_t o = 0; o < objects.size(); ++o) tracks[o].name = objects[o].name;
  auto read_objects = [&] {
    mj_kinematics(model, data.get());
    for (size_t o = 0; o < objects.size(); ++o) {
      const double* x = data->xpos + 3 * objects[o].body_id;
      tracks[o].positions_m.emplace_back(x[0], x[1], x[2]);
    }
  };

  const double step_s = model->opt.timestep;
  PoseToQpos(character, motion.frames.front(), data->qpos);
  read_objects();
  for (int t = 0; t + 1 < motion.num_frames(); ++t) {
    for (int s = 0; s < steps_per_frame; ++s) {
      const Pose3D from =
          InterpolatePose(motion.frames[t], motion.frames[t + 1],
                          static_cast<double>(s) / steps_per_frame);
      const Pose3D to =
          InterpolatePose(motion.frames[t], motion.frames[t + 1],
                          static_cast<double>(s + 1) / steps_per_frame);
      PoseToQpos(character, from, data->qpos);
      QvelFromPoses(character, from, to, step_s, data->qvel, &from);
      mj_step(model, data.get());
    }
    read_objects();
  }
  return tracks;
}

}  // namespace m2d
