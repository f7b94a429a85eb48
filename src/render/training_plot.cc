#include "render/training_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "common/error.h"
#include "common/file_io.h"
#include "media/subprocess.h"

namespace m2d {
namespace {

struct Metric {
  const char* column;
  const char* title;
};
// The four panels of each figure.
constexpr Metric kMetrics[] = {
    {"mean_return", "mean episode return"},
    {"succ", "Succ (success rate)"},
    {"e2d_px", "E2D (px)"},
    {"samples_per_s", "throughput (samples/s)"},
};

struct TimeAxis {
  double seconds_per_unit = 1.0;
  const char* label = "wall time (s)";
};

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

// A cell as a number: empty or nan is missing (NaN); anything else must
// parse completely.
bool ParseCell(const std::string& cell, double* value) {
  std::string lower = cell;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  if (lower.empty() || lower == "nan") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  char* end = nullptr;
  *value = std::strtod(cell.c_str(), &end);
  return end != cell.c_str() && *end == '\0';
}

// A gnuplot single-quoted string ('' stands for one quote).
std::string Quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text)
    quoted += (c == '\'') ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

// Seconds, minutes or hours, whichever keeps the axis readable.
TimeAxis ChooseTimeAxis(const std::vector<TrainingCurves>& logs) {
  double longest_s = 0.0;
  for (const TrainingCurves& log : logs) {
    for (double t : log.columns.at("wall_time_s")) {
      if (std::isfinite(t)) longest_s = std::max(longest_s, t);
    }
  }
  if (longest_s > 3 * 3600.0) return {3600.0, "wall time (h)"};
  if (longest_s > 600.0) return {60.0, "wall time (min)"};
  return {};
}

// Legend names: file stems, prefixed with their folder where two clash.
std::vector<std::string> LegendNames(const std::vector<TrainingCurves>& logs) {
  std::vector<std::string> names;
  std::multiset<std::string> seen;
  for (const TrainingCurves& log : logs) seen.insert(log.name);
  for (const TrainingCurves& log : logs) {
    std::string name = log.name;
    if (seen.count(name) > 1) {
      const std::string folder = std::filesystem::path(log.source_path)
                                     .parent_path()
                                     .filename()
                                     .string();
      if (!folder.empty()) name = folder + "/" + name;
    }
    names.push_back(name);
  }
  return names;
}

// Writes the finite points of one metric: samples, time, value. Returns the
// number of points.
int WriteSeries(const TrainingCurves& log, const char* column,
                const TimeAxis& time, const std::string& path) {
  std::ofstream out(path);
  out.precision(12);
  const std::vector<double>& samples = log.columns.at("samples");
  const std::vector<double>& wall_s = log.columns.at("wall_time_s");
  const std::vector<double>& values = log.columns.at(column);
  int points = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || !std::isfinite(samples[i]) ||
        !std::isfinite(wall_s[i])) {
      continue;
    }
    out << samples[i] << ' ' << wall_s[i] / time.seconds_per_unit << ' '
        << values[i] << '\n';
    ++points;
  }
  if (!out) throw std::runtime_error("cannot write plot data " + path);
  return points;
}

// One 2x2 figure: each metric against x column 1 (samples) or 2 (time).
std::string FigureScript(const std::vector<std::string>& names,
                         const std::vector<std::vector<std::string>>& series,
                         int x_column, const std::string& x_label,
                         const std::string& title, const std::string& output,
                         const PlotOptions& options) {
  std::ostringstream script;
  script << "set terminal pngcairo noenhanced size " << options.width_px << ","
         << options.height_px << " font 'sans,11'\n"
         << "set output " << Quote(output) << "\n"
         << "set grid\nset key top left\n"
         // Samples in engineering notation (819.2k, 1.6M).
         << (x_column == 1 ? "set format x '%.1s%c'\n" : "")
         << "set multiplot layout 2,2 title " << Quote(title) << "\n";
  for (size_t m = 0; m < std::size(kMetrics); ++m) {
    script << "set title " << Quote(kMetrics[m].title) << "\n"
           << "set xlabel " << Quote(x_label) << "\n";
    std::vector<std::string> plots;
    for (size_t run = 0; run < names.size(); ++run) {
      if (series[run][m].empty()) continue;
      plots.push_back(Quote(series[run][m]) + " using " +
                      std::to_string(x_column) +
                      ":3 with linespoints pointsize 0.4 linewidth 2 title " +
                      Quote(names[run]));
    }
    if (plots.empty()) {
      // No run logged this metric: an empty panel that says so.
      script << "set label 1 'no data' at graph 0.5,0.5 center\n"
             << "plot [0:1] [0:1] -1 notitle\nunset label 1\n";
      continue;
    }
    script << "plot ";
    for (size_t p = 0; p < plots.size(); ++p) {
      script << (p ? ", \\\n     " : "") << plots[p];
    }
    script << "\n";
  }
  script << "unset multiplot\nset output\n";
  return script.str();
}

