// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_EPISODE_RENDERER_H_
#define MIMIC2D_RENDER_EPISODE_RENDERER_H_

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera/pinhole.h"
#include "media/image.h"
#include "media/video_reader.h"
#include "media/video_writer.h"
#include "motion/bundle.h"
#include "motion/clip2d.h"
#include "render/gl_camera.h"
#include "render/overlay.h"
#include "render/scene_renderer.h"
#include "sim/simulation.h"

namespace m2d {

// One moment of an episode to show: the scene, the camera the reference
// was seen from, and the 2D reference at that moment.
struct EpisodeFrame {
  int clip_frame = 0;    // reference clip frame, printed in the corner
  PinholeCamera camera;  // at the clip's image size (scaling comes later)
  // The layout's keypoints in the clip's image pixels; empty: no reference.
  std::vector<Keypoint2D> reference;
  // The tracked objects' reference (e.g. the ball's centre), clip pixels,
  // in the scene's free-object order; drawn as rings beside the simulated
  // objects' projections. Empty: no objects tracked.
  std::vector<Keypoint2D> reference_objects;
  // The character's (and the scene's) state; nullopt: the scene without
  // the character.
  std::optional<SimState> state;
  // With no `state`: the shown pose's 3D keypoints (layout order, world),
  // e.g. a bundle's ground truth for a skeleton without a character. With a
  // `state` the character's keypoint sites are used and this is ignored.
  std::vector<Eigen::Vector3d> keypoints_world_m;
  // The recording's own frame at this moment, at the clip's image size
  // (EpisodeRenderOptions::source_panel); empty: none.
  RgbImage source_image;
};

// Where frames come from: a kinematic replay (BundleReplaySource), a policy
// rollout, or any recorded sequence (RecordedFrames).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Fills the next frame; false when the episode is over.
  virtual bool Next(EpisodeFrame* frame) = 0;
};

// Frames recorded beforehand (e.g. Simulation::Save() after every step of
// a rollout), played in order.
class RecordedFrames : public FrameSource {
 public:
  explicit RecordedFrames(std::vector<EpisodeFrame> frames)
      : frames_(std::move(frames)) {}
  bool Next(EpisodeFrame* frame) override;

 private:
  std::vector<EpisodeFrame> frames_;
  size_t next_ = 0;
};

// Adds to each frame of `inner` the frame of the recording it was seen in:
// clip frame t is at start_s + t / clip_fps in the video, which shows there
// the last video frame that began by then (a 10 fps video holds each frame
// for three 30 Hz clip frames; past its end, its last frame). Frames must
// come in order. InputError naming the video when it cannot be read.
class SourceVideoFrames : public FrameSource {
 public:
  SourceVideoFrames(FrameSource& inner, const std::string& video_path,
                    double clip_fps, double start_s);
  bool Next(EpisodeFrame* frame) override;

 private:
  FrameSource& inner_;
  std::string video_path_;
  VideoReader reader_;
  double clip_fps_;
  double start_s_;
  RgbImage current_;            // the video frame last read
  int64_t current_index_ = -1;  // its index; -1 before the first
  bool ended_ = false;          // the video has no more frames
};

// How a frame looks.
struct EpisodeRenderOptions {
  // Output size = the clip's image size x scale, rounded up to even.
  double scale = 1.0;
  // A second panel on the right: an orbit camera following the pose's
  // centre, with the pose's keypoints drawn (the reference has no meaning
  // in that view).
  bool side_camera = false;
  OrbitCameraOptions side;
  bool shadows = true;
  // A panel on the left: the recording's own frame (EpisodeFrame::
  // source_image) under the same framing as the render, with the 2D
  // reference drawn over it; every frame must then carry one.
  bool source_panel = false;
  // Framing: the view zooms in on the subject (a crop of the reference
  // camera, drawn at full resolution) so that it fills about this share of
  // the frame height, following it smoothly; at most `max_zoom`x, never
  // out. 0 shows the camera's whole image.
  double subject_height_fraction = 0.5;
  double max_zoom = 3.0;
  Rgb reference_color = {40, 200, 70};  // green: the 2D reference
  Rgb pose_color = {230, 50, 40};       // red: the shown pose, projected
  std::string reference_label = "2D reference";
  std::string pose_label = "character";
  void Validate() const;  // throws ConfigError
};

// One drawn frame and the 2D error it shows.
struct RenderedFrame {
  RgbImage image;
  // Mean distance (clip pixels) between the reference and the projected
  // pose over the reference's present keypoints; NaN when not measurable.
  double e2d_px = std::numeric_limits<double>::quiet_NaN();
  // The framing crop shown (EpisodeRenderOptions::subject_height_fraction):
  // clip pixel p is drawn at (p - crop_corner_px) x zoom x scale.
  Eigen::Vector2d crop_corner_px = Eigen::Vector2d::Zero();
  double zoom = 1.0;
};

