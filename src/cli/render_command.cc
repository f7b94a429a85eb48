// cli: `mimic2d render` — a video of an episode from the reference camera,
// with the 2D reference and the character's projected keypoints drawn over.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/policy_runs.h"
#include "common/error.h"
#include "env/reference.h"
#include "motion/bundle.h"
#include "render/episode_renderer.h"

namespace m2d::cli {
namespace {

struct RenderArgs {
  std::string bundle;
  BundleReplayOptions replay;
  bool no_shadows = false;
  std::string policy;       // checkpoint; empty: kinematic replay
  int start_frame = 0;      // policy rollouts start here
  double episode_s = 10.0;  // and last at most this long
  std::string starts;       // policy rollouts: "" = the checkpoint's config
  std::string cameras;      // likewise
};

int RunRender(RenderArgs& args) {
  args.replay.render.shadows = !args.no_shadows;
  const ReferenceBundle bundle = ReadBundle(args.bundle);
  SourceOverrides sources;
  if (!args.starts.empty())
    sources.initial_states = ParseInitialStateSource(args.starts);
  if (!args.cameras.empty()) sources.cameras = ParseCameraSource(args.cameras);
  EpisodeSummary summary;
  try {
    summary = args.policy.empty()
                  ? RenderBundleReplay(bundle, args.replay)
                  : RenderCheckpointRollout(args.policy, bundle, args.replay,
                                            args.start_frame, args.episode_s,
                                            sources);
  } catch (const InputError& e) {
    // The library names the bundle; the user needs the file.
    if (e.source() != bundle.name) throw;
    throw InputError(args.bundle + " (" + bundle.name + ")", e.problem());
  }
  std::cout << "rendered " << summary.frames_rendered << " frames, "
            << summary.width_px << "x" << summary.height_px << " px";
  if (std::isfinite(summary.mean_e2d_px)) {
    std::cout << ", mean E2D " << std::fixed << std::setprecision(2)
              << summary.mean_e2d_px << " px";
  }
  std::cout << "\n";
  if (!summary.video_path.empty()) {
    std::cout << "video: " << summary.video_path << "\n";
  }
  if (!summary.png_paths.empty()) {
    std::cout << "frames: " << args.replay.output.png_folder << " ("
              << summary.png_paths.size() << " PNG files)\n";
  }
  return 0;
}

}  // namespace

void AddRenderCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<RenderArgs>();
  args->replay.character_config = AssetPath("characters/humanoid.yaml");
  CLI::App* render = app.add_subcommand(
      "render",
      "Roll out a policy (--policy) or replay a reference bundle kinematically "
      "and write an MP4 (and/or "
      "PNG frames) from a view's camera, with the 2D reference (green) and "
      "the character's projected keypoints (red) drawn over");
  render->add_option("bundle", args->bundle, "Reference bundle (JSON)")
      ->required();
  render
      ->add_option("-o,--output", args->replay.output.video_path,
                   "MP4 file to write")
      ->check(WritableFile());
  render->add_option("--png-dir", args->replay.output.png_folder,
                     "Also write every frame as frame_<n>.png here");
  render->add_flag_function(
      "--estimate",
      [args](int64_t) { args->replay.motion = ReplayedMotion::kEstimate; },
      "Replay the fit's estimate (its cameras and poses, mimic2d fit) "
      "instead of the ground truth: how well the fit explains the 2D");
  render->add_option("--view", args->replay.view,
                     "View (camera) name; default: the first view");
  render
      ->add_option("--character", args->replay.character_config,
                   "Character config (YAML)")
      ->capture_default_str();
  render->add_option("--scene", args->replay.scene, "Scene of the character")
      ->capture_default_str();
  render
      ->add_option("--scale", args->replay.render.scale,
                   "Output size relative to the clip's image size")
      ->capture_default_str();
  render->add_flag("--side-camera", args->replay.render.side_camera,
                   "Add a free camera panel on the right");
  render
      ->add_option("--side-azimuth", args->replay.render.side.azimuth_deg,
                   "Free camera azimuth (deg; 90 looks along +y)")
      ->capture_default_str();
  render
      ->add_option("--side-elevation", args->replay.render.side.elevation_deg,
                   "Free camera elevation (deg, negative looks down)")
      ->capture_default_str();
  render
      ->add_option("--side-distance", args->replay.render.side.distance_m,
                   "Free camera distance (m)")
      ->capture_default_str();
  render
      ->add_option("--side-fovy", args->replay.render.side.fovy_deg,
                   "Free camera vertical field of view (deg)")
      ->capture_default_str();
  render
      ->add_option("--first-frame", args->replay.output.first_frame,
                   "First frame to draw (0-based)")
      ->capture_default_str();
  render
      ->add_option("--last-frame", args->replay.output.last_frame,
                   "Last frame to draw (inclusive; -1: the last)")
      ->capture_default_str();
  render
      ->add_option("--crf", args->replay.output.video.crf,
                   "H.264 quality (0 lossless .. 51 worst)")
      ->capture_default_str();
  render->add_option(
      "--policy", args->policy,
      "Roll out this checkpoint instead of replaying the bundle");
  render
      ->add_option("--start-frame", args->start_frame,
                   "Policy rollout: first reference frame")
      ->capture_default_str();
  render
      ->add_option("--episode-s", args->episode_s,
                   "Policy rollout: longest episode (s)")
      ->capture_default_str();
  render
      ->add_option("--starts", args->starts,
                   "Policy rollout: initial states from truth, estimate or "
                   "default (default: the checkpoint's config)")
      ->check(CLI::IsMember({"truth", "estimate", "default"}));
  render
      ->add_option("--cameras", args->cameras,
                   "Policy rollout: cameras from truth or estimate (default: "
                   "the checkpoint's config)")
      ->check(CLI::IsMember({"truth", "estimate"}));
  render
      ->add_option("--subject-height",
                   args->replay.render.subject_height_fraction,
                   "Zoom in on the subject until it fills this share of the "
                   "frame height (0: the camera's whole image)")
      ->capture_default_str();
  render
      ->add_option("--max-zoom", args->replay.render.max_zoom,
                   "Largest zoom of that framing")
      ->capture_default_str();
  render->add_option(
      "--beside", args->replay.source_video,
      "The recording the view's 2D came from (e.g. the video given to "
      "keypoints): its frames are drawn on the left under the same framing");
  render
      ->add_option("--beside-start-s", args->replay.source_video_start_s,
                   "Time in that video of the clip's frame 0 (s)")
      ->capture_default_str();
  render->add_flag("--no-shadows", args->no_shadows,
                   "Skip shadows (faster software rendering)");
  render->callback([run, args] { *run = [args] { return RunRender(*args); }; });
}

}  // namespace m2d::cli
