// eval: the fit accuracy table (`mimic2d bench fit`, docs/fit.md "Accuracy
// table"): DeepMimic clips rendered into synthetic bundles under a few camera
// settings, clean and with detector noise; each view fitted from its 2D
// alone (fit/fit.h) and measured against the truth (eval/fit_accuracy.h).
#ifndef MIMIC2D_EVAL_FIT_BENCHMARK_H_
#define MIMIC2D_EVAL_FIT_BENCHMARK_H_

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/fit_accuracy.h"
#include "fit/fit.h"
#include "motion/bundle.h"

namespace m2d {

class Character;

// How the synthetic views are filmed, and the camera model the fit assumes.
struct FitCameraSetting {
  std::string name;  // short label in the table ("A")
  std::string description;
  CameraFollow follow = CameraFollow::kStatic;
  CameraMotion fit_camera = CameraMotion::kStatic;
  double elevation_deg = 10.0;
  double distance_m = 4.5;
  double focal_px = 1000.0;
};

// A: a static rig, elevation 10 deg, 4.5 m, focal 1000 px, fitted static.
// B: cameras dollying with the subject (CameraFollow::kRootDolly), elevation
// 25 deg, 6 m, focal 1500 px, fitted as moving.
std::vector<FitCameraSetting> DefaultFitCameraSettings();

struct FitBenchmarkOptions {
  // Folder holding humanoid3d_<clip>.txt (DeepMimic).
  std::string motion_dir;
  std::vector<std::string> clips{"walk", "run", "jump", "kick", "dance_a"};
  std::vector<FitCameraSetting> settings = DefaultFitCameraSettings();
  bool clean = true;  // measure clean keypoints
  bool noisy = true;  // and keypoints with `noise`
  DetectorNoiseOptions noise{4.0, 0.05, 0.0, 11};
  int num_views = 2;            // rig views per bundle, each fitted on its own
  double max_duration_s = 4.0;  // clips longer than this are cut
  // > 0: a looping clip (DeepMimic "wrap") shorter than this is repeated to
  // at least this long, cut at max_duration_s; a clip that does not loop
  // keeps its own length. A video is seconds long, a DeepMimic cycle 0.8-
  // 1.8 s: under a following camera the clip's travel is what shows the
  // ground (docs/fit.md, "Clip length under a following camera").
  double min_duration_s = 0.0;
  int num_threads = 1;  // Ceres threads per fit
  FitOptions fit;  // every fit's settings (camera model and threads: above)
  // Also refine each view from its true camera and poses (fit/fit.h's
  // RefineView, hinges clamped to their ranges): where the objective's own
  // minimum near the truth lies, and whether the fit missed a lower cost.
  bool from_truth = false;
  // Called with a line before each fit and after it (empty: silent).
  std::function<void(const std::string& line)> progress;

  // The CLI's --quick: the walk, clean, setting A, one view.
  void MakeQuick();
  // Throws ConfigError: no clips or settings, neither clean nor noisy,
  // views < 1, threads < 1, a non-positive duration, a clip without its
  // file (naming the clip and the clips that exist).
  void Validate() const;
  std::string MotionPath(const std::string& clip) const;
};

// One (clip, setting, noise) combination, averaged over its views.
struct FitBenchmarkRow {
  std::string clip;
  std::string setting;
  bool noisy = false;
  int num_frames = 0;
  std::vector<FitAccuracy> views;       // the views whose fit returned
  std::vector<FitAccuracy> from_truth;  // with from_truth: per view
  std::vector<std::string> errors;      // views whose fit threw: the message
  FitAccuracy mean;                     // over `views`
};

struct FitBenchmarkResult {
  std::vector<FitBenchmarkRow> rows;
  // Means over every row's views: all, clean only, noisy only.
  FitAccuracy all, all_clean, all_noisy;
  int num_fits = 0, num_failed_fits = 0;
  double wall_seconds = 0.0;
  // With from_truth: the truth-started refinements' means, and the fits
  // that ended more than 5 % above the refinement's cost (the search
  // missed a better minimum of the same objective).
  FitAccuracy from_truth;
  int num_search_misses = 0;
};

// One clip's synthetic bundle under one setting: the clip at its own
// length (a looping one repeated to options.min_duration_s), cut at
// options.max_duration_s, seen by options.num_views views, with
// options.noise when `noisy`.
ReferenceBundle MakeBenchmarkBundle(const Motion3D& motion,
                                    const Character& character,
                                    const FitBenchmarkOptions& options,
                                    const FitCameraSetting& setting, bool noisy,
                                    const std::string& name);

// Runs the table. The fit reads only each view's 2D clip; the truth is read
// by the measurement alone. A fit that throws (input it cannot use) is
// recorded in its row's `errors` and the run goes on.
FitBenchmarkResult RunFitBenchmark(const Character& character,
                                   const FitBenchmarkOptions& options);

// A fixed-width text table (one row per combination, then the means; with
// from_truth, a line on the truth-started refinements).
std::string FormatFitBenchmarkTable(const FitBenchmarkResult& result);
// The same as a markdown table (docs/fit.md).
std::string FormatFitBenchmarkMarkdown(const FitBenchmarkResult& result);
// Settings, every view's figures, the rows' means and the overall means.
nlohmann::json FitBenchmarkToJson(const FitBenchmarkResult& result,
                                  const FitBenchmarkOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_FIT_BENCHMARK_H_
