#include "render/episode_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/error.h"
#include "env/reward.h"
#include "render/gl_camera.h"
#include "render/overlay.h"

namespace m2d {
namespace {

std::string FormatE2d(double e2d_px) {
  if (!std::isfinite(e2d_px)) return "E2D n/a";
  char text[48];
  std::snprintf(text, sizeof(text), "E2D %.1f px", e2d_px);
  return text;
}

std::string PngName(int clip_frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.png", clip_frame);
  return name;
}

// Keypoints scaled from clip pixels to output pixels.
std::vector<Keypoint2D> ScaleKeypoints(const std::vector<Keypoint2D>& points,
                                       double scale) {
  std::vector<Keypoint2D> scaled = points;
  for (Keypoint2D& point : scaled) {
    point.x_px *= scale;
    point.y_px *= scale;
  }
  return scaled;
}

// The crop that frames the subject: centre (x, y) of the box around the
// present points, and the zoom that makes the box `fraction` of the image
// height (in [1, max_zoom]); nullopt without present points.
std::optional<Eigen::Vector3d> SubjectFraming(
    const std::vector<Keypoint2D>& points, int height_px, double fraction,
    double max_zoom) {
  Eigen::Vector2d low(1e300, 1e300), high(-1e300, -1e300);
  int present = 0;
  for (const Keypoint2D& point : points) {
    if (!point.IsPresent()) continue;
    low = low.cwiseMin(point.Pixel());
    high = high.cwiseMax(point.Pixel());
    ++present;
  }
  if (present < 2) return std::nullopt;
  const double box_height_px = std::max(high.y() - low.y(), 1.0);
  const double zoom =
      std::clamp(fraction * height_px / box_height_px, 1.0, max_zoom);
  const Eigen::Vector2d centre = 0.5 * (low + high);
  return Eigen::Vector3d(centre.x(), centre.y(), zoom);
}

// `points` seen through the crop whose top-left corner is `corner` and
// magnification `zoom` (CropCamera's map).
std::vector<Keypoint2D> CropKeypoints(const std::vector<Keypoint2D>& points,
                                      const Eigen::Vector2d& corner,
                                      double zoom) {
  std::vector<Keypoint2D> cropped = points;
  for (Keypoint2D& point : cropped) {
    point.x_px = (point.x_px - corner.x()) * zoom;
    point.y_px = (point.y_px - corner.y()) * zoom;
  }
  return cropped;
}

Eigen::Vector3d MeanPoint(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& fallback) {
  if (points.empty()) return fallback;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : points) sum += point;
  return sum / static_cast<double>(points.size());
}

}  // namespace

bool RecordedFrames::Next(EpisodeFrame* frame) {
  if (next_ >= frames_.size()) return false;
  *frame = frames_[next_++];
  return true;
}

void EpisodeRenderOptions::Validate() const {
  if (!(std::isfinite(scale) && scale > 0 && scale <= 4)) {
    throw ConfigError("render scale must be in (0, 4]");
  }
  if (side_camera) side.Validate();
  if (!(subject_height_fraction >= 0 && subject_height_fraction <= 1)) {
    throw ConfigError("render: subject_height_fraction must be in [0, 1]");
  }
  if (!(max_zoom >= 1 && max_zoom <= 20)) {
    throw ConfigError("render: max_zoom must be in [1, 20]");
  }
}

void EpisodeOutputOptions::Validate() const {
  if (video_path.empty() && png_folder.empty()) {
    throw ConfigError(
        "render: nothing to write (no video path, no PNG folder)");
  }
  if (first_frame < 0) throw ConfigError("render: first frame must be >= 0");
  if (last_frame >= 0 && last_frame < first_frame) {
    throw ConfigError("render: last frame is before the first frame");
  }
  if (!video_path.empty()) video.Validate();
}

