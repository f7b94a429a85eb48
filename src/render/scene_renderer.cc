#include "render/scene_renderer.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "common/error.h"
#include "render/gl_camera.h"

namespace m2d {
namespace {

constexpr int kMaxSceneGeoms = 4000;

}  // namespace

void SceneRenderOptions::Validate() const {
  if (max_width_px < 1 || max_height_px < 1) {
    throw ConfigError("render size must be positive");
  }
  if (max_width_px > 8192 || max_height_px > 8192) {
    throw ConfigError("render size is limited to 8192 x 8192 px");
  }
  if (shadow_map_size_px < 64) {
    throw ConfigError("shadow map size must be at least 64 px");
  }
  if (multisamples < 0 || multisamples > 16) {
    throw ConfigError("multisamples must be in [0, 16]");
  }
}

struct SceneRenderer::GlState {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> window;  // OSMesa's default framebuffer
  int window_width_px = 0;
  int window_height_px = 0;
  mjvScene scene;
  mjrContext render_context;
  mjvOption visual_options;
  bool scene_made = false;
  bool render_context_made = false;

  bool MakeCurrent() {
    return OSMesaMakeCurrent(context, window.data(), GL_UNSIGNED_BYTE,
                             window_width_px, window_height_px);
  }
  // Frees in reverse order of creation, with the context current (MuJoCo
  // deletes GL objects).
  ~GlState() {
    if (context == nullptr) return;
    MakeCurrent();
    if (render_context_made) mjr_freeContext(&render_context);
    if (scene_made) mjv_freeScene(&scene);
    OSMesaDestroyContext(context);
  }
};

SceneRenderer::SceneRenderer(const mjModel* model,
                             const SceneRenderOptions& options)
    : options_(options), gl_(std::make_unique<GlState>()) {
  options_.Validate();
  InstallMujocoErrorHandlers();
  model_.reset(mj_copyModel(nullptr, model));
  // The offscreen framebuffer's size and quality come from the model.
  model_->vis.global.offwidth = options_.max_width_px;
  model_->vis.global.offheight = options_.max_height_px;
  model_->vis.quality.shadowsize = options_.shadow_map_size_px;
  model_->vis.quality.offsamples = options_.multisamples;
  hidden_body_.assign(model_->nbody, 0);

  // RGBA, 24-bit depth, 8-bit stencil, no accumulation buffer.
  gl_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (gl_->context == nullptr) {
    throw std::runtime_error(
        "OSMesa cannot create an offscreen OpenGL context "
        "(is libosmesa6 installed?)");
  }
  // MuJoCo draws into its own framebuffer object; the default framebuffer
  // only has to exist.
  gl_->window_width_px = 64;
  gl_->window_height_px = 64;
  gl_->window.assign(4 * gl_->window_width_px * gl_->window_height_px, 0);
  MakeCurrent();
  mjv_defaultOption(&gl_->visual_options);
  mjv_defaultScene(&gl_->scene);
  mjr_defaultContext(&gl_->render_context);
  try {
    mjv_makeScene(model_.get(), &gl_->scene, kMaxSceneGeoms);
    gl_->scene_made = true;
    mjr_makeContext(model_.get(), &gl_->render_context, mjFONTSCALE_100);
    gl_->render_context_made = true;
  } catch (const MujocoError& e) {
    throw std::runtime_error(std::string("MuJoCo cannot set up rendering: ") +
                             e.what());
  }
  gl_->scene.flags[mjRND_SHADOW] = options_.shadows ? 1 : 0;
  if (gl_->render_context.offWidth < options_.max_width_px ||
      gl_->render_context.offHeight < options_.max_height_px) {
    throw std::runtime_error("MuJoCo's offscreen buffer is smaller than asked");
  }
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::MakeCurrent() {
  if (!gl_->MakeCurrent()) {
    throw std::runtime_error("OSMesa cannot make its context current");
  }
}

void SceneRenderer::SetHiddenBodies(const std::vector<int>& body_ids) {
  std::fill(hidden_body_.begin(), hidden_body_.end(), 0);
  for (int body : body_ids) {
    if (body < 0 || body >= model_->nbody) {
      throw std::out_of_range("SetHiddenBodies: no body " +
                              std::to_string(body));
    }
    hidden_body_[body] = 1;
  }
}

void SceneRenderer::UpdateScene(mjData* data) {
  // Any camera will do: RenderPinhole replaces it.
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  mjvScene& scene = gl_->scene;
  mjv_updateScene(model_.get(), data, &gl_->visual_options, nullptr, &camera,
                  mjCAT_ALL, &scene);
  // Drop the hidden bodies' geoms and sites from the scene's geom list.
  int kept = 0;
  for (int i = 0; i < scene.ngeom; ++i) {
    const mjvGeom& geom = scene.geoms[i];
    int body = -1;
    if (geom.objtype == mjOBJ_GEOM) body = model_->geom_bodyid[geom.objid];
    if (geom.objtype == mjOBJ_SITE) body = model_->site_bodyid[geom.objid];
    if (body >= 0 && hidden_body_[body]) continue;
    scene.geoms[kept++] = geom;
  }
  scene.ngeom = kept;
}

RgbImage SceneRenderer::Draw(int width_px, int height_px) {
  if (width_px > options_.max_width_px || height_px > options_.max_height_px) {
    throw ConfigError("a " + std::to_string(width_px) + "x" +
                      std::to_string(height_px) +
                      " px view exceeds the renderer's " +
                      std::to_string(options_.max_width_px) + "x" +
                      std::to_string(options_.max_height_px) + " px buffer");
  }
  mjrRect viewport = {0, 0, width_px, height_px};
  mjr_setBuffer(mjFB_OFFSCREEN, &gl_->render_context);
  mjr_render(viewport, &gl_->scene, &gl_->render_context);
  std::vector<unsigned char> bottom_up(static_cast<size_t>(width_px) *
                                       height_px * 3);
  mjr_readPixels(bottom_up.data(), nullptr, viewport, &gl_->render_context);
  // OpenGL rows run bottom to top; images run top to bottom.
  RgbImage image(width_px, height_px);
  const size_t row_bytes = static_cast<size_t>(width_px) * 3;
  for (int y = 0; y < height_px; ++y) {
    std::memcpy(image.data() + y * row_bytes,
                bottom_up.data() + (height_px - 1 - y) * row_bytes, row_bytes);
  }
  return image;
}

RgbImage SceneRenderer::RenderPinhole(mjData* data,
                                      const PinholeCamera& camera) {
  MakeCurrent();
  UpdateScene(data);
  // Replace MuJoCo's camera by the pinhole's, keeping the model's clip
  // range (the one mjv_updateScene uses: znear/zfar times the extent).
  const double extent_m = model_->stat.extent;
  const mjvGLCamera gl_camera =
      GlCameraFromPinhole(camera, model_->vis.map.znear * extent_m,
                          model_->vis.map.zfar * extent_m);
  // Both eyes alike: mono rendering draws their average.
  gl_->scene.camera[0] = gl_camera;
  gl_->scene.camera[1] = gl_camera;
  return Draw(camera.intrinsics().width_px, camera.intrinsics().height_px);
}

}  // namespace m2d
