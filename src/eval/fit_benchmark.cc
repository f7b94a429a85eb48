#include "eval/fit_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <set>

#include "common/error.h"
#include "motion/motion_io.h"
#include "sim/character.h"

namespace m2d {
namespace {

const char* NoiseName(bool noisy) { return noisy ? "noisy" : "clean"; }

// CPU time of the whole process (every thread), seconds.
double ProcessCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * now.tv_nsec;
}

std::string Format(const char* format, ...)
    __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

// The clips that `motion_dir` holds (humanoid3d_<clip>.txt), sorted.
std::vector<std::string> AvailableClips(const std::string& motion_dir) {
  std::set<std::string> clips;
  std::error_code error;
  for (const auto& entry :
       std::filesystem::directory_iterator(motion_dir, error)) {
    const std::string name = entry.path().filename().string();
    const std::string prefix = "humanoid3d_", suffix = ".txt";
    if (name.size() > prefix.size() + suffix.size() &&
        name.compare(0, prefix.size(), prefix) == 0 &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      clips.insert(name.substr(prefix.size(),
                               name.size() - prefix.size() - suffix.size()));
    }
  }
  return {clips.begin(), clips.end()};
}

nlohmann::json AccuracyJson(const FitAccuracy& a) {
  return {{"num_frames", a.num_frames},
          {"focal_error_pct", a.focal_error_pct},
          {"pitch_error_deg", a.pitch_error_deg},
          {"roll_error_deg", a.roll_error_deg},
          {"focal_px", a.focal_px},
          {"true_focal_px", a.true_focal_px},
          {"pitch_deg", a.pitch_deg},
          {"true_pitch_deg", a.true_pitch_deg},
          {"roll_deg", a.roll_deg},
          {"true_roll_deg", a.true_roll_deg},
          {"root_relative_mpjpe_mm", a.root_relative_mpjpe_mm},
          {"pa_mpjpe_mm", a.pa_mpjpe_mm},
          {"reachable_pa_mpjpe_mm", a.reachable_pa_mpjpe_mm},
          {"mean_reprojection_px", a.mean_reprojection_px},
          {"seconds_per_100_frames", a.seconds_per_100_frames},
          {"cpu_seconds_per_100_frames", a.cpu_seconds_per_100_frames},
          {"unconverged_fraction", a.unconverged_fraction},
          {"final_cost", a.final_cost}};
}

// The rows of a table: label columns, then the figures.
struct TableLine {
  std::string clip, setting, noise, fits;
  int frames = 0;
  FitAccuracy accuracy;
  bool empty = false;  // every fit failed: no figures
};

std::vector<TableLine> TableLines(const FitBenchmarkResult& result) {
  std::vector<TableLine> lines;
  // Fits that returned / fits run: clean, noisy.
  int returned[2] = {0, 0}, run[2] = {0, 0};
  for (const FitBenchmarkRow& row : result.rows) {
    const int total = static_cast<int>(row.views.size() + row.errors.size());
    lines.push_back(
        {row.clip, row.setting, NoiseName(row.noisy),
         std::to_string(row.views.size()) + "/" + std::to_string(total),
         row.num_frames, row.mean, row.views.empty()});
    returned[row.noisy] += static_cast<int>(row.views.size());
    run[row.noisy] += total;
  }
  auto fits = [](int ok, int total) {
    return std::to_string(ok) + "/" + std::to_string(total);
  };
  if (run[0] > 0 && run[1] > 0) {
    lines.push_back({"all", "", "clean", fits(returned[0], run[0]), 0,
                     result.all_clean, returned[0] == 0});
    lines.push_back({"all", "", "noisy", fits(returned[1], run[1]), 0,
                     result.all_noisy, returned[1] == 0});
  }
  lines.push_back({"all", "", "",
                   fits(returned[0] + returned[1], run[0] + run[1]), 0,
                   result.all, returned[0] + returned[1] == 0});
  return lines;
}

}  // namespace

