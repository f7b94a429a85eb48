// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_TRAINING_PLOT_H_
#define MIMIC2D_RENDER_TRAINING_PLOT_H_

#include <map>
#include <string>
#include <vector>

namespace m2d {

// Columns a training log must have (the trainer writes more; see
// docs/rendering.md for the full schema).
inline constexpr const char* kTrainingLogRequiredColumns[] = {
    "samples", "wall_time_s", "samples_per_s", "mean_return", "succ", "e2d_px"};

// One run's training log as read for plotting (CSV with a header row; not
// rl's TrainingLog, which writes it). Every column is numeric; an empty
// cell or "nan" is a missing value (e.g. Succ between evaluations).
struct TrainingCurves {
  std::string source_path;
  std::string name;                                    // legend label
  std::map<std::string, std::vector<double>> columns;  // one value per row
  int num_rows() const;
};

// Reads and checks a log; InputError naming the file, the line and the
// column of the first problem (missing column, non-number, ragged row).
TrainingCurves ReadTrainingLog(const std::string& csv_path);

struct PlotOptions {
  int width_px = 1400;  // size of each PNG
  int height_px = 900;
  std::string gnuplot_binary = "gnuplot";
  void Validate() const;  // throws ConfigError
};

struct PlotFiles {
  std::string vs_samples_png;    // return, Succ, E2D, samples/s vs samples
  std::string vs_wall_time_png;  // the same against wall-clock time
};

// Draws the curves of one or more runs (one line per run) with gnuplot's
// pngcairo terminal into `output_folder`/curves_vs_samples.png and
// curves_vs_wall_time.png (written atomically). Throws std::runtime_error
// with gnuplot's message when it fails.
PlotFiles PlotTrainingCurves(const std::vector<TrainingCurves>& logs,
                             const std::string& output_folder,
                             const PlotOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_TRAINING_PLOT_H_
