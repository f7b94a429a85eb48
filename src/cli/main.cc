// cli: entry point. Parses the command line, runs one subcommand, and turns
// every input error into a one-line message and a non-zero exit.
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iostream>

#include "cli/commands.h"
#include "common/blas_kernels.h"
#include "common/error.h"

namespace m2d::cli {

std::string AssetPath(const std::string& relative) {
  const char* override_dir = std::getenv("MIMIC2D_ASSETS");
  std::string base = override_dir != nullptr
                         ? std::string(override_dir)
                         : std::string(MIMIC2D_SOURCE_DIR) + "/assets";
  return base + "/" + relative;
}

}  // namespace m2d::cli

int main(int argc, char** argv) {
  // May restart the program once, before anything else happens.
  m2d::UseFastestBlasKernels(argv);
  CLI::App app{
      "mimic2d: learn physics-based character controllers from 2D keypoints"};
  app.require_subcommand(1);
  m2d::cli::CommandRun run;
  m2d::cli::AddClipCommand(app, &run);
  m2d::cli::AddDemoCommand(app, &run);
  m2d::cli::AddRenderCommand(app, &run);
  m2d::cli::AddPlotCommand(app, &run);
  m2d::cli::AddReportCommand(app, &run);
  m2d::cli::AddTrainCommand(app, &run);
  m2d::cli::AddEvalCommand(app, &run);
  m2d::cli::AddFitCommand(app, &run);
  m2d::cli::AddBenchCommand(app, &run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return run ? run() : 1;
  } catch (const m2d::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const m2d::ConfigError& e) {
    std::cerr << "error: invalid setting: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
