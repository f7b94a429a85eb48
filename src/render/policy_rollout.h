// render: recording a policy's rollout in the tracking environment as
// episode frames to draw.
#ifndef MIMIC2D_RENDER_POLICY_ROLLOUT_H_
#define MIMIC2D_RENDER_POLICY_ROLLOUT_H_

#include <vector>

#include "env/policy.h"
#include "env/tracking_env.h"
#include "render/episode_renderer.h"

namespace m2d {

// Starts `env` on view `view_index` at `start_frame` from that frame's
// best-scoring initial state, runs the policy until the episode ends, and
// returns one frame per state (the start included) with its camera and 2D
// reference.
std::vector<EpisodeFrame> RecordPolicyRollout(
    Policy& policy, TrackingEnv& env, const TrackingReference& reference,
    const InitialStates& initial_states, int view_index, int start_frame);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_POLICY_ROLLOUT_H_
