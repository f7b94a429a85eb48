#include "render/scene_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/error.h"
#include "render/gl_camera.h"
#include "render_test_util.h"

namespace m2d {
namespace {

using testing::ColorDistance;

// Distance from `pixel` (image coordinates) to the centre of the nearest
// pixel where `scene` differs from `empty`, searched within 12 px.
double DistanceToCharacterPx(const RgbImage& scene, const RgbImage& empty,
                             const Eigen::Vector2d& pixel) {
  double best = 1e9;
  const int u = static_cast<int>(std::floor(pixel.x()));
  const int v = static_cast<int>(std::floor(pixel.y()));
  for (int y = std::max(0, v - 12);
       y <= std::min(scene.height_px() - 1, v + 12); ++y) {
    for (int x = std::max(0, u - 12);
         x <= std::min(scene.width_px() - 1, u + 12); ++x) {
      if (ColorDistance(scene.at(x, y), empty.at(x, y)) <= 10) continue;
      best = std::min(best, (Eigen::Vector2d(x + 0.5, y + 0.5) - pixel).norm());
    }
  }
  return best;
}

// The humanoid in its reference pose with an arm raised and a knee bent,
// the projected keypoints, and renders with and without the character.
class KnownPoseRender : public ::testing::Test {
 protected:
  void SetUp() override {
    character_ = testing::LoadRenderHumanoid();
    simulation_ = std::make_unique<Simulation>(character_, SimulationOptions());
    mjData* data = simulation_->mutable_data();
    const mjModel* model = simulation_->model();
    for (const char* joint : {"right_shoulder_x", "left_knee", "left_hip_y"}) {
      const int id = mj_name2id(model, mjOBJ_JOINT, joint);
      ASSERT_GE(id, 0) << joint;
      // 60% of the way to the range end farther from zero.
      const double low = model->jnt_range[2 * id];
      const double high = model->jnt_range[2 * id + 1];
      data->qpos[model->jnt_qposadr[id]] =
          0.6 * (std::abs(low) > std::abs(high) ? low : high);
    }
    simulation_->Refresh();
    keypoints_m_ = SimulatedKeypoints(*simulation_);
    const Eigen::Vector3d center = testing::Centroid(keypoints_m_);
    // Off-centre principal point: a frustum ignoring it misses by 60 px
    // horizontally and 50 px vertically.
    Intrinsics intrinsics;
    intrinsics.width_px = 640;
    intrinsics.height_px = 480;
    intrinsics.fx_px = intrinsics.fy_px = 520.0;
    intrinsics.cx_px = 260.0;
    intrinsics.cy_px = 290.0;
    camera_ = PinholeCamera::LookAt(
        intrinsics, center + Eigen::Vector3d(2.6, -2.2, 0.6), center);
    SceneRenderOptions options;
    options.max_width_px = 640;
    options.max_height_px = 480;
    renderer_ = std::make_unique<SceneRenderer>(simulation_->model(), options);
  }

  RgbImage Render(bool with_character) {
    renderer_->SetHiddenBodies(with_character ? std::vector<int>{}
                                              : character_->bodies());
    return renderer_->RenderPinhole(simulation_->mutable_data(), camera_);
  }

  std::shared_ptr<const Character> character_;
  std::unique_ptr<Simulation> simulation_;
  std::vector<Eigen::Vector3d> keypoints_m_;
  PinholeCamera camera_;
  std::unique_ptr<SceneRenderer> renderer_;
};

TEST_F(KnownPoseRender, CharacterIsWhereItsProjectedKeypointsAre) {
  const RgbImage scene = Render(true);
  const RgbImage empty = Render(false);
  ASSERT_EQ(scene.width_px(), 640);
  ASSERT_EQ(scene.height_px(), 480);

  // Each keypoint lies on the character: a character pixel within 3 px
  // (keypoints at joints can fall in the gap between two capsules).
  double min_u = 1e9, max_u = -1e9, min_v = 1e9, max_v = -1e9;
  for (size_t j = 0; j < keypoints_m_.size(); ++j) {
    const Projection p = camera_.Project(keypoints_m_[j]);
    ASSERT_TRUE(p.in_front);
    EXPECT_LE(DistanceToCharacterPx(scene, empty, p.pixel_px), 3.0)
        << "keypoint " << character_->keypoint_layout().keypoint_names[j];
    min_u = std::min(min_u, p.pixel_px.x());
    max_u = std::max(max_u, p.pixel_px.x());
    min_v = std::min(min_v, p.pixel_px.y());
    max_v = std::max(max_v, p.pixel_px.y());
  }

  // Far from the character (outside its keypoints' box grown by half its
  // height, which holds the head, hands, feet and shadow) the two renders
  // are identical, and the character's pixels lie inside that box.
  const double margin_px = 0.5 * (max_v - min_v);
  int far_pixels = 0, far_differences = 0, character_pixels = 0;
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const bool far = x < min_u - margin_px || x > max_u + margin_px ||
                       y < min_v - margin_px || y > max_v + margin_px;
      const bool differs = ColorDistance(scene.at(x, y), empty.at(x, y)) > 0;
      if (far) {
        ++far_pixels;
        far_differences += differs;
      } else {
        character_pixels += differs;
      }
    }
  }
  EXPECT_GT(far_pixels, 50000);
  EXPECT_EQ(far_differences, 0);
  EXPECT_GT(character_pixels, 2000);
}

