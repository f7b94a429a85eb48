// cli: `mimic2d demo` — the one entry point that shows the pipeline on data
// present after setup (Debian's CMU capture), with nothing downloaded.
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"

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
  std::cout << "[1/1] 3D capture -> 4-view 2D reference bundle\n";
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