std::vector<FitCameraSetting> DefaultFitCameraSettings() {
  FitCameraSetting a;
  a.name = "A";
  a.description = "static rig, elevation 10 deg, 4.5 m, focal 1000 px";
  a.follow = CameraFollow::kStatic;
  a.fit_camera = CameraMotion::kStatic;
  a.elevation_deg = 10.0;
  a.distance_m = 4.5;
  a.focal_px = 1000.0;
  FitCameraSetting b;
  b.name = "B";
  b.description =
      "cameras dollying with the subject, elevation 25 deg, 6 m, focal 1500 "
      "px; fitted as moving";
  b.follow = CameraFollow::kRootDolly;
  b.fit_camera = CameraMotion::kMoving;
  b.elevation_deg = 25.0;
  b.distance_m = 6.0;
  b.focal_px = 1500.0;
  return {a, b};
}

void FitBenchmarkOptions::MakeQuick() {
  clips = {"walk"};
  settings.resize(1);
  settings[0] = DefaultFitCameraSettings()[0];
  clean = true;
  noisy = false;
  num_views = 1;
}

std::string FitBenchmarkOptions::MotionPath(const std::string& clip) const {
  return (std::filesystem::path(motion_dir) / ("humanoid3d_" + clip + ".txt"))
      .string();
}

void FitBenchmarkOptions::Validate() const {
  if (clips.empty()) throw ConfigError("bench fit: no clips");
  if (settings.empty()) throw ConfigError("bench fit: no camera settings");
  if (!clean && !noisy)
    throw ConfigError("bench fit: neither clean nor noisy keypoints");
  if (num_views < 1) throw ConfigError("bench fit: --views must be >= 1");
  if (num_threads < 1) throw ConfigError("bench fit: --threads must be >= 1");
  if (!(max_duration_s > 0))
    throw ConfigError("bench fit: the clip duration must be positive");
  if (!(min_duration_s >= 0) || min_duration_s > max_duration_s)
    throw ConfigError(
        "bench fit: --min-duration must be within [0, the clip cut at " +
        std::to_string(max_duration_s) + " s]");
  noise.Validate();
  for (const std::string& clip : clips) {
    if (clip.empty() || clip.find('/') != std::string::npos ||
        !std::filesystem::is_regular_file(MotionPath(clip))) {
      std::string known;
      for (const std::string& name : AvailableClips(motion_dir))
        known += (known.empty() ? "" : ", ") + name;
      throw ConfigError(
          "bench fit: unknown clip '" + clip + "' (no " + MotionPath(clip) +
          "; clips there: " + (known.empty() ? "none" : known) + ")");
    }
  }
}

ReferenceBundle MakeBenchmarkBundle(const Motion3D& motion,
                                    const Character& character,
                                    const FitBenchmarkOptions& options,
                                    const FitCameraSetting& setting, bool noisy,
                                    const std::string& name) {
  BundleFromMotionOptions bundle_options;
  // The clip's own length, a looping clip repeated to min_duration_s, cut
  // at max_duration_s (duration 0 = the clip as it is).
  double length_s = motion.duration_s();
  if (motion.loops) length_s = std::max(length_s, options.min_duration_s);
  length_s = std::min(length_s, options.max_duration_s);
  bundle_options.duration_s = length_s == motion.duration_s() ? 0.0 : length_s;
  bundle_options.follow = setting.follow;
  bundle_options.rig.num_views = options.num_views;
  bundle_options.rig.elevation_deg = setting.elevation_deg;
  bundle_options.rig.distance_m = setting.distance_m;
  bundle_options.rig.focal_px = setting.focal_px;
  if (noisy) bundle_options.noise = options.noise;
  return MakeBundleFromMotion(motion, character.keypoint_map(), bundle_options,
                              name);
}