// The check above has teeth: a render that ignores the principal point
// (what a plain MuJoCo free camera does) misses most keypoints.
TEST_F(KnownPoseRender, CenteredFrustumWouldMissTheKeypoints) {
  Intrinsics centered = camera_.intrinsics();
  centered.cx_px = 320.0;
  centered.cy_px = 240.0;
  const PinholeCamera wrong(centered, camera_.rotation_world_to_camera(),
                            camera_.translation_m());
  renderer_->SetHiddenBodies({});
  const RgbImage scene =
      renderer_->RenderPinhole(simulation_->mutable_data(), wrong);
  // The empty scene through the same wrong camera: only the character
  // differs (the checker floor is seen from the same place).
  renderer_->SetHiddenBodies(character_->bodies());
  const RgbImage empty =
      renderer_->RenderPinhole(simulation_->mutable_data(), wrong);
  int missed = 0;
  for (const Eigen::Vector3d& keypoint : keypoints_m_) {
    missed += DistanceToCharacterPx(scene, empty,
                                    camera_.Project(keypoint).pixel_px) > 3.0;
  }
  EXPECT_GT(missed, static_cast<int>(keypoints_m_.size()) / 2);
}

TEST_F(KnownPoseRender, ScaledCameraRendersTheSameViewSmaller) {
  const PinholeCamera half = ScaleCamera(camera_, 0.5);
  EXPECT_EQ(half.intrinsics().width_px, 320);
  EXPECT_EQ(half.intrinsics().height_px, 240);
  renderer_->SetHiddenBodies({});
  const RgbImage small =
      renderer_->RenderPinhole(simulation_->mutable_data(), half);
  renderer_->SetHiddenBodies(character_->bodies());
  const RgbImage empty =
      renderer_->RenderPinhole(simulation_->mutable_data(), half);
  for (size_t j = 0; j < keypoints_m_.size(); ++j) {
    EXPECT_LE(DistanceToCharacterPx(small, empty,
                                    half.Project(keypoints_m_[j]).pixel_px),
              2.0)
        << "keypoint " << j;
  }
}

TEST(SceneRenderer, OrbitCameraSeesTheCharacterWithinTheBuffer) {
  auto character = testing::LoadRenderHumanoid();
  Simulation simulation(character, SimulationOptions());
  SceneRenderOptions options;
  options.max_width_px = 320;
  options.max_height_px = 240;
  SceneRenderer renderer(simulation.model(), options);
  const Eigen::Vector3d target(0, 0, 1);
  const PinholeCamera camera =
      OrbitCamera(OrbitCameraOptions(), target, 320, 240);
  // The orbit camera looks at its target from the set distance.
  EXPECT_TRUE(camera.Project(target).pixel_px.isApprox(
      Eigen::Vector2d(160.0, 120.0), 1e-9));
  EXPECT_NEAR((camera.CenterWorld() - target).norm(), 4.0, 1e-9);
  EXPECT_GT(camera.CenterWorld().z(), target.z());  // looking down
  const RgbImage scene =
      renderer.RenderPinhole(simulation.mutable_data(), camera);
  renderer.SetHiddenBodies(character->bodies());
  const RgbImage empty =
      renderer.RenderPinhole(simulation.mutable_data(), camera);
  // The character stands at the image centre.
  EXPECT_GT(ColorDistance(scene.at(160, 120), empty.at(160, 120)), 10);
  // Views larger than the offscreen buffer are refused.
  EXPECT_THROW(renderer.RenderPinhole(
                   simulation.mutable_data(),
                   OrbitCamera(OrbitCameraOptions(), target, 640, 240)),
               ConfigError);
}

}  // namespace
}  // namespace m2d
