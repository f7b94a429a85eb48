// cli: `mimic2d fit` — estimates each view's camera and the character's
// per-frame 3D poses from the 2D alone, and writes them into the bundle's
// `estimate` section (docs/fit.md).
#include <cstdio>
#include <iostream>
#include <optional>
#include <vector>

#include "cli/commands.h"
#include "cli/motion_source.h"
#include "common/error.h"
#include "eval/fit_accuracy.h"
#include "fit/fit.h"
#include "fit/fit_config.h"
#include "motion/bundle.h"
#include "sim/simulation.h"

namespace m2d::cli {
namespace {

struct FitArgs {
  bool list_settings = false;
  std::string input;
  std::string output;
  std::string camera;  // "": the config's (default static)
  std::string config;  // FitOptions YAML; "": the defaults
  double focal_px = 0.0;
  int threads = 0;  // 0: the config's (default 1)
  std::string character = "characters/humanoid.yaml";
  // A bundle holding the input's truth (e.g. the original of a stripped
  // bundle): each view's fit is measured against it after fitting. The fit
  // never reads it.
  std::string truth;
  std::vector<double> tilt_deg;  // --tilt: pitch, roll (deg); empty: fitted
  FitOptions options;
  bool quiet = false;
  bool rig = false;  // the views are one synchronized take (FitRig)
};

int RunFit(FitArgs& args) {
  if (args.list_settings) {
    std::printf("%s", FitSettingsReference().c_str());
    return 0;
  }
  if (args.input.empty() || args.output.empty())
    throw InputError("", "fit: give an input bundle and -o OUTPUT");
  // The config file, then the command line's explicit settings over it.
  if (!args.config.empty()) args.options = ReadFitOptions(args.config);
  if (!args.camera.empty() &&
      !ParseCameraMotion(args.camera, &args.options.camera_motion)) {
    throw ConfigError("--camera must be static or moving, not '" + args.camera +
                      "'");
  }
  if (args.focal_px > 0) args.options.fixed_focal_px = args.focal_px;
  if (!args.tilt_deg.empty()) {
    args.options.tilt_known = true;
    args.options.known_pitch_deg = args.tilt_deg[0];
    args.options.known_roll_deg = args.tilt_deg[1];
  }
  if (args.threads > 0) args.options.num_threads = args.threads;
  if (!args.quiet) {
    args.options.progress = [](const std::string& line) {
      std::printf("    %s\n", line.c_str());
      std::fflush(stdout);
    };
  }
  args.options.Validate();
  const ReferenceBundle bundle = ReadBundleOrClip(args.input);
  std::optional<ReferenceBundle> truth;
  if (!args.truth.empty()) {
    truth = ReadMatchingTruth(args.truth, bundle, args.input);
  }
  const std::string character_path = AssetArgumentPath(args.character);
  auto character =
      LoadCharacterForSimulation(character_path, "flat", SimulationOptions());
  std::printf(
      "fitting %zu view(s) of %s (%d frames)%s, camera %s, focal %s, tilt "
      "%s\n",
      bundle.views.size(), args.input.c_str(), bundle.num_frames(),
      args.rig ? " as one rig" : "",
      CameraMotionName(args.options.camera_motion),
      args.options.fixed_focal_px > 0 ? "fixed" : "estimated",
      args.options.tilt_known ? "known" : "estimated");
  int failed_views = 0;
  std::vector<FitAccuracy> accuracies;
  const auto fit_views = args.rig ? FitRig : FitBundle;
  ReferenceBundle fitted = fit_views(
      bundle, *character, args.options, args.input,
      [&](int view, const ViewEstimate& estimate) {
        const FitSummary& summary = estimate.summary;
        std::printf("view %d/%zu (%s): %s\n", view + 1, bundle.views.size(),
                    bundle.views[view].name.c_str(),
                    summary.BriefReport().c_str());
        // An unreliable view fails the command; the estimate is still
        // written, for inspection.
        if (summary.Unreliable()) ++failed_views;
        if (truth) {  // the measurement's side, after the fit
          accuracies.push_back(
              MeasureFitAccuracy(estimate, truth->views[view].cameras,
                                 *truth->ground_truth, *character));
          std::printf("  against the truth: %s\n",
                      accuracies.back().BriefReport().c_str());
          // Which terms prefer the fit to the truth (docs/fit.md, "Search
          // or objective?").
          const std::string source =
              args.input + " (view " + bundle.views[view].name + ")";
          std::printf(
              "  stage 3's terms at the truth: %s\n  stage 3's terms at the "
              "fit:   %s\n",
              ExplainCost(bundle.views[view].clip, *character, args.options,
                          truth->views[view].cameras,
                          truth->ground_truth->poses, source)
                  .BriefReport()
                  .c_str(),
              ExplainCost(bundle.views[view].clip, *character, args.options,
                          estimate.cameras, estimate.poses, source)
                  .BriefReport()
                  .c_str());
        }
        std::fflush(stdout);
      });
  WriteBundle(args.output, fitted);
  std::printf("wrote %s\n", args.output.c_str());
  if (accuracies.size() > 1) {
    std::printf("mean over the views, against the truth: %s\n",
                MeanFitAccuracy(accuracies).BriefReport().c_str());
  }
  if (failed_views > 0) {
    std::fprintf(stderr,
                 "error: %s: the fit did not converge on more than %.0f%% of "
                 "the frames of %d view(s) (listed above); the estimate was "
                 "written for inspection but should not be trained on\n",
                 args.input.c_str(), 100 * kMaxUnconvergedFraction,
                 failed_views);
    return 3;
  }
  return 0;
}

}  // namespace

void AddFitCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* fit = app.add_subcommand(
      "fit",
      "Estimate each view's camera and the character's 3D poses from its 2D "
      "keypoints alone (Ceres), into the bundle's estimate section");
  fit->add_option("input", args->input,
                  "reference bundle (2D; truth unused) or a 2D clip (one "
                  "view, e.g. from `mimic2d keypoints`)");
  fit->add_option("-o,--output", args->output, "bundle with the estimate")
      ->check(WritableFile());
  fit->add_flag("--list-settings", args->list_settings,
                "Print every --config setting with its default, allowed "
                "values and meaning (Markdown), and exit");
  fit->add_option("--camera", args->camera,
                  "static (tripod) or moving (smooth per-frame position); "
                  "default static");
  fit->add_option("--focal", args->focal_px,
                  "known focal length in pixels (default: estimated)")
      ->check(CLI::PositiveNumber);
  fit->add_option("--tilt", args->tilt_deg,
                  "known camera tilt PITCH,ROLL in degrees (pitch positive "
                  "looks down), held fixed (default: estimated)")
      ->expected(2)
      ->delimiter(',');
  fit->add_option("--config", args->config,
                  "FitOptions as YAML (docs/fit.md, \"Settings\"); the "
                  "flags above and below override it");
  fit->add_option("--character", args->character,
                  "character config (relative to assets/ unless absolute)")
      ->default_val("characters/humanoid.yaml");
  fit->add_option("--threads", args->threads, "solver threads (default 1)")
      ->check(CLI::PositiveNumber);
  fit->add_flag("--quiet", args->quiet, "no per-stage progress lines");
  fit->add_flag("--rig", args->rig,
                "the views are one synchronized take (a calibrated rig of "
                "static cameras, or cameras that all follow the subject "
                "with --camera moving): one body fitted to all of them, "
                "each camera placed in one world (docs/fit.md, \"A rig\")");
  fit->add_option("--truth", args->truth,
                  "bundle holding the input's 3D truth and true cameras (a "
                  "stripped bundle's original): each view's fit is measured "
                  "against it afterwards (focal, pitch, roll, MPJPE, "
                  "PA-MPJPE; stage 3's objective term by term at the truth "
                  "and at the fit); the fit never reads it");
  fit->callback([run, args] { *run = [args] { return RunFit(*args); }; });
}

}  // namespace m2d::cli