EpisodeRenderer::EpisodeRenderer(std::shared_ptr<const Character> character,
                                 const SimulationOptions& simulation,
                                 const KeypointLayout& layout,
                                 int image_width_px, int image_height_px,
                                 const EpisodeRenderOptions& options)
    : character_(std::move(character)),
      layout_(&layout),
      options_(options),
      simulation_(character_, simulation),
      image_width_px_(image_width_px),
      image_height_px_(image_height_px) {
  options_.Validate();
  if (layout.name != character_->keypoint_layout().name) {
    throw InputError(character_->config().source_path,
                     "the reference uses keypoint layout '" + layout.name +
                         "', the character's keypoints are '" +
                         character_->keypoint_layout().name + "'");
  }
  Intrinsics image;
  image.width_px = image_width_px;
  image.height_px = image_height_px;
  const Intrinsics scaled =
      ScaleCamera(PinholeCamera(image, Eigen::Matrix3d::Identity(),
                                Eigen::Vector3d::Zero()),
                  options_.scale)
          .intrinsics();
  panel_width_px_ = scaled.width_px;
  panel_height_px_ = scaled.height_px;
  SceneRenderOptions scene;
  scene.max_width_px = panel_width_px_;
  scene.max_height_px = panel_height_px_;
  scene.shadows = options_.shadows;
  scene_ = std::make_unique<SceneRenderer>(character_->model(), scene);
}

int EpisodeRenderer::width_px() const {
  return (1 + options_.side_camera + options_.source_panel) * panel_width_px_;
}
int EpisodeRenderer::height_px() const { return panel_height_px_; }

std::vector<Eigen::Vector3d> EpisodeRenderer::PlaceScene(
    const EpisodeFrame& frame) {
  if (!frame.state) {
    scene_->SetHiddenBodies(character_->bodies());
    return frame.keypoints_world_m;
  }
  scene_->SetHiddenBodies({});
  simulation_.Restore(*frame.state);
  return SimulatedKeypoints(simulation_);
}

void EpisodeRenderer::DrawObjects(const EpisodeFrame& frame,
                                  const Eigen::Vector2d& corner, double zoom,
                                  const OverlaySizes& reference_sizes,
                                  const OverlaySizes& sizes,
                                  OverlayCanvas& canvas) const {
  // Rings a ball's size: its radius (or 0.11 m) at its depth, shown.
  const std::vector<FreeObject>& objects = character_->free_objects();
  const double shown = zoom * options_.scale;
  const double fx_px = frame.camera.intrinsics().fx_px;
  const size_t count = std::min(objects.size(), frame.reference_objects.size());
  for (size_t o = 0; o < count; ++o) {
    const double* x = simulation_.data()->xpos + 3 * objects[o].body_id;
    const Projection projection = frame.camera.Project({x[0], x[1], x[2]});
    const double radius_m =
        objects[o].radius_m > 0 ? objects[o].radius_m : 0.11;
    const double radius_px = projection.in_front
                                 ? fx_px * radius_m / projection.depth_m * shown
                                 : 0.0;
    const Keypoint2D simulated = {projection.pixel_px.x(),
                                  projection.pixel_px.y(),
                                  projection.in_front ? 1.0 : 0.0};
    const auto shown_point = [&](const Keypoint2D& point) {
      return ScaleKeypoints(CropKeypoints({point}, corner, zoom),
                            options_.scale)
          .front();
    };
    canvas.DrawRing(shown_point(frame.reference_objects[o]),
                    radius_px + reference_sizes.line_width_px,
                    options_.reference_color, reference_sizes);
    if (frame.state)
      canvas.DrawRing(shown_point(simulated), radius_px, options_.pose_color,
                      sizes);
  }
}

