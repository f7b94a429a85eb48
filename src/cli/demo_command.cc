// cli: `mimic2d demo` — the one entry point that shows the pipeline on data
// present after setup (Debian's CMU capture), with nothing downloaded.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"
#include "render/episode_renderer.h"
#include "render/report.h"

namespace m2d::cli {
namespace {

struct DemoArgs {
  std::string motion = "/usr/share/assimp/models/BVH/01_01.bvh";
  std::string output_dir = "out/demo";
};

int RunDemo(const DemoArgs& args) {
  if (!std::filesystem::exists(args.motion)) {
    throw InputError(args.motion,
                     "demo motion not found (install Debian's "
                     "assimp-testmodels, or pass --motion)");
  }
  std::filesystem::create_directories(args.output_dir);
  std::cout << "[1/2] 3D capture -> 4-view 2D reference bundle\n";
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
  std::cout << "[2/2] video and report\n";
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
  std::string report_path = args.output_dir + "/report.html";
  WriteReport(report_path, report);
  std::cout << "video:  " << video.video_path << " (" << video.frames_rendered
            << " frames, " << video.width_px << "x" << video.height_px << ")\n"
            << "report: " << report_path << "\n";
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
  demo->callback([run, args] { *run = [args] { return RunDemo(*args); }; });
}

}  // namespace m2d::cli
