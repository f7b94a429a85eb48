#include "render/policy_rollout.h"

namespace m2d {
namespace {

EpisodeFrame CurrentFrame(const TrackingEnv& env,
                          const TrackingReference& reference) {
  const TrackedView& view = env.view();
  const int num_keypoints =
      env.simulation().character().keypoint_layout().num_keypoints();
  EpisodeFrame frame;
  frame.clip_frame = env.frame();
  frame.camera = env.camera();  // recorded, or following the character
  const Keypoint2D* points = view.frame(env.frame());
  frame.reference.assign(points, points + num_keypoints);
  // The objects' reference in the scene's free-object order (missing where
  // an object is not tracked).
  const std::vector<int>& tracked = reference.object_bodies();
  for (const FreeObject& object : env.simulation().character().free_objects()) {
    Keypoint2D point;
    for (size_t o = 0; o < tracked.size(); ++o) {
      if (tracked[o] == object.body_id) point = points[num_keypoints + o];
    }
    if (!tracked.empty()) frame.reference_objects.push_back(point);
  }
  frame.state = env.simulation().Save();
  return frame;
}

}  // namespace

std::vector<EpisodeFrame> RecordPolicyRollout(
    Policy& policy, TrackingEnv& env, const TrackingReference& reference,
    const InitialStates& initial_states, int view_index, int start_frame) {
  const StateBuffer& buffer = initial_states.BufferOfView(view_index);
  const int best = buffer.Best(start_frame);
  std::vector<float> observation(env.observation_size()),
      action(env.action_size());
  env.ResetTo(view_index, start_frame, buffer.entry(start_frame, best).state,
              observation.data());
  std::vector<EpisodeFrame> frames = {CurrentFrame(env, reference)};
  for (;;) {
    policy.Act(observation.data(), 1, action.data());
    StepOutcome outcome = env.Step(action.data(), observation.data());
    if (outcome.diverged) break;
    frames.push_back(CurrentFrame(env, reference));
    if (outcome.terminated || outcome.truncated) break;
  }
  return frames;
}

}  // namespace m2d
