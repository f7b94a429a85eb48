// cli: `mimic2d demo` — the one entry point that shows the pipeline on data
// present after setup, with nothing downloaded: Debian's CMU capture as a
// 2D bundle, and the DeepMimic walk (in the repository) from 2D only:
// strip, fit, and the committed walk2d policy tracking it in simulation.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "cli/policy_runs.h"
#include "common/error.h"
#include "fit/fit.h"
#include "render/episode_renderer.h"
#include "render/report.h"
#include "sim/simulation.h"

namespace m2d::cli {
namespace {

struct DemoArgs {
  std::string motion = "/usr/share/assimp/models/BVH/01_01.bvh";
  std::string output_dir = "out/demo";
  // The walk the committed policy was trained on (DeepMimic, MIT licence,
  // carried with its LICENSE under assets/motions/deepmimic/).
  std::string walk_motion = AssetPath("motions/deepmimic/humanoid3d_walk.txt");
  // Learned from 2D only (configs/walk2d.yaml).
  std::string walk_policy = AssetPath("policies/walk2d/checkpoint.pt");
  double walk_seconds = 8.0;  // of the walk, per view
  int walk_views = 2;
};

// The 2D-only loop on the walk, as a user with videos would run it: the
// walk seen by following cameras, stripped to its 2D (no 3D, no cameras),
// fitted (cameras and starts from the 2D), then the committed walk2d policy
// (trained the same way, configs/walk2d.yaml) tracking it in simulation:
// eval table (E3D against the truth the policy never saw) and a video.
// Returns the video's path.
std::string RunWalkPolicy(const DemoArgs& args) {
  if (!std::filesystem::exists(args.walk_policy)) {
    throw InputError(args.walk_policy, "committed walk policy not found");
  }
  MotionSourceArgs source;
  source.path = args.walk_motion;
  LoadedMotion loaded = LoadMotionSource(source);
  BundleFromMotionOptions options;
  options.duration_s = args.walk_seconds;
  options.rig.num_views = args.walk_views;
  options.follow = CameraFollow::kRootDolly;
  const ReferenceBundle bundle = MakeBundleFromMotion(
      loaded.motion, loaded.keypoint_map, options,
      std::filesystem::path(args.walk_motion).stem().string());
  const std::string truth_path = args.output_dir + "/walk_truth.json";
  WriteBundle(truth_path, bundle);

  // What a user has: the 2D of each view. Then the fit (the rig's focal
  // length is known, as a calibrated camera's would be).
  const ReferenceBundle stripped = StripBundle(bundle);
  auto character = LoadCharacterForSimulation(
      AssetPath("characters/humanoid.yaml"), "flat", SimulationOptions());
  FitOptions fit;
  fit.camera_motion = CameraMotion::kMoving;
  fit.fixed_focal_px = options.rig.focal_px;
  fit.num_threads = 2;
  std::cout << "  fitting " << stripped.views.size() << " views of "
            << stripped.num_frames() << " frames from their 2D alone\n";
  const ReferenceBundle fitted =
      FitBundle(stripped, *character, fit, truth_path + " (2D only)",
                [&](int view, const ViewEstimate& estimate) {
                  std::cout << "  view " << stripped.views[view].name << ": "
                            << estimate.summary.BriefReport();
                });
  const std::string fitted_path = args.output_dir + "/walk_fitted.json";
  WriteBundle(fitted_path, fitted);

  EvalOptions eval;
  eval.episodes_per_view = 4;
  eval.episode_s = std::min(10.0, args.walk_seconds - 1.0);
  SourceOverrides sources;
  sources.initial_states = InitialStateSource::kEstimate;
  sources.cameras = CameraSource::kEstimate;
  std::cout << "  policy " << args.walk_policy << ", " << eval.episodes_per_view
            << " episodes of " << eval.episode_s << " s per view:\n";
  CheckpointEvaluation evaluation = EvaluateCheckpoint(
      args.walk_policy, {fitted_path}, eval, sources, {truth_path});
  PrintEvalTable(evaluation);
  WriteEvalJson(args.output_dir + "/walk_eval.json", args.walk_policy, eval,
                evaluation);

  // The video shows the longest evaluated rollout (a failed one when no
  // rollout succeeded: the video then shows where it fails).
  std::string view = fitted.views[0].name;
  int start_frame = 0, longest = -1;
  for (const EvalRow& row : evaluation.rows) {
    for (const EvalRollout& rollout : row.rollouts) {
      if (rollout.frames > longest) {
        longest = rollout.frames;
        view = row.view;
        start_frame = rollout.start_frame;
      }
    }
  }
  BundleReplayOptions replay;
  replay.character_config = AssetPath("characters/humanoid.yaml");
  replay.view = view;
  replay.render.scale = 0.5;
  replay.render.pose_label = "character (policy)";
  replay.output.video_path = args.output_dir + "/walk_policy.mp4";
  std::cout << "  video: " << view << " from frame " << start_frame << "\n";
  EpisodeSummary video = RenderCheckpointRollout(
      args.walk_policy, fitted, replay, start_frame, eval.episode_s, sources);
  return video.video_path;
}

int RunDemo(const DemoArgs& args) {
  if (!std::filesystem::exists(args.motion)) {
    throw InputError(args.motion,
                     "demo motion not found (install Debian's "
                     "assimp-testmodels, or pass --motion)");
  }
  std::filesystem::create_directories(args.output_dir);
  std::cout << "[1/3] 3D capture -> 4-view 2D reference bundle\n";
  MotionSourceArgs source;
  source.path = args.motion;
  LoadedMotion loaded = LoadMotionSource(source);
  BundleFromMotionOptions options;
  options.follow = CameraFollow::kRootDolly;
  std::string bundle_path = args.output_dir + "/bundle.json";
  ReferenceBundle bundle =
      MakeBundleFromMotion(loaded.motion, loaded.keypoint_map, options,
                           std::filesystem::path(args.motion).stem().string());
  WriteBundle(bundle_path, bundle);
  PrintBundleSummary(bundle, bundle_path);

  // The CMU skeleton has no MuJoCo character: the video shows the floor
  // from the first view's camera with the 2D reference (green) and the
  // projected 3D truth (red) drawn over it.
  std::cout << "[2/3] the walk from 2D only: strip -> fit -> the committed "
               "walk2d policy in simulation\n";
  const std::string walk_video = RunWalkPolicy(args);

  std::cout << "[3/3] videos and report\n";
  BundleReplayOptions replay;
  replay.character_config = AssetPath("characters/humanoid.yaml");
  replay.render.scale = 0.5;
  replay.output.video_path = args.output_dir + "/reference.mp4";
  replay.output.last_frame = std::min(bundle.num_frames(), 150) - 1;
  EpisodeSummary video = RenderBundleReplay(bundle, replay);
  ReportContents report;
  report.title = "mimic2d demo: " + bundle.name;
  report.video_paths = {video.video_path};
  report.video_paths.push_back(walk_video);
  report.eval = ReadEvalTable(args.output_dir + "/walk_eval.json");
  std::string report_path = args.output_dir + "/report.html";
  WriteReport(report_path, report);
  std::cout << "video:  " << video.video_path << " (" << video.frames_rendered
            << " frames, " << video.width_px << "x" << video.height_px << ")\n";
  std::cout << "video:  " << walk_video << "\n";
  std::cout << "report: " << report_path << "\n";
  return 0;
}

}  // namespace

void AddDemoCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* demo =
      app.add_subcommand("demo",
                         "Run the pipeline on the embedded default (CMU "
                         "capture from assimp-testmodels)");
  demo->add_option("--motion", args->motion, "3D motion to use")
      ->capture_default_str();
  demo->add_option("-o,--output-dir", args->output_dir, "Where outputs go")
      ->capture_default_str();
  demo->add_option("--walk-motion", args->walk_motion,
                   "DeepMimic walk the walk policy tracks")
      ->capture_default_str();
  demo->add_option("--walk-policy", args->walk_policy,
                   "Walk policy checkpoint (learned from 2D only)")
      ->capture_default_str();
  demo->add_option("--walk-seconds", args->walk_seconds,
                   "Seconds of the walk, fitted and tracked")
      ->check(CLI::Range(3.0, 20.0))
      ->capture_default_str();
  demo->add_option("--walk-views", args->walk_views, "Views of the walk")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  demo->callback([run, args] { *run = [args] { return RunDemo(*args); }; });
}

}  // namespace m2d::cli
