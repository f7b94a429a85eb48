#include "render/policy_rollout.h"

#include <gtest/gtest.h>

#include "env/env_fixture.h"

namespace m2d {
namespace {

using testing::ZeroPolicy;

TEST(PolicyRollout, RecordsOneFramePerStateWithItsCameraAndReference) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 2.0);
  task.options.max_episode_s = 1.0;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 1);
  ZeroPolicy policy(env.observation_size(), env.action_size());
  std::vector<EpisodeFrame> frames = RecordPolicyRollout(
      policy, env, *task.reference, *task.initial_states, 2, 10);
  ASSERT_GE(frames.size(), 2u);
  EXPECT_EQ(static_cast<int>(frames.size()), policy.calls + 1);
  const ReferenceBundle& bundle = task.reference->bundles()[0];
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].clip_frame, 10 + static_cast<int>(i));
    ASSERT_TRUE(frames[i].state.has_value());
    EXPECT_EQ(frames[i].reference.size(), 17u);
    EXPECT_EQ(frames[i].reference[0].x_px,
              bundle.views[2].clip.keypoints.at(10 + i, 0).x_px);
    EXPECT_TRUE(frames[i].camera.CenterWorld().isApprox(
        bundle.views[2].CameraAt(10 + static_cast<int>(i)).CenterWorld()));
  }
  // The zero-target policy cannot walk: it either falls behind (early exit)
  // or lasts the 1 s episode.
  EXPECT_LE(frames.size(), 31u);
}

}  // namespace
}  // namespace m2d
