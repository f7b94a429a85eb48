// cli: `mimic2d demo` — the one entry point that shows the pipeline on data
// present after setup (Debian's CMU capture), with nothing downloaded; and,
// when the DeepMimic walk is next to the repository, the committed walk
// policy tracking it (no training needed).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "cli/policy_runs.h"
#include "common/error.h"
#include "render/episode_renderer.h"
#include "render/report.h"

namespace m2d::cli {
namespace {

struct DemoArgs {
  std::string motion = "/usr/share/assimp/models/BVH/01_01.bvh";
  std::string output_dir = "out/demo";
  // The walk the committed policy was trained on (DeepMimic, MIT licence,
  // carried with its LICENSE under assets/motions/deepmimic/).
  std::string walk_motion = AssetPath("motions/deepmimic/humanoid3d_walk.txt");
  std::string walk_policy = AssetPath("policies/walk/checkpoint.pt");
};

// The committed walk policy on the bundle it was trained on, made exactly
// as configs/walk.yaml says: eval table on stdout and a video of one view.
// Returns the video's path ("" when skipped).
std::string RunWalkPolicy(const DemoArgs& args) {
  if (!std::filesystem::exists(args.walk_policy)) {
    throw InputError(args.walk_policy, "committed walk policy not found");
  }
  if (!std::filesystem::exists(args.walk_motion)) {
    std::cout << "skipped: the walk policy needs the DeepMimic walk at "
              << args.walk_motion << " (pass --walk-motion)\n";
    return "";
  }
  MotionSourceArgs source;
  source.path = args.walk_motion;
  LoadedMotion loaded = LoadMotionSource(source);
  BundleFromMotionOptions options;
  options.duration_s = 20.0;
  options.follow = CameraFollow::kRootDolly;
  ReferenceBundle bundle = MakeBundleFromMotion(
      loaded.motion, loaded.keypoint_map, options,
      std::filesystem::path(args.walk_motion).stem().string());
  const std::string bundle_path = args.output_dir + "/walk_bundle.json";
  WriteBundle(bundle_path, bundle);

  EvalOptions eval;  // 4 ten-second episodes per view
  std::cout << "policy " << args.walk_policy << ", " << eval.episodes_per_view
            << " episodes of " << eval.episode_s << " s per view:\n";
  CheckpointEvaluation evaluation =
      EvaluateCheckpoint(args.walk_policy, {bundle_path}, eval);
  PrintEvalTable(evaluation);
  WriteEvalJson(args.output_dir + "/walk_eval.json", args.walk_policy, eval,
                evaluation);

  BundleReplayOptions replay;
  replay.character_config = AssetPath("characters/humanoid.yaml");
  replay.view = bundle.views[1].name;  // a side view: the gait is visible
  replay.render.scale = 0.5;
  replay.render.shadows = false;
  replay.output.video_path = args.output_dir + "/walk_policy.mp4";
  EpisodeSummary video = RenderCheckpointRollout(
      args.walk_policy, bundle, replay, /*start_frame=*/0, eval.episode_s);
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
  std::cout << "[2/3] committed walk policy, tracking the walk from 2D\n";
  const std::string walk_video = RunWalkPolicy(args);

  std::cout << "[3/3] videos and report\n";
  BundleReplayOptions replay;
  replay.character_config = AssetPath("characters/humanoid.yaml");
  replay.render.scale = 0.5;
  replay.render.shadows = false;
  replay.output.video_path = args.output_dir + "/reference.mp4";
  replay.output.last_frame = std::min(bundle.num_frames(), 150) - 1;
  EpisodeSummary video = RenderBundleReplay(bundle, replay);
  ReportContents report;
  report.title = "mimic2d demo: " + bundle.name;
  report.video_paths = {video.video_path};
  if (!walk_video.empty()) report.video_paths.push_back(walk_video);
  std::string report_path = args.output_dir + "/report.html";
  WriteReport(report_path, report);
  std::cout << "video:  " << video.video_path << " (" << video.frames_rendered
            << " frames, " << video.width_px << "x" << video.height_px << ")\n";
  if (!walk_video.empty()) std::cout << "video:  " << walk_video << "\n";
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
                   "DeepMimic walk the committed walk policy tracks (absent: "
                   "that step is skipped)")
      ->capture_default_str();
  demo->add_option("--walk-policy", args->walk_policy, "Walk policy checkpoint")
      ->capture_default_str();
  demo->callback([run, args] { *run = [args] { return RunDemo(*args); }; });
}

}  // namespace m2d::cli