RenderedFrame EpisodeRenderer::Render(const EpisodeFrame& frame) {
  // Outline: place the scene, draw it through the scaled camera, project
  // the pose, measure the 2D error, draw the overlays, add the side panel.
  const std::string where = "frame " + std::to_string(frame.clip_frame);
  const Intrinsics& intrinsics = frame.camera.intrinsics();
  if (intrinsics.width_px != image_width_px_ ||
      intrinsics.height_px != image_height_px_) {
    throw InputError("render", where + ": the camera's image is " +
                                   std::to_string(intrinsics.width_px) + "x" +
                                   std::to_string(intrinsics.height_px) +
                                   " px, the clip's " +
                                   std::to_string(image_width_px_) + "x" +
                                   std::to_string(image_height_px_));
  }
  const int num_keypoints = layout_->num_keypoints();
  if (!frame.reference.empty() &&
      static_cast<int>(frame.reference.size()) != num_keypoints) {
    throw InputError("render", where + ": the reference has " +
                                   std::to_string(frame.reference.size()) +
                                   " keypoints, layout " + layout_->name +
                                   " has " + std::to_string(num_keypoints));
  }
  const std::vector<Eigen::Vector3d> pose_world_m = PlaceScene(frame);
  if (!pose_world_m.empty() &&
      static_cast<int>(pose_world_m.size()) != num_keypoints) {
    throw InputError("render", where + ": the pose has " +
                                   std::to_string(pose_world_m.size()) +
                                   " 3D keypoints, layout " + layout_->name +
                                   " has " + std::to_string(num_keypoints));
  }
  // The pose's projection in clip pixels, for the error and the framing.
  std::vector<Keypoint2D> pose_px(pose_world_m.size());
  std::vector<double> projected_xy(2 * pose_world_m.size());
  auto in_front = std::make_unique<bool[]>(pose_world_m.size() + 1);
  for (size_t j = 0; j < pose_world_m.size(); ++j) {
    const Projection projection = frame.camera.Project(pose_world_m[j]);
    projected_xy[2 * j] = projection.pixel_px.x();
    projected_xy[2 * j + 1] = projection.pixel_px.y();
    in_front[j] = projection.in_front;
    pose_px[j] = {projection.pixel_px.x(), projection.pixel_px.y(),
                  projection.in_front ? 1.0 : 0.0};
  }

  // Framing: follow the subject (the reference, else the pose) with a crop
  // that moves and zooms smoothly, kept inside the image.
  Eigen::Vector2d corner(0.0, 0.0);
  double zoom = 1.0;
  if (options_.subject_height_fraction > 0) {
    std::optional<Eigen::Vector3d> target =
        SubjectFraming(frame.reference, image_height_px_,
                       options_.subject_height_fraction, options_.max_zoom);
    if (!target) {
      target =
          SubjectFraming(pose_px, image_height_px_,
                         options_.subject_height_fraction, options_.max_zoom);
    }
    constexpr double kFollow = 0.15;  // per frame: about a 0.2 s lag at 30 Hz
    if (target) {
      framing_ =
          framing_ ? (1.0 - kFollow) * *framing_ + kFollow * *target : *target;
    }
    if (framing_) {
      zoom = (*framing_)[2];
      const Eigen::Vector2d window(image_width_px_ / zoom,
                                   image_height_px_ / zoom);
      corner = framing_->head<2>() - 0.5 * window;
      corner.x() = std::clamp(corner.x(), 0.0, image_width_px_ - window.x());
      corner.y() = std::clamp(corner.y(), 0.0, image_height_px_ - window.y());
    }
  }
  const PinholeCamera camera = ScaleCamera(
      CropCamera(frame.camera, corner.x(), corner.y(), zoom), options_.scale);
  RenderedFrame rendered;
  rendered.image = scene_->RenderPinhole(simulation_.mutable_data(), camera);
  rendered.crop_corner_px = corner;
  rendered.zoom = zoom;

  if (!pose_world_m.empty() && !frame.reference.empty()) {
    const ReprojectionError error =
        MeasureReprojection(projected_xy.data(), in_front.get(),
                            frame.reference.data(), num_keypoints);
    if (error.num_present > 0) rendered.e2d_px = error.mean_px;
  }

  // The reference is drawn wider, under the pose: where they agree the
  // pose shows as a red core inside a green halo.
  const OverlaySizes sizes = OverlaySizesForHeight(panel_height_px_);
  OverlaySizes reference_sizes = sizes;
  reference_sizes.line_width_px *= 2.2;
  reference_sizes.dot_radius_px *= 1.6;
  OverlayCanvas canvas(&rendered.image);
  canvas.DrawSkeleton(
      *layout_,
      ScaleKeypoints(CropKeypoints(frame.reference, corner, zoom),
                     options_.scale),
      options_.reference_color, reference_sizes);
  canvas.DrawSkeleton(
      *layout_,
      ScaleKeypoints(CropKeypoints(pose_px, corner, zoom), options_.scale),
      options_.pose_color, sizes);
  if (!frame.reference_objects.empty())
    DrawObjects(frame, corner, zoom, reference_sizes, sizes, canvas);
  const double margin_px = 0.5 * sizes.font_size_px;
  canvas.DrawLabel({{"frame " + std::to_string(frame.clip_frame)},
                    {FormatE2d(rendered.e2d_px)},
                    {options_.reference_label, options_.reference_color, true},
                    {options_.pose_label, options_.pose_color, true}},
                   margin_px, margin_px, sizes);
  canvas.Finish();

  // Panels left to right: the recording, the render, the free camera.
  std::vector<RgbImage> panels;
  if (options_.source_panel) {
    const RgbImage& source = frame.source_image;
    if (source.width_px() != image_width_px_ ||
        source.height_px() != image_height_px_) {
      throw InputError(
          "render", where + (source.empty()
                                 ? ": no frame of the source video"
                                 : ": the source video's frame is " +
                                       std::to_string(source.width_px()) + "x" +
                                       std::to_string(source.height_px()) +
                                       " px, the clip's image " +
                                       std::to_string(image_width_px_) + "x" +
                                       std::to_string(image_height_px_)));
    }
    RgbImage shown =
        CropAndScale(source, corner.x(), corner.y(), zoom * options_.scale,
                     panel_width_px_, panel_height_px_);
    OverlayCanvas source_canvas(&shown);
    source_canvas.DrawSkeleton(
        *layout_,
        ScaleKeypoints(CropKeypoints(frame.reference, corner, zoom),
                       options_.scale),
        options_.reference_color, sizes);
    source_canvas.DrawLabel(
        {{"source video"},
         {options_.reference_label, options_.reference_color, true}},
        margin_px, margin_px, sizes);
    source_canvas.Finish();
    panels.push_back(std::move(shown));
  }
  panels.push_back(std::move(rendered.image));
  if (options_.side_camera) {
    const PinholeCamera side_camera = OrbitCamera(
        options_.side, MeanPoint(pose_world_m, Eigen::Vector3d(0.0, 0.0, 1.0)),
        panel_width_px_, panel_height_px_);
    RgbImage side =
        scene_->RenderPinhole(simulation_.mutable_data(), side_camera);
    std::vector<Keypoint2D> side_pose_px;
    for (const Eigen::Vector3d& point : pose_world_m) {
      const Projection projection = side_camera.Project(point);
      side_pose_px.push_back({projection.pixel_px.x(), projection.pixel_px.y(),
                              projection.in_front ? 1.0 : 0.0});
    }
    OverlayCanvas side_canvas(&side);
    side_canvas.DrawSkeleton(*layout_, side_pose_px, options_.pose_color,
                             sizes);
    side_canvas.DrawLabel({{"free camera"}}, margin_px, margin_px, sizes);
    side_canvas.Finish();
    panels.push_back(std::move(side));
  }
  if (panels.size() == 1) {
    rendered.image = std::move(panels[0]);
  } else {
    rendered.image = RgbImage(width_px(), panel_height_px_);
    for (size_t p = 0; p < panels.size(); ++p) {
      rendered.image.Paste(panels[p], static_cast<int>(p) * panel_width_px_, 0);
    }
  }
  return rendered;
}

