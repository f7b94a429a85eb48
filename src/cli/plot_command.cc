// cli: `mimic2d plot` — training curves from the trainer's CSV logs.
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "render/training_plot.h"

namespace m2d::cli {
namespace {

struct PlotArgs {
  std::vector<std::string> logs;
  std::string output_folder = ".";
  PlotOptions options;
};

int RunPlot(const PlotArgs& args) {
  std::vector<TrainingCurves> logs;
  for (const std::string& path : args.logs)
    logs.push_back(ReadTrainingLog(path));
  const PlotFiles files =
      PlotTrainingCurves(logs, args.output_folder, args.options);
  std::cout << "curves vs samples:   " << files.vs_samples_png << "\n"
            << "curves vs wall time: " << files.vs_wall_time_png << "\n";
  return 0;
}

}  // namespace

void AddPlotCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<PlotArgs>();
  CLI::App* plot = app.add_subcommand(
      "plot",
      "Training curves (return, Succ, E2D, samples/s) against samples and "
      "wall time, one line per log, as two PNG files");
  plot->add_option("logs", args->logs, "Training CSV logs")->required();
  plot->add_option("-o,--output-dir", args->output_folder,
                   "Where curves_vs_samples.png and curves_vs_wall_time.png "
                   "go")
      ->capture_default_str();
  plot->add_option("--width", args->options.width_px, "PNG width (px)")
      ->capture_default_str();
  plot->add_option("--height", args->options.height_px, "PNG height (px)")
      ->capture_default_str();
  plot->callback([run, args] { *run = [args] { return RunPlot(*args); }; });
}

}  // namespace m2d::cli
