#include "env/observation.h"

#include <gtest/gtest.h>

#include <random>

#include "env/vec_env.h"
#include "env_fixture.h"

namespace m2d {
namespace {

BodyKinematics RandomBodies(int count, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  BodyKinematics bodies;
  for (int b = 0; b < count; ++b) {
    bodies.positions_m.push_back(
        Eigen::Vector3d(normal(rng), normal(rng), 1.0 + 0.2 * normal(rng)));
    bodies.orientations.push_back(Eigen::Quaterniond::UnitRandom());
    bodies.linear_velocities_m_s.push_back(
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    bodies.angular_velocities_rad_s.push_back(
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
  }
  return bodies;
}

TEST(Observation, ProprioceptionIsInvariantToHeadingAndGroundPosition) {
  std::mt19937 rng(3);
  BodyKinematics bodies = RandomBodies(15, rng);
  ObservationLayout layout;
  layout.num_bodies = 15;
  std::vector<float> a(layout.proprioception_size()), b(a.size());
  WriteProprioception(bodies, a.data());
  // Turn the whole scene about +z and slide it along the ground.
  Eigen::Quaterniond turn(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()));
  Eigen::Vector3d slide(3.0, -2.0, 0.0);
  BodyKinematics moved = bodies;
  for (int i = 0; i < 15; ++i) {
    moved.positions_m[i] = turn * bodies.positions_m[i] + slide;
    moved.orientations[i] = turn * bodies.orientations[i];
    moved.linear_velocities_m_s[i] = turn * bodies.linear_velocities_m_s[i];
    moved.angular_velocities_rad_s[i] =
        turn * bodies.angular_velocities_rad_s[i];
  }
  WriteProprioception(moved, b.data());
  for (size_t i = 0; i < a.size(); ++i)
    EXPECT_NEAR(a[i], b[i], 1e-5) << "feature " << i;
  EXPECT_FLOAT_EQ(a[0], static_cast<float>(bodies.positions_m[0].z()));
}

TEST(Observation, NormalizedPointsAreInvariantToImageShiftAndZoom) {
  std::vector<Keypoint2D> points = {
      {500, 300, 1}, {520, 400, 0.7}, {0, 0, 0}, {NAN, 5, 1}};
  ImageNormalization normalization{{510, 350}, 40};
  std::vector<float> a(12), b(12);
  WriteNormalizedPoints(points.data(), 4, normalization, a.data());
  // The same picture zoomed 2x about the origin and shifted by (100, -50).
  std::vector<Keypoint2D> zoomed = points;
  for (Keypoint2D& p : zoomed) {
    p.x_px = 2 * p.x_px + 100;
    p.y_px = 2 * p.y_px - 50;
  }
  ImageNormalization zoomed_normalization{{2 * 510 + 100, 2 * 350 - 50}, 80};
  WriteNormalizedPoints(zoomed.data(), 4, zoomed_normalization, b.data());
  for (int i = 0; i < 12; ++i) EXPECT_FLOAT_EQ(a[i], b[i]) << i;
  EXPECT_FLOAT_EQ(a[0], -0.25f);
  EXPECT_FLOAT_EQ(a[2], 1.0f);
  EXPECT_FLOAT_EQ(a[8], 0.0f);   // missing: all zero
  EXPECT_FLOAT_EQ(a[11], 0.0f);  // NaN coordinate: missing
}

// The critic-only block: the reference's keypoints and the camera about the
// root, in its heading frame; unchanged when the whole scene, camera
// included, turns about +z and slides along the ground.
TEST(Observation, CriticOnlyInputsAreRootAndHeadingRelative) {
  std::mt19937 rng(5);
  BodyKinematics bodies = RandomBodies(3, rng);
  // Root at (1, 2, 0.9) facing +y (heading 90 degrees), pitched a little.
  bodies.positions_m[0] = {1.0, 2.0, 0.9};
  bodies.orientations[0] =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()));
  const std::vector<Eigen::Vector3d> now = {{1.0, 3.0, 0.9}, {0.0, 2.0, 0.1}};
  const std::vector<Eigen::Vector3d> next = {{1.0, 2.0, 1.4}, {1.0, 2.0, 25.0}};
  const Eigen::Vector3d camera_center(1.0, 6.0, 1.4);  // 4 m ahead, 0.5 up
  // Image x along world -x, image y along world -z: the camera faces -y,
  // back at the character.
  Eigen::Matrix3d camera_to_world;
  camera_to_world << -1, 0, 0, 0, 0, -1, 0, -1, 0;
  constexpr int kSize = 2 * 2 * 3 + 9;
  ASSERT_EQ(CriticOnlySize(2), kSize);
  std::vector<float> a(kSize + 1, -7.0f);
  WriteCriticOnlyInputs(bodies, now.data(), next.data(), 2, camera_center,
                        camera_to_world, a.data());
  const std::vector<float> expected = {
      1, 0, 0,   0, 1, -0.8,  // now: 1 m ahead; 1 m to the left, low
      0, 0, 0.5, 0, 0, 10,    // next: above the root; clipped to 10 m
      4, 0, 0.5,              // camera centre: 4 m ahead, 0.5 m up
      0, 1, 0,   0, 0, -1};   // image x: the root's left; image y: down
  for (int i = 0; i < kSize; ++i) EXPECT_NEAR(a[i], expected[i], 1e-6) << i;
  EXPECT_EQ(a[kSize], -7.0f);  // nothing written past the block