EpisodeSummary RenderEpisode(FrameSource& source, EpisodeRenderer& renderer,
                             const EpisodeOutputOptions& output) {
  output.Validate();
  EpisodeSummary summary;
  summary.width_px = renderer.width_px();
  summary.height_px = renderer.height_px();
  std::unique_ptr<Mp4Writer> video;
  if (!output.video_path.empty()) {
    video = std::make_unique<Mp4Writer>(output.video_path, summary.width_px,
                                        summary.height_px, output.video);
  }
  if (!output.png_folder.empty()) {
    std::filesystem::create_directories(output.png_folder);
  }
  double e2d_sum_px = 0.0;
  int e2d_frames = 0;
  EpisodeFrame frame;
  int index = 0;
  for (; source.Next(&frame); ++index) {
    if (index < output.first_frame) continue;
    if (output.last_frame >= 0 && index > output.last_frame) break;
    RenderedFrame rendered = renderer.Render(frame);
    if (video) video->Write(rendered.image);
    if (!output.png_folder.empty()) {
      std::string path =
          (std::filesystem::path(output.png_folder) / PngName(frame.clip_frame))
              .string();
      WritePng(path, rendered.image);
      summary.png_paths.push_back(path);
    }
    if (std::isfinite(rendered.e2d_px)) {
      e2d_sum_px += rendered.e2d_px;
      ++e2d_frames;
    }
    ++summary.frames_rendered;
  }
  if (summary.frames_rendered == 0) {
    throw ConfigError("render: the frame range starts at frame " +
                      std::to_string(output.first_frame) +
                      " but the episode has " + std::to_string(index) +
                      " frames");
  }
  if (e2d_frames > 0) summary.mean_e2d_px = e2d_sum_px / e2d_frames;
  if (video) {
    video->Finish();
    summary.video_path = output.video_path;
  }
  return summary;
}

