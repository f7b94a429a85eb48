// The tracking task with an object: a ball tracked in 2D next to the walker.
#include <gtest/gtest.h>

#include "common/error.h"
#include "env/tracking_env.h"
#include "env_fixture.h"

namespace m2d {
namespace {

TEST(TrackingEnvWithObject, ObservesTheBallAndRewardsItsTracking) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  options.reward.object_weight = 0.5;
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      options.simulation);
  ASSERT_EQ(character->free_objects().size(), 1u);
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 2.0);

  // The ball's 2D track: where the scene's resting ball projects.
  Simulation probe(character, options.simulation);
  const int ball_body = character->free_objects()[0].body_id;
  const double* ball = probe.data()->xpos + 3 * ball_body;
  Eigen::Vector3d ball_m(ball[0], ball[1], ball[2]);
  for (ReferenceView& view : bundle.views) {
    ObjectTrack2D track{"ball", {}};
    for (int t = 0; t < view.clip.num_frames(); ++t) {
      Projection p = view.CameraAt(t).Project(ball_m);
      track.points.push_back({p.pixel_px.x(), p.pixel_px.y(), 1.0});
    }
    view.clip.objects.push_back(track);
  }
  auto reference = TrackingReference::Prepare({bundle}, *character,
                                              options.simulation.control_hz);
  EXPECT_EQ(reference->num_object_points(), 1);
  EXPECT_EQ(reference->num_points(), 18);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  TrackingEnv env(character, reference, states, options, 3);
  EXPECT_EQ(env.layout().num_objects, 1);
  EXPECT_EQ(env.observation_size(),
            env.layout().proprioception_size() + 6 +
                (1 + options.num_future_frames) * 18 * 3);
  std::vector<float> obs(env.observation_size()),
      action(env.action_size(), 0.0f);
  env.ResetTo(0, 0, states->buffer(0).entry(0, 0).state, obs.data());
  // Object state: the ball's position relative to the root, heading frame.
  const float* object = obs.data() + env.layout().proprioception_size();
  Eigen::Vector3d root(env.simulation().data()->qpos[0],
                       env.simulation().data()->qpos[1],
                       env.simulation().data()->qpos[2]);
  EXPECT_NEAR(Eigen::Vector3d(object[0], object[1], object[2]).norm(),
              (ball_m - root).norm(), 1e-3);
  StepOutcome outcome = env.Step(action.data(), obs.data());
  // The ball has not moved, so its 2D term is nearly perfect.
  EXPECT_GT(outcome.terms.object, 0.9);
  EXPECT_NEAR(outcome.terms.total,
              outcome.terms.pose + 0.5 * outcome.terms.object +
                  options.reward.energy_weight * outcome.terms.energy,
              1e-9);
}

TEST(TrackingEnvWithObject, AnUnknownObjectNameIsRejected) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  auto character = testing::LoadHumanoid(options.simulation);  // flat: no ball
  ReferenceBundle bundle = testing::MakeWalkBundle(path, *character, 1.0);
  for (ReferenceView& view : bundle.views) {
    view.clip.objects.push_back(
        {"ball", std::vector<Keypoint2D>(view.clip.num_frames(), {1, 1, 1})});
  }
  EXPECT_THROW(TrackingReference::Prepare({bundle}, *character, 30.0),
               InputError);
}

}  // namespace
}  // namespace m2d
