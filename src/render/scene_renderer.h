// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_SCENE_RENDERER_H_
#define MIMIC2D_RENDER_SCENE_RENDERER_H_

#include <mujoco/mujoco.h>

#include <memory>
#include <vector>

#include "camera/pinhole.h"
#include "media/image.h"
#include "sim/mujoco_handles.h"

namespace m2d {

struct SceneRenderOptions {
  int max_width_px = 1920;  // largest viewport this renderer will draw
  int max_height_px = 1080;
  bool shadows = true;
  int shadow_map_size_px = 4096;  // MuJoCo's default; smaller is faster
  int multisamples = 4;           // anti-aliasing of the 3D render
  void Validate() const;          // throws ConfigError
};

// Draws a MuJoCo model offscreen on the CPU (OSMesa: no display, no GPU).
// One OSMesa context per renderer, made current on the calling thread by
// each call: use a renderer from one thread at a time.
class SceneRenderer {
 public:
  // Keeps its own copy of `model` (the offscreen buffer size lives in it).
  // Throws std::runtime_error when OSMesa or MuJoCo's GL context fails.
  SceneRenderer(const mjModel* model, const SceneRenderOptions& options);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  const mjModel* model() const { return model_.get(); }

  // Hides every geom of the listed bodies (e.g. the character, to draw the
  // empty scene); an empty list shows everything.
  void SetHiddenBodies(const std::vector<int>& body_ids);

  // `data` (of a model with the same structure) seen through `camera`, at
  // the camera's image size. `data` is only read (MuJoCo's API is not
  // const-correct).
  RgbImage RenderPinhole(mjData* data, const PinholeCamera& camera);

 private:
  void MakeCurrent();
  void UpdateScene(mjData* data);
  RgbImage Draw(int width_px, int height_px);

  struct GlState;
  MujocoModelPtr model_;
  SceneRenderOptions options_;
  std::unique_ptr<GlState> gl_;
  std::vector<char> hidden_body_;  // per model body
};

}  // namespace m2d

#endif  // MIMIC2D_RENDER_SCENE_RENDERER_H_