SourceVideoFrames::SourceVideoFrames(FrameSource& inner,
                                     const std::string& video_path,
                                     double clip_fps, double start_s)
    : inner_(inner),
      video_path_(video_path),
      reader_(video_path),
      clip_fps_(clip_fps),
      start_s_(start_s) {
  if (!(clip_fps > 0) || !(reader_.info().fps > 0)) {
    throw InputError(video_path,
                     "no frame rate to align the video with the "
                     "clip (clip " +
                         std::to_string(clip_fps) + " fps, video " +
                         std::to_string(reader_.info().fps) + " fps)");
  }
}

bool SourceVideoFrames::Next(EpisodeFrame* frame) {
  // Outline: take the inner frame, read the video forward to the frame
  // shown at that clip frame's moment, attach it.
  if (!inner_.Next(frame)) return false;
  const double time_s = start_s_ + frame->clip_frame / clip_fps_;
  // Video frame k is shown over [k, k + 1) / fps; the epsilon keeps a clip
  // frame that falls exactly on a video frame's start on that frame.
  const int64_t wanted =
      static_cast<int64_t>(std::floor(time_s * reader_.info().fps + 1e-6));
  if (wanted < current_index_) {
    throw InputError(video_path_,
                     "clip frame " + std::to_string(frame->clip_frame) +
                         " is earlier than the video frame already shown: "
                         "frames must come in order");
  }
  while (current_index_ < wanted && !ended_) {
    RgbImage next;
    if (!reader_.Read(&next)) {
      ended_ = true;  // past the end: the last frame stays
      break;
    }
    current_ = std::move(next);
    ++current_index_;
  }
  if (current_index_ < 0) {
    throw InputError(video_path_, time_s < 0
                                      ? "the clip starts before the video"
                                      : "the video has no frames");
  }
  frame->source_image = current_;
  return true;
}

BundleReplaySource::BundleReplaySource(
    const ReferenceBundle& bundle, int view_index,
    std::shared_ptr<const Character> character,
    const SimulationOptions& simulation, ReplayedMotion motion)
    : bundle_(bundle),
      view_(bundle.views.at(view_index)),
      simulation_(character, simulation) {
  if (motion == ReplayedMotion::kEstimate) {
    if (!bundle.estimate) {
      throw InputError(bundle.name,
                       "has no estimate to replay: fit it first (mimic2d fit)");
    }
    estimate_ = &(*bundle.estimate)[view_index];
    if (estimate_->skeleton_name != character->skeleton().name) {
      throw InputError(bundle.name, "the estimate of view " + view_.name +
                                        " is of skeleton '" +
                                        estimate_->skeleton_name +
                                        "', not the character's");
    }
    shows_character_ = true;
    return;
  }
  if (view_.cameras.empty()) {
    throw InputError(bundle.name, "view " + view_.name +
                                      " has no true cameras (stripped): "
                                      "nothing to replay it from");
  }
  shows_character_ =
      bundle.ground_truth && !bundle.ground_truth->poses.empty() &&
      bundle.ground_truth->skeleton_name == character->skeleton().name;
}

