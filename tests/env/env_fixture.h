// tests: a humanoid tracking a multi-view walk bundle (shared data).
#ifndef MIMIC2D_TESTS_ENV_ENV_FIXTURE_H_
#define MIMIC2D_TESTS_ENV_ENV_FIXTURE_H_

#include <algorithm>
#include <memory>
#include <string>

#include "env/policy.h"
#include "env/reference.h"
#include "env/task.h"
#include "env/tracking_env.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "sim/pose_mapping.h"
#include "sim/simulation.h"
#include "synthetic_motion.h"
#include "test_paths.h"

namespace m2d::testing {

struct WalkTask {
  std::shared_ptr<const Character> character;
  std::shared_ptr<const TrackingReference> reference;
  std::shared_ptr<InitialStates> initial_states;
  TrackingEnvOptions options;
};

inline std::shared_ptr<const Character> LoadHumanoid(
    const SimulationOptions& options) {
  return LoadCharacterForSimulation(
      SourcePath("assets/characters/humanoid.yaml"), "flat", options);
}

// The DeepMimic walk looped to `duration_s`, seen by 4 cameras that follow.
inline ReferenceBundle MakeWalkBundle(const std::string& motion_path,
                                      const Character& character,
                                      double duration_s = 4.0) {
  Motion3D motion =
      ReadDeepMimicMotion(motion_path, character.shared_skeleton());
  BundleFromMotionOptions options;
  options.duration_s = duration_s;
  options.follow = CameraFollow::kRootDolly;
  return MakeBundleFromMotion(motion, character.keypoint_map(), options,
                              "walk");
}

// Without the shared data: the humanoid's standing pose carried along +x
// (tests/synthetic_motion.h), seen by `num_views` static cameras.
inline ReferenceBundle MakeGlidingBundle(const Character& character,
                                         double duration_s = 2.0,
                                         int num_views = 2) {
  const Pose3D standing = QposToPose(character, character.model()->qpos0);
  BundleFromMotionOptions options;
  options.rig.num_views = num_views;
  return MakeBundleFromMotion(
      GlidingMotion(character.shared_skeleton(), standing, duration_s),
      character.keypoint_map(), options, "gliding");
}

// A tracking task (default sources and options) on MakeGlidingBundle's
// motion seen by `num_views` static cameras.
inline TrackingTask MakeGlidingTask(int num_views, double duration_s = 1.0) {
  TrackingTaskOptions options;
  auto character = LoadHumanoid(options.simulation);
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(MakeGlidingBundle(*character, duration_s, num_views));
  return BuildTrackingTask(character, std::move(bundles), options);
}

// A scripted controller without LibTorch: every PD target at the centre of
// its range, whatever it observes. It cannot walk.
class ZeroPolicy : public Policy {
 public:
  ZeroPolicy(int observation_size, int action_size)
      : observation_size_(observation_size), action_size_(action_size) {}
  void Act(const float*, int batch, float* actions) override {
    std::fill(actions, actions + batch * action_size_, 0.0f);
    ++calls;
  }
  int observation_size() const override { return observation_size_; }
  int action_size() const override { return action_size_; }
  int calls = 0;  // Act() calls so far

 private:
  int observation_size_, action_size_;
};

inline WalkTask MakeWalkTask(const std::string& motion_path,
                             double duration_s = 4.0) {
  WalkTask task;
  task.character = LoadHumanoid(task.options.simulation);
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(MakeWalkBundle(motion_path, *task.character, duration_s));
  TrackingTaskOptions task_options;
  task_options.simulation = task.options.simulation;
  TrackingTask built =
      BuildTrackingTask(task.character, std::move(bundles), task_options);
  task.reference = built.reference;
  task.initial_states = built.initial_states;
  return task;
}

// Gives `bundle` the ball of `character`'s scene resting where the scene
// puts it: its 2D in every view (where it projects) and its 3D in the
// truth. Returns that position (m).
inline Eigen::Vector3d AddRestingBall(const Character& character,
                                      ReferenceBundle* bundle) {
  const FreeObject& ball = character.free_objects().at(0);
  const double* qpos0 = character.model()->qpos0 + ball.qpos_address;
  const Eigen::Vector3d ball_m(qpos0[0], qpos0[1], qpos0[2]);
  for (ReferenceView& view : bundle->views) {
    ObjectTrack2D track{ball.name, {}};
    for (int t = 0; t < view.clip.num_frames(); ++t) {
      Projection p = view.CameraAt(t).Project(ball_m);
      track.points.push_back({p.pixel_px.x(), p.pixel_px.y(), 1.0});
    }
    view.clip.objects.push_back(track);
  }
  bundle->ground_truth->objects = {
      {ball.name, std::vector<Eigen::Vector3d>(bundle->num_frames(), ball_m)}};
  return ball_m;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_ENV_ENV_FIXTURE_H_