FitBenchmarkResult RunFitBenchmark(const Character& character,
                                   const FitBenchmarkOptions& options) {
  // Outline: for each clip x setting x noise, make the bundle; fit each view
  // from its clip alone; measure against the bundle's truth; average.
  options.Validate();
  const auto start = std::chrono::steady_clock::now();
  auto elapsed_s = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  auto report = [&options](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  std::vector<bool> noise_levels;
  if (options.clean) noise_levels.push_back(false);
  if (options.noisy) noise_levels.push_back(true);
  const int total_fits =
      static_cast<int>(options.clips.size() * options.settings.size() *
                       noise_levels.size()) *
      options.num_views;

  FitBenchmarkResult result;
  std::vector<FitAccuracy> every, clean, noisy, from_truth;
  for (const std::string& clip : options.clips) {
    const Motion3D motion = ReadDeepMimicMotion(options.MotionPath(clip),
                                                character.shared_skeleton());
    for (const FitCameraSetting& setting : options.settings) {
      FitOptions fit_options = options.fit;
      fit_options.camera_motion = setting.fit_camera;
      fit_options.num_threads = options.num_threads;
      for (bool is_noisy : noise_levels) {
        const ReferenceBundle bundle = MakeBenchmarkBundle(
            motion, character, options, setting, is_noisy, clip);
        FitBenchmarkRow row;
        row.clip = clip;
        row.setting = setting.name;
        row.noisy = is_noisy;
        row.num_frames = bundle.num_frames();
        for (size_t v = 0; v < bundle.views.size(); ++v) {
          const ReferenceView& view = bundle.views[v];
          report(
              Format("[%d/%d] %s, setting %s, %s, view %zu/%zu (%d frames), "
                     "elapsed %.0f s",
                     result.num_fits + 1, total_fits, clip.c_str(),
                     setting.name.c_str(), NoiseName(is_noisy), v + 1,
                     bundle.views.size(), row.num_frames, elapsed_s()));
          ++result.num_fits;
          const std::string source = clip + " " + setting.name + " " +
                                     NoiseName(is_noisy) + " " + view.name;
          try {
            // The fit sees the view's 2D clip and nothing else.
            const double cpu_start_s = ProcessCpuSeconds();
            const ViewEstimate estimate =
                FitView(view.clip, character, fit_options, source);
            const double cpu_s = ProcessCpuSeconds() - cpu_start_s;
            FitAccuracy accuracy = MeasureFitAccuracy(
                estimate, view.cameras, *bundle.ground_truth, character);
            accuracy.cpu_seconds_per_100_frames =
                100.0 * cpu_s / accuracy.num_frames;
            report("    " + accuracy.BriefReport());
            row.views.push_back(accuracy);
            if (options.from_truth) {
              // Stages 2-3 from the truth: the measurement's side, never
              // the fit's (the fit above saw the 2D alone).
              const ViewEstimate refined =
                  RefineView(view.clip, character, fit_options, view.cameras,
                             bundle.ground_truth->poses, source + " (truth)");
              const FitAccuracy truth_started = MeasureFitAccuracy(
                  refined, view.cameras, *bundle.ground_truth, character);
              // Missed: more than 5 % above (equal minima end a little
              // apart).
              const bool missed =
                  accuracy.final_cost > 1.05 * truth_started.final_cost;
              report(Format(
                  "    from the truth (cost there %.3g): PA-MPJPE "
                  "%.0f mm, reprojection %.1f px, cost %.3g (the "
                  "fit's %.3g%s)",
                  refined.summary.initial_cost, truth_started.pa_mpjpe_mm,
                  truth_started.mean_reprojection_px, truth_started.final_cost,
                  accuracy.final_cost, missed ? ": the search missed it" : ""));
              // Which terms prefer the fit: stage 3's objective, term by
              // term, at the (clamped) truth and at the fit.
              report("    stage 3's terms at the truth: " +
                     ExplainCost(view.clip, character, fit_options,
                                 view.cameras, bundle.ground_truth->poses,
                                 source + " (truth)")
                         .BriefReport());
              report("    stage 3's terms at the fit:   " +
                     ExplainCost(view.clip, character, fit_options,
                                 estimate.cameras, estimate.poses, source)
                         .BriefReport());
              row.from_truth.push_back(truth_started);
              from_truth.push_back(truth_started);
              if (missed) ++result.num_search_misses;
            }
          } catch (const InputError& error) {
            report(std::string("    fit failed: ") + error.what());
            row.errors.push_back(error.what());
            ++result.num_failed_fits;
          }
        }
        row.mean = MeanFitAccuracy(row.views);
        for (const FitAccuracy& a : row.views) {
          every.push_back(a);
          (is_noisy ? noisy : clean).push_back(a);
        }
        result.rows.push_back(std::move(row));
      }
    }
  }
  result.from_truth = MeanFitAccuracy(from_truth);
  result.all = MeanFitAccuracy(every);
  result.all_clean = MeanFitAccuracy(clean);
  result.all_noisy = MeanFitAccuracy(noisy);
  result.wall_seconds = elapsed_s();
  return result;
}

// With from_truth: the truth-started refinements in one line.
std::string FromTruthLine(const FitBenchmarkResult& result) {
  if (result.from_truth.num_frames == 0) return "";
  const FitAccuracy& a = result.from_truth;
  return Format(
      "\nfrom the truth (stages 2-3 started at the true cameras and poses, "
      "hinges clamped): PA-MPJPE %.0f mm, MPJPE root-rel. %.0f mm, "
      "reprojection %.1f px, pitch %.1f deg, roll %.1f deg off; %d of %d "
      "fits ended more than 5%% above this refinement's cost (the search "
      "missed it)\n",
      a.pa_mpjpe_mm, a.root_relative_mpjpe_mm, a.mean_reprojection_px,
      a.pitch_error_deg, a.roll_error_deg, result.num_search_misses,
      result.num_fits - result.num_failed_fits);
}

std::string FormatFitBenchmarkTable(const FitBenchmarkResult& result) {
  std::string text =
      Format("%-8s %-3s %-5s %5s %6s %7s %6s %6s %9s %9s %9s %7s %7s %7s %7s\n",
             "clip", "cam", "noise", "fits", "frames", "focal%", "pitch",
             "roll", "MPJPEroot", "PA-MPJPE", "reachable", "reproj", "s/100f",
             "cpu", "unconv");
  text +=
      Format("%-8s %-3s %-5s %5s %6s %7s %6s %6s %9s %9s %9s %7s %7s %7s %7s\n",
             "", "", "", "", "", "", "(deg)", "(deg)", "(mm)", "(mm)",
             "PA (mm)", "(px)", "(s)", "(s)", "(%)");
  for (const TableLine& line : TableLines(result)) {
    const std::string frames =
        line.frames > 0 ? std::to_string(line.frames) : "";
    text += Format("%-8s %-3s %-5s %5s %6s", line.clip.c_str(),
                   line.setting.c_str(), line.noise.c_str(), line.fits.c_str(),
                   frames.c_str());
    if (line.empty) {
      text += "   (every fit failed)\n";
      continue;
    }
    const FitAccuracy& a = line.accuracy;
    text +=
        Format(" %7.1f %6.1f %6.1f %9.0f %9.0f %9.0f %7.1f %7.1f %7.1f %7.0f\n",
               a.focal_error_pct, a.pitch_error_deg, a.roll_error_deg,
               a.root_relative_mpjpe_mm, a.pa_mpjpe_mm, a.reachable_pa_mpjpe_mm,
               a.mean_reprojection_px, a.seconds_per_100_frames,
               a.cpu_seconds_per_100_frames, 100.0 * a.unconverged_fraction);
  }
  return text + FromTruthLine(result);
}

std::string FormatFitBenchmarkMarkdown(const FitBenchmarkResult& result) {
  std::string text =
      "| clip | camera | 2D | fits | frames | focal err % | pitch err ° | "
      "roll err ° | MPJPE root-rel. (mm) | PA-MPJPE (mm) | reachable PA (mm) "
      "| reprojection (px) | s / 100 frames (wall, CPU) | unconverged % |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const TableLine& line : TableLines(result)) {
    const std::string frames =
        line.frames > 0 ? std::to_string(line.frames) : "";
    const bool total = line.clip == "all";
    const std::string clip = total ? "**all**" : line.clip;
    text +=
        Format("| %s | %s | %s | %s | %s |", clip.c_str(), line.setting.c_str(),
               line.noise.c_str(), line.fits.c_str(), frames.c_str());
    if (line.empty) {
      text += " every fit failed | | | | | | | | |\n";
      continue;
    }
    const FitAccuracy& a = line.accuracy;
    text += Format(
        " %.1f | %.1f | %.1f | %.0f | %.0f | %.0f | %.1f | %.1f, %.1f | %.0f "
        "|\n",
        a.focal_error_pct, a.pitch_error_deg, a.roll_error_deg,
        a.root_relative_mpjpe_mm, a.pa_mpjpe_mm, a.reachable_pa_mpjpe_mm,
        a.mean_reprojection_px, a.seconds_per_100_frames,
        a.cpu_seconds_per_100_frames, 100.0 * a.unconverged_fraction);
  }
  return text;
}

