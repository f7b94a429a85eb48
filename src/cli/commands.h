// cli: the `mimic2d` front end. Each file adds one subcommand; settings are
// parsed here, at the edge, into the typed Options structs of the library.
#ifndef MIMIC2D_CLI_COMMANDS_H_
#define MIMIC2D_CLI_COMMANDS_H_

#include <CLI/CLI.hpp>
#include <functional>

namespace m2d::cli {

// A subcommand's body; returns the process exit code.
using CommandRun = std::function<int()>;

// Each registers its subcommand on `app` and stores its body in `*run`.
void AddClipCommand(CLI::App& app, CommandRun* run);
void AddDemoCommand(CLI::App& app, CommandRun* run);
void AddRenderCommand(CLI::App& app, CommandRun* run);
void AddPlotCommand(CLI::App& app, CommandRun* run);
void AddReportCommand(CLI::App& app, CommandRun* run);
void AddTrainCommand(CLI::App& app, CommandRun* run);
// `checkpoint slim`.
void AddCheckpointCommand(CLI::App& app, CommandRun* run);
void AddEvalCommand(CLI::App& app, CommandRun* run);
void AddFitCommand(CLI::App& app, CommandRun* run);
void AddPriorCommand(CLI::App& app, CommandRun* run);
void AddKeypointsCommand(CLI::App& app, CommandRun* run);
void AddBenchCommand(CLI::App& app, CommandRun* run);
// `gen train` and `generate`.
void AddGenCommands(CLI::App& app, CommandRun* run);
// `bench train`, registered by AddBenchCommand on its `bench` subcommand.
void AddBenchTrainSubcommand(CLI::App* bench, CommandRun* run);
// `bench fit`, likewise.
void AddBenchFitSubcommand(CLI::App* bench, CommandRun* run);

// Where assets/ lives: $MIMIC2D_ASSETS, else the source tree's assets/.
std::string AssetPath(const std::string& relative);
// A path given on the command line for an asset: as is when absolute, else
// relative to assets/ (e.g. --character characters/humanoid.yaml).
std::string AssetArgumentPath(const std::string& argument);

// A check for an output file's option: the command line is refused, before
// any work, when no file could be written at the path (the option and the
// problem named; common/file_io.h's WritableFileProblem).
const CLI::Validator& WritableFile();

}  // namespace m2d::cli

#endif  // MIMIC2D_CLI_COMMANDS_H_