// Draws episode frames: the 3D scene through the frame's pinhole camera,
// then the reference (green) and the pose's projected keypoints (red) as
// skeletons (tracked objects as rings of the same colours), the frame number
// and 2D error in the top-left corner, and optionally a free (orbit) camera
// panel on the right.
class EpisodeRenderer {
 public:
  // Frames show `character`'s scene; their states are restored into the
  // renderer's own simulation (the caller's is never touched). `layout`
  // is the references' keypoint layout and must be the character's.
  EpisodeRenderer(std::shared_ptr<const Character> character,
                  const SimulationOptions& simulation,
                  const KeypointLayout& layout, int image_width_px,
                  int image_height_px, const EpisodeRenderOptions& options);

  RenderedFrame Render(const EpisodeFrame& frame);
  // Forget the framing (the next frame is framed on its own, not smoothed
  // from the previous one): call between episodes.
  void ResetFraming() { framing_.reset(); }

  // Output frame size (both panels).
  int width_px() const;
  int height_px() const;
  const EpisodeRenderOptions& options() const { return options_; }

 private:
  // The pose's 3D keypoints: restores the state (or hides the character).
  std::vector<Eigen::Vector3d> PlaceScene(const EpisodeFrame& frame);
  // The frame's reference objects (rings, reference colour) and, with a
  // state, the scene's simulated objects (rings, pose colour), cropped by
  // `corner` and `zoom` and scaled as the skeletons are.
  void DrawObjects(const EpisodeFrame& frame, const Eigen::Vector2d& corner,
                   double zoom, const OverlaySizes& reference_sizes,
                   const OverlaySizes& sizes, OverlayCanvas& canvas) const;

  std::shared_ptr<const Character> character_;
  const KeypointLayout* layout_;
  EpisodeRenderOptions options_;
  Simulation simulation_;
  int image_width_px_;  // the clip's image size
  int image_height_px_;
  int panel_width_px_;  // one panel of the output, after scaling
  int panel_height_px_;
  std::unique_ptr<SceneRenderer> scene_;
  // The smoothed crop (centre x, y in clip pixels; zoom), once framed.
  std::optional<Eigen::Vector3d> framing_;
};

// What to write and which frames.
struct EpisodeOutputOptions {
  std::string video_path;  // MP4; empty: no video
  std::string png_folder;  // frame_<clip frame>.png; empty: no PNGs
  Mp4Options video;
  int first_frame = 0;    // the source's frames [first, last] are drawn,
  int last_frame = -1;    // counted from 0 in source order; -1: to the end
  void Validate() const;  // throws ConfigError
};

struct EpisodeSummary {
  int frames_rendered = 0;
  int width_px = 0;
  int height_px = 0;
  double mean_e2d_px = std::numeric_limits<double>::quiet_NaN();
  std::string video_path;
  std::vector<std::string> png_paths;
};

// Draws the source's frames in the range and writes the video and PNGs.
EpisodeSummary RenderEpisode(FrameSource& source, EpisodeRenderer& renderer,
                             const EpisodeOutputOptions& output);

// What a replay shows: the bundle's ground truth (true cameras and poses),
// or the view's fit (`mimic2d fit`'s estimated cameras and poses: how well
// the fit explains the 2D).
enum class ReplayedMotion { kTruth, kEstimate };

// Kinematic replay of a bundle view. From the truth: each frame puts the
// character in the ground-truth pose when the bundle's poses belong to the
// character's skeleton; otherwise the scene is drawn without the character
// and the ground-truth 3D keypoints (if any) are projected instead. From the
// estimate: the fitted pose under the fitted camera.
class BundleReplaySource : public FrameSource {
 public:
  BundleReplaySource(const ReferenceBundle& bundle, int view_index,
                     std::shared_ptr<const Character> character,
                     const SimulationOptions& simulation,
                     ReplayedMotion motion = ReplayedMotion::kTruth);
  bool Next(EpisodeFrame* frame) override;
  bool shows_character() const { return shows_character_; }

 private:
  const ReferenceBundle& bundle_;
  const ReferenceView& view_;
  const ViewEstimate* estimate_ = nullptr;  // replaying the fit
  Simulation simulation_;
  bool shows_character_ = false;
  int next_frame_ = 0;
};

struct BundleReplayOptions {
  std::string character_config;  // e.g. assets/characters/humanoid.yaml
  std::string scene = "flat";
  std::string view;  // view name; empty: the first view
  ReplayedMotion motion = ReplayedMotion::kTruth;
  // The recording the view's 2D came from, shown beside the render
  // (SourceVideoFrames); empty: none. `source_video_start_s`: the time in
  // it of the clip's frame 0.
  std::string source_video;
  double source_video_start_s = 0.0;
  EpisodeRenderOptions render;
  EpisodeOutputOptions output;
};

// Draws `frames` of a view whose 2D is `clip` at `fps` and writes the
// outputs of `options`, with the recording beside them when
// `options.source_video` is set: the shared tail of a replay and a rollout.
EpisodeSummary RenderViewFrames(FrameSource& frames,
                                std::shared_ptr<const Character> character,
                                const SimulationOptions& simulation,
                                const Clip2D& clip, double fps,
                                EpisodeRenderOptions render,
                                const BundleReplayOptions& options);

// Replays `bundle` kinematically (BundleReplaySource) and writes the
// outputs; the one call for `mimic2d render` and the demo.
EpisodeSummary RenderBundleReplay(const ReferenceBundle& bundle,
                                  const BundleReplayOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_EPISODE_RENDERER_H_