nlohmann::json FitBenchmarkToJson(const FitBenchmarkResult& result,
                                  const FitBenchmarkOptions& options) {
  nlohmann::json settings = nlohmann::json::array();
  for (const FitCameraSetting& s : options.settings) {
    settings.push_back(
        {{"name", s.name},
         {"description", s.description},
         {"follow",
          s.follow == CameraFollow::kRootDolly ? "root_dolly" : "static"},
         {"fit_camera", CameraMotionName(s.fit_camera)},
         {"elevation_deg", s.elevation_deg},
         {"distance_m", s.distance_m},
         {"focal_px", s.focal_px}});
  }
  // A mean over no fit (that noise level not run, or every fit failed) is
  // null, not zeros. `noisy` -1: either.
  auto mean_json = [&result](const FitAccuracy& mean, int noisy) {
    for (const FitBenchmarkRow& row : result.rows) {
      if ((noisy < 0 || row.noisy == (noisy == 1)) && !row.views.empty())
        return AccuracyJson(mean);
    }
    return nlohmann::json();
  };
  nlohmann::json rows = nlohmann::json::array();
  for (const FitBenchmarkRow& row : result.rows) {
    nlohmann::json views = nlohmann::json::array();
    for (const FitAccuracy& a : row.views) views.push_back(AccuracyJson(a));
    nlohmann::json from_truth = nlohmann::json::array();
    for (const FitAccuracy& a : row.from_truth)
      from_truth.push_back(AccuracyJson(a));
    rows.push_back({{"clip", row.clip},
                    {"setting", row.setting},
                    {"noise", NoiseName(row.noisy)},
                    {"num_frames", row.num_frames},
                    {"views", views},
                    {"from_truth", from_truth},
                    {"errors", row.errors},
                    {"mean", row.views.empty() ? nlohmann::json()
                                               : AccuracyJson(row.mean)}});
  }
  return {{"format", "mimic2d.bench_fit"},
          {"version", 1},
          {"clips", options.clips},
          {"settings", settings},
          {"num_views", options.num_views},
          {"num_threads", options.num_threads},
          {"max_duration_s", options.max_duration_s},
          {"min_duration_s", options.min_duration_s},
          {"clean", options.clean},
          {"noisy", options.noisy},
          {"noise",
           {{"pixel_sigma_px", options.noise.pixel_sigma_px},
            {"drop_probability", options.noise.drop_probability},
            {"seed", options.noise.seed}}},
          {"rows", rows},
          {"all", mean_json(result.all, -1)},
          {"all_clean", mean_json(result.all_clean, 0)},
          {"all_noisy", mean_json(result.all_noisy, 1)},
          {"num_fits", result.num_fits},
          {"num_failed_fits", result.num_failed_fits},
          {"num_search_misses", result.num_search_misses},
          {"wall_seconds", result.wall_seconds}};
}

}  // namespace m2d
