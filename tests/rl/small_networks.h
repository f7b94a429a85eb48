// An observation layout and networks small enough for tests that only need
// the model's structure (its tensors, their names, how they are saved).
#ifndef MIMIC2D_TESTS_RL_SMALL_NETWORKS_H_
#define MIMIC2D_TESTS_RL_SMALL_NETWORKS_H_

#include "env/observation.h"
#include "rl/train_config.h"

namespace m2d::testing {

// Two bodies, three keypoints, two future frames.
inline ObservationLayout SmallLayout() {
  ObservationLayout layout;
  layout.num_bodies = 2;
  layout.num_points = 3;
  layout.num_future_frames = 2;
  return layout;
}

inline ModelOptions SmallModel() {
  ModelOptions options;
  options.encoder_hidden = {16};
  options.encoder_features = 8;
  options.policy_hidden = {32};
  options.critic_hidden = {32};
  return options;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_RL_SMALL_NETWORKS_H_
