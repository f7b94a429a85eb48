#include "env/reference_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "common/error.h"
#include "env_fixture.h"

namespace m2d {
namespace {

// A deterministic controller whose actions depend on every observation
// number (fixed random weights through tanh): two rollouts act alike only
// if they observe alike.
class ObservingPolicy : public Policy {
 public:
  ObservingPolicy(int observation_size, int action_size)
      : observation_size_(observation_size),
        action_size_(action_size),
        weights_(static_cast<size_t>(observation_size) * action_size) {
    std::mt19937_64 rng(5);
    std::normal_distribution<float> normal(0.0f, 0.05f);
    for (float& w : weights_) w = normal(rng);
  }
  void Act(const float* observations, int batch, float* actions) override {
    for (int b = 0; b < batch; ++b) {
      for (int a = 0; a < action_size_; ++a) {
        float sum = 0.0f;
        for (int k = 0; k < observation_size_; ++k) {
          sum += weights_[static_cast<size_t>(a) * observation_size_ + k] *
                 observations[b * observation_size_ + k];
        }
        actions[b * action_size_ + a] = 0.3f * std::tanh(sum);
      }
    }
  }
  int observation_size() const override { return observation_size_; }
  int action_size() const override { return action_size_; }

 private:
  int observation_size_, action_size_;
  std::vector<float> weights_;
};

// Rolls view 1 of the following walk (`duration_s` long) out twice from
// its truth start with ObservingPolicy: prepared whole, and streamed frame by
// frame with its true cameras asked for frame by frame. Expects the same
// states step for step (to rounding: restoring a saved state recomputes
// MuJoCo's derived quantities), the same errors and the same end; returns
// whether the rollout failed (early exit) rather than ran out of frames.
bool ExpectStreamedRolloutMatchesWhole(const std::string& motion_path,
                                       double duration_s) {
  testing::WalkTask task = testing::MakeWalkTask(motion_path, duration_s);
  const ReferenceView& view = task.reference->bundles()[0].views[1];
  std::mt19937_64 rng(3);
  const SimState start = task.initial_states->BufferOfView(1).Draw(0, rng);

  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 0);
  ObservingPolicy policy(env.observation_size(), env.action_size());
  std::vector<float> observation(env.observation_size()),
      action(env.action_size());
  env.ResetTo(1, 0, start, observation.data());

  ClipStream stream(view.clip);
  int camera_calls = 0;
  StreamedRollout rollout(
      task.character, task.options, &stream,
      [&](int frame, const SimState&, double) {
        ++camera_calls;
        return view.CameraAt(frame);
      },
      start);

  const int nq = task.character->model()->nq;
  int steps = 0;
  double worst_qpos = 0.0;
  while (true) {
    policy.Act(observation.data(), 1, action.data());
    const StepOutcome outcome = env.Step(action.data(), observation.data());
    const bool whole_going = !outcome.terminated && !outcome.truncated;
    const bool streamed_going = rollout.Step(policy);
    ++steps;
    for (int i = 0; i < nq; ++i) {
      worst_qpos =
          std::max(worst_qpos, std::abs(env.simulation().data()->qpos[i] -
                                        rollout.simulation().data()->qpos[i]));
    }
    EXPECT_EQ(whole_going, streamed_going) << "step " << steps;
    if (!whole_going || !streamed_going) break;
  }
  EXPECT_LT(worst_qpos, 1e-9);
  EXPECT_EQ(rollout.stats().steps, steps);
  EXPECT_EQ(rollout.stats().failed, env.episode().failed);
  EXPECT_NEAR(rollout.stats().mean_error_px(), env.episode().mean_error_px(),
              1e-6);
  EXPECT_NEAR(rollout.stats().max_error_px, env.episode().max_error_px, 1e-6);
  // The window's cameras asked for at every restart: L + 1 frames or fewer.
  EXPECT_LE(camera_calls, (task.options.num_future_frames + 1) * (steps + 1));
  EXPECT_GE(camera_calls, steps + 1);
  return env.episode().failed;
}

// Streamed frame by frame, a recorded view rolls out as the same view
// prepared whole: to its last frame (a 0.3-s clip) and to an early exit (a
// 2-s clip, which the untrained controller does not keep up with).
TEST(StreamedRollout, AStreamedClipRollsOutAsTheClipPreparedWhole) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  EXPECT_FALSE(ExpectStreamedRolloutMatchesWhole(path, 0.3));
  EXPECT_TRUE(ExpectStreamedRolloutMatchesWhole(path, 2.0));
}

