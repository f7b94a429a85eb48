// cli: `mimic2d report` — one self-contained HTML page with a run's
// evaluation table, training curves and videos.
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "media/subprocess.h"
#include "render/report.h"
#include "render/training_plot.h"

namespace m2d::cli {
namespace {

struct ReportArgs {
  std::string output;
  std::string title = "mimic2d run";
  std::string eval;
  std::vector<std::string> logs;
  std::vector<std::string> images;
  std::vector<std::string> videos;
};

int RunReport(const ReportArgs& args) {
  ReportContents contents;
  contents.title = args.title;
  if (!args.eval.empty()) contents.eval = ReadEvalTable(args.eval);
  // Curves from the logs are drawn into a scratch folder and embedded.
  ScopedTempFolder scratch("mimic2d_report");
  if (!args.logs.empty()) {
    std::vector<TrainingCurves> logs;
    for (const std::string& path : args.logs) {
      logs.push_back(ReadTrainingLog(path));
    }
    const PlotFiles curves =
        PlotTrainingCurves(logs, scratch.path(), PlotOptions());
    contents.image_paths = {curves.vs_samples_png, curves.vs_wall_time_png};
  }
  contents.image_paths.insert(contents.image_paths.end(), args.images.begin(),
                              args.images.end());
  contents.video_paths = args.videos;
  WriteReport(args.output, contents);
  std::cout << "report: " << args.output << "\n";
  return 0;
}

}  // namespace

void AddReportCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* report = app.add_subcommand(
      "report",
      "One self-contained HTML page (opens offline) with the evaluation "
      "table, training curves and videos of a run");
  report->add_option("-o,--output", args->output, "HTML file to write")
      ->check(WritableFile())
      ->required();
  report->add_option("--title", args->title, "Page title")
      ->capture_default_str();
  report->add_option("--eval", args->eval,
                     "Evaluation JSON ({\"rows\": [...]}, docs/rendering.md)");
  report->add_option("--log", args->logs,
                     "Training CSV log(s): their curves are embedded");
  report->add_option("--image", args->images, "Extra images to embed");
  report->add_option("--video", args->videos, "Videos (MP4) to embed");
  report->callback([run, args] { *run = [args] { return RunReport(*args); }; });
}

}  // namespace m2d::cli