void RunGnuplot(const std::string& script_path, const PlotOptions& options) {
  ProcessResult result = RunProcess({options.gnuplot_binary, script_path});
  if (!result.ok()) {
    throw std::runtime_error("gnuplot failed (exit code " +
                             std::to_string(result.exit_code) +
                             "): " + result.output);
  }
}

}  // namespace

int TrainingCurves::num_rows() const {
  return columns.empty() ? 0 : static_cast<int>(columns.begin()->second.size());
}

TrainingCurves ReadTrainingLog(const std::string& csv_path) {
  std::istringstream text(ReadFileText(csv_path));
  TrainingCurves log;
  log.source_path = csv_path;
  log.name = std::filesystem::path(csv_path).stem().string();
  std::string line;
  if (!std::getline(text, line)) throw InputError(csv_path, "empty file");
  const std::vector<std::string> header = SplitCsvLine(line);
  for (const char* required : kTrainingLogRequiredColumns) {
    if (std::find(header.begin(), header.end(), required) == header.end()) {
      throw InputError(
          csv_path, std::string("line 1: missing column '") + required + "'");
    }
  }
  std::set<std::string> unique(header.begin(), header.end());
  if (unique.size() != header.size()) {
    throw InputError(csv_path, "line 1: a column name appears twice");
  }
  std::vector<std::vector<double>*> targets;
  for (const std::string& name : header) targets.push_back(&log.columns[name]);
  for (int line_number = 2; std::getline(text, line); ++line_number) {
    if (Trim(line).empty()) continue;
    const std::vector<std::string> cells = SplitCsvLine(line);
    if (cells.size() != header.size()) {
      throw InputError(csv_path, "line " + std::to_string(line_number) + ": " +
                                     std::to_string(cells.size()) +
                                     " cells, the header has " +
                                     std::to_string(header.size()));
    }
    for (size_t c = 0; c < cells.size(); ++c) {
      double value;
      if (!ParseCell(cells[c], &value)) {
        throw InputError(csv_path, "line " + std::to_string(line_number) +
                                       ", column '" + header[c] + "': '" +
                                       cells[c] + "' is not a number");
      }
      targets[c]->push_back(value);
    }
  }
  if (log.num_rows() == 0) throw InputError(csv_path, "no data rows");
  return log;
}

void PlotOptions::Validate() const {
  if (width_px < 200 || height_px < 150 || width_px > 10000 ||
      height_px > 10000) {
    throw ConfigError("plot size must be within 200x150 .. 10000x10000 px");
  }
}

PlotFiles PlotTrainingCurves(const std::vector<TrainingCurves>& logs,
                             const std::string& output_folder,
                             const PlotOptions& options) {
  // Outline: one data file per run and metric (finite points only), one
  // gnuplot script per figure, then move the PNGs into place.
  options.Validate();
  if (logs.empty()) throw ConfigError("plot: no training log given");
  ScopedTempFolder scratch("mimic2d_plot");
  const TimeAxis time = ChooseTimeAxis(logs);
  const std::vector<std::string> names = LegendNames(logs);
  std::vector<std::vector<std::string>> series(logs.size());
  for (size_t run = 0; run < logs.size(); ++run) {
    for (size_t m = 0; m < std::size(kMetrics); ++m) {
      const std::string path = scratch.path() + "/run" + std::to_string(run) +
                               "_" + kMetrics[m].column + ".dat";
      const int points = WriteSeries(logs[run], kMetrics[m].column, time, path);
      series[run].push_back(points > 0 ? path : "");
    }
  }
  PlotFiles files;
  files.vs_samples_png = output_folder + "/curves_vs_samples.png";
  files.vs_wall_time_png = output_folder + "/curves_vs_wall_time.png";
  const struct {
    int x_column;
    std::string x_label, title, output;
  } figures[] = {
      {1, "environment samples", "training curves vs samples",
       files.vs_samples_png},
      {2, time.label, "training curves vs wall-clock time",
       files.vs_wall_time_png},
  };
  for (const auto& figure : figures) {
    const std::string png = scratch.path() + "/figure.png";
    const std::string script = scratch.path() + "/figure.gp";
    WriteFileAtomic(script,
                    FigureScript(names, series, figure.x_column, figure.x_label,
                                 figure.title, png, options));
    RunGnuplot(script, options);
    WriteFileAtomic(figure.output, ReadFileText(png));
  }
  return files;
}

}  // namespace m2d