  Eigen::Quaterniond turn(Eigen::AngleAxisd(-2.3, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d slide(-4.0, 1.5, 0.0);
  auto move = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return turn * p + slide;
  };
  BodyKinematics moved = bodies;
  moved.positions_m[0] = move(bodies.positions_m[0]);
  moved.orientations[0] = turn * bodies.orientations[0];
  std::vector<Eigen::Vector3d> moved_now, moved_next;
  for (const Eigen::Vector3d& p : now) moved_now.push_back(move(p));
  for (const Eigen::Vector3d& p : next) moved_next.push_back(move(p));
  std::vector<float> b(kSize);
  WriteCriticOnlyInputs(moved, moved_now.data(), moved_next.data(), 2,
                        move(camera_center),
                        turn.toRotationMatrix() * camera_to_world, b.data());
  for (int i = 0; i < kSize; ++i) EXPECT_NEAR(a[i], b[i], 1e-5) << i;
}

// Two cameras that see the same image: the second camera and the whole
// motion are moved by the same offset. The environment's observations must
// be identical, because nothing camera-specific is observed.
TEST(Observation, CamerasProducingIdenticalImagesGiveIdenticalObservations) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  TrackingEnvOptions options;
  auto character = testing::LoadHumanoid(options.simulation);
  ReferenceBundle original = testing::MakeWalkBundle(path, *character, 2.0);
  ReferenceBundle moved = original;
  const Eigen::Vector3d offset(5.0, -3.0, 0.0);
  for (ReferenceView& view : moved.views) {
    for (PinholeCamera& camera : view.cameras)
      camera = camera.Translated(offset);
  }
  for (Pose3D& pose : moved.ground_truth->poses) pose.root_position_m += offset;
  for (auto& frame : moved.ground_truth->keypoints_m) {
    for (Eigen::Vector3d& p : frame) p += offset;
  }
  std::vector<ReferenceBundle> bundles = {original, moved};
  auto reference = TrackingReference::Prepare(bundles, *character,
                                              options.simulation.control_hz);
  auto states = std::make_shared<InitialStates>(
      *reference, character, options.simulation, StateBufferOptions());
  TrackingEnv env_a(character, reference, states, options, 1);
  TrackingEnv env_b(character, reference, states, options, 1);
  const int num_views = static_cast<int>(original.views.size());
  std::vector<float> obs_a(env_a.observation_size()), obs_b(obs_a.size());
  std::vector<float> action(env_a.action_size(), 0.1f);
  for (int view = 0; view < num_views; ++view) {
    env_a.ResetTo(view, 5, states->buffer(0).entry(5, 0).state, obs_a.data());
    env_b.ResetTo(num_views + view, 5, states->buffer(1).entry(5, 0).state,
                  obs_b.data());
    for (int step = 0; step < 10; ++step) {
      for (size_t i = 0; i < obs_a.size(); ++i)
        ASSERT_NEAR(obs_a[i], obs_b[i], 1e-4)
            << "view " << view << " step " << step << " feature " << i;
      StepOutcome a = env_a.Step(action.data(), obs_a.data());
      StepOutcome b = env_b.Step(action.data(), obs_b.data());
      ASSERT_NEAR(a.error.mean_px, b.error.mean_px, 1e-3);
      if (a.terminated || a.truncated) break;
    }
  }
}

}  // namespace
}  // namespace m2d