bool BundleReplaySource::Next(EpisodeFrame* frame) {
  const int t = next_frame_;
  if (t >= bundle_.num_frames()) return false;
  ++next_frame_;
  frame->clip_frame = t;
  frame->camera =
      estimate_ != nullptr ? estimate_->CameraAt(t) : view_.CameraAt(t);
  const Clip2D& clip = view_.clip;
  frame->reference.assign(
      clip.keypoints.frame(t),
      clip.keypoints.frame(t) + clip.keypoints.num_keypoints());
  frame->keypoints_world_m.clear();
  if (shows_character_) {
    simulation_.SetPose(estimate_ != nullptr ? estimate_->poses[t]
                                             : bundle_.ground_truth->poses[t]);
    if (!frame->state) frame->state.emplace();
    simulation_.Save(&*frame->state);
  } else {
    frame->state.reset();
    // Ground-truth keypoints are drawn only in the clip's own layout.
    if (bundle_.ground_truth && bundle_.ground_truth->layout == clip.layout &&
        !bundle_.ground_truth->keypoints_m.empty()) {
      frame->keypoints_world_m = bundle_.ground_truth->keypoints_m[t];
    }
  }
  return true;
}

EpisodeSummary RenderBundleReplay(const ReferenceBundle& bundle,
                                  const BundleReplayOptions& options) {
  if (bundle.views.empty())
    throw InputError(bundle.name, "bundle has no views");
  int view_index = 0;
  if (!options.view.empty()) {
    view_index = -1;
    std::string names;
    for (size_t v = 0; v < bundle.views.size(); ++v) {
      if (bundle.views[v].name == options.view)
        view_index = static_cast<int>(v);
      names += (names.empty() ? "" : ", ") + bundle.views[v].name;
    }
    if (view_index < 0) {
      throw InputError(bundle.name,
                       "no view '" + options.view + "' (views: " + names + ")");
    }
  }
  const SimulationOptions simulation;
  std::shared_ptr<const Character> character = LoadCharacterForSimulation(
      options.character_config, options.scene, simulation);
  BundleReplaySource replay(bundle, view_index, character, simulation,
                            options.motion);
  EpisodeRenderOptions render = options.render;
  if (options.motion == ReplayedMotion::kEstimate) {
    render.pose_label = "fitted pose";
  } else if (!replay.shows_character()) {
    render.pose_label = "3D ground truth";
  }
  const Clip2D& clip = bundle.views[view_index].clip;
  return RenderViewFrames(replay, character, simulation, clip, bundle.fps,
                          render, options);
}

EpisodeSummary RenderViewFrames(FrameSource& frames,
                                std::shared_ptr<const Character> character,
                                const SimulationOptions& simulation,
                                const Clip2D& clip, double fps,
                                EpisodeRenderOptions render,
                                const BundleReplayOptions& options) {
  std::optional<SourceVideoFrames> with_video;
  if (!options.source_video.empty()) {
    with_video.emplace(frames, options.source_video, fps,
                       options.source_video_start_s);
    render.source_panel = true;
  }
  EpisodeRenderer renderer(std::move(character), simulation, *clip.layout,
                           clip.image_width_px, clip.image_height_px, render);
  EpisodeOutputOptions output = options.output;
  output.video.fps = fps;
  FrameSource& source =
      with_video ? static_cast<FrameSource&>(*with_video) : frames;
  return RenderEpisode(source, renderer, output);
}

}  // namespace m2d