// A stream too short to track, or with frames of the wrong size, is a
// named error.
TEST(StreamedRollout, ShortOrMisshapenStreamsAreNamedErrors) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 1.0);
  const ReferenceView& view = task.reference->bundles()[0].views[0];
  std::mt19937_64 rng(3);
  const SimState start = task.initial_states->BufferOfView(0).Draw(0, rng);
  auto camera = [&](int frame, const SimState&, double) {
    return view.CameraAt(frame);
  };
  Clip2D one_frame = view.clip;
  one_frame.keypoints = KeypointTrack(1, 17);
  ClipStream short_stream(one_frame);
  try {
    StreamedRollout rollout(task.character, task.options, &short_stream, camera,
                            start);
    FAIL() << "a one-frame stream was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 2 frames"),
              std::string::npos)
        << e.what();
  }

  class MisshapenStream : public ReferenceStream {
   public:
    explicit MisshapenStream(const Clip2D& clip) : format_(clip) {}
    const Clip2D& format() const override { return format_; }
    bool Next(std::vector<Keypoint2D>* keypoints) override {
      keypoints->assign(12, Keypoint2D{100, 100, 1});
      return true;
    }

   private:
    Clip2D format_;
  } misshapen(view.clip);
  try {
    StreamedRollout rollout(task.character, task.options, &misshapen, camera,
                            start);
    FAIL() << "12 keypoints were accepted for a 17-keypoint layout";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has 12 keypoints"), std::string::npos)
        << e.what();
  }
}

// A camera that dollies with the simulated character is asked, for the
// frame a step lands on, one control period ahead, from the state the step
// starts at: it sees the character where it is, not where it was L frames
// ago (20 cm back at walking speed, before 2026-11-26).
TEST(StreamedRollout, AFollowingCameraIsAskedWhereTheCharacterWillBe) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  testing::WalkTask task = testing::MakeWalkTask(path, 1.0);
  const ReferenceView& view = task.reference->bundles()[0].views[0];
  std::mt19937_64 rng(3);
  const SimState start = task.initial_states->BufferOfView(0).Draw(0, rng);
  const int root = task.character->root_qpos_address();
  const int root_dof = task.character->root_dof_address();
  const double dt_s = 1.0 / task.options.simulation.control_hz;
  // frame -> the root (x, y) predicted for it at lead dt.
  std::map<int, Eigen::Vector2d> predicted;
  auto camera = [&](int frame, const SimState& state, double lead_s) {
    const Eigen::Vector2d root_m(
        state.qpos[root] + state.qvel[root_dof] * lead_s,
        state.qpos[root + 1] + state.qvel[root_dof + 1] * lead_s);
    if (std::abs(lead_s - dt_s) < 1e-12) predicted[frame] = root_m;
    return view.CameraAt(0).Translated(
        {root_m.x() - start.qpos[root], root_m.y() - start.qpos[root + 1], 0});
  };
  ClipStream stream(view.clip);
  StreamedRollout rollout(task.character, task.options, &stream, camera, start);
  TrackingEnv sizes(task.character, task.reference, task.initial_states,
                    task.options, 0);
  testing::ZeroPolicy controller(sizes.observation_size(), sizes.action_size());
  const Eigen::Vector3d offset_m =
      view.CameraAt(0).CenterWorld() -
      Eigen::Vector3d(start.qpos[root], start.qpos[root + 1], 0);
  int steps = 0;
  double worst_lag_m = 0.0, travel_m = 0.0;
  Eigen::Vector2d first_root(start.qpos[root], start.qpos[root + 1]);
  while (rollout.Step(controller) && steps < 20) {
    ++steps;
    const double* qpos = rollout.simulation().data()->qpos;
    const Eigen::Vector2d root_m(qpos[root], qpos[root + 1]);
    // The current frame's camera sits at the character's root.
    const Eigen::Vector3d center = rollout.camera().CenterWorld();
    EXPECT_NEAR(center.x() - offset_m.x(), root_m.x(), 1e-9);
    EXPECT_NEAR(center.y() - offset_m.y(), root_m.y(), 1e-9);
    // The camera the step projected with was asked one period ahead.
    ASSERT_EQ(predicted.count(rollout.frame()), 1u) << rollout.frame();
    worst_lag_m =
        std::max(worst_lag_m, (predicted[rollout.frame()] - root_m).norm());
    travel_m = (root_m - first_root).norm();
  }
  ASSERT_GE(steps, 10);
  EXPECT_GT(travel_m, 0.1);      // the walk's start carries it forward
  EXPECT_LT(worst_lag_m, 0.02);  // one step's prediction, not L frames back
}

}  // namespace
}  // namespace m2d
