// cli: entry point. Parses the command line, runs one subcommand, and turns
// every input error into a one-line message and a non-zero exit.
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iostream>
#include <new>

#include "cli/commands.h"
#include "common/blas_kernels.h"
#include "common/error.h"
#include "common/file_io.h"

namespace m2d::cli {

std::string AssetPath(const std::string& relative) {
  const char* override_dir = std::getenv("MIMIC2D_ASSETS");
  std::string base = override_dir != nullptr
                         ? std::string(override_dir)
                         : std::string(MIMIC2D_SOURCE_DIR) + "/assets";
  return base + "/" + relative;
}

std::string AssetArgumentPath(const std::string& argument) {
  return !argument.empty() && argument[0] == '/' ? argument
                                                 : AssetPath(argument);
}

const CLI::Validator& WritableFile() {
  static const CLI::Validator validator(
      [](std::string& path) {
        const std::string problem = WritableFileProblem(path);
        return problem.empty() ? problem
                               : "cannot write " + path + ": " + problem;
      },
      "FILE", "WritableFile");
  return validator;
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
  m2d::cli::AddCheckpointCommand(app, &run);
  m2d::cli::AddEvalCommand(app, &run);
  m2d::cli::AddFitCommand(app, &run);
  m2d::cli::AddPriorCommand(app, &run);
  m2d::cli::AddKeypointsCommand(app, &run);
  m2d::cli::AddBenchCommand(app, &run);
  m2d::cli::AddGenCommands(app, &run);
  // No command, or one that does not exist: say so and list the commands
  // (CLI11 alone says "A subcommand is required" for both).
  std::string commands;
  for (const CLI::App* command : app.get_subcommands({})) {
    commands += (commands.empty() ? "" : ", ") + command->get_name();
  }
  if (argc < 2) {
    std::cerr << "error: no command given; commands: " << commands
              << " (mimic2d COMMAND --help for one)\n";
    return 2;
  }
  const std::string first = argv[1];
  bool known = false;
  for (const CLI::App* command : app.get_subcommands({}))
    known = known || command->check_name(first);
  if (first.empty() || (first[0] != '-' && !known)) {
    std::cerr << "error: unknown command '" << first
              << "'; commands: " << commands
              << " (mimic2d COMMAND --help for one)\n";
    return 2;
  }
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
  } catch (const std::bad_alloc&) {
    std::cerr << "error: out of memory (a setting or input far larger than "
                 "this machine can hold?)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
