// cli: `mimic2d bench fit` — the fit's accuracy table (docs/fit.md,
// "Accuracy table"): DeepMimic clips x camera settings x clean/noisy 2D,
// each view fitted from its 2D alone and measured against the truth. The
// loop is eval/fit_benchmark.h; this file parses and prints.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "common/error.h"

#ifdef MIMIC2D_HAVE_SIM
#include "common/file_io.h"
#include "eval/fit_benchmark.h"
#include "fit/fit_config.h"
#include "sim/simulation.h"
#endif

namespace m2d::cli {
namespace {

struct BenchFitArgs {
  std::vector<std::string> clips{"walk", "run", "jump", "kick", "dance_a"};
  int views = 2;
  int threads = 1;
  double min_duration_s = 0.0;  // loop cyclic clips to this long (s)
  double max_duration_s = 4.0;  // cut longer clips (s)
  std::string output;           // JSON; empty: none
  std::string motion_dir;
  std::string config;                 // FitOptions YAML; "": the defaults
  std::vector<std::string> settings;  // names; empty: all
  std::string noise = "both";         // clean, noisy or both
  bool markdown = false;              // also print the table as Markdown
  bool from_truth = false;            // also refine from the truth
  bool quick = false;
};

#ifdef MIMIC2D_HAVE_SIM

int RunBenchFit(const BenchFitArgs& args) {
  FitBenchmarkOptions options;
  options.motion_dir = args.motion_dir.empty() ? AssetPath("motions/deepmimic")
                                               : args.motion_dir;
  options.clips = args.clips;
  options.num_views = args.views;
  options.num_threads = args.threads;
  options.min_duration_s = args.min_duration_s;
  options.max_duration_s = args.max_duration_s;
  if (!args.config.empty()) options.fit = ReadFitOptions(args.config);
  if (!args.settings.empty()) {
    std::vector<FitCameraSetting> chosen;
    for (const std::string& name : args.settings) {
      bool found = false;
      for (const FitCameraSetting& setting : options.settings) {
        if (setting.name != name) continue;
        chosen.push_back(setting);
        found = true;
      }
      if (!found)
        throw ConfigError("--settings: no camera setting '" + name + "'");
    }
    options.settings = chosen;
  }
  options.from_truth = args.from_truth;
  options.clean = args.noise != "noisy";
  options.noisy = args.noise != "clean";
  if (args.quick) options.MakeQuick();
  options.progress = [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  options.Validate();
  auto character = LoadCharacterForSimulation(
      AssetPath("characters/humanoid.yaml"), "flat", SimulationOptions());

  std::printf(
      "bench fit: %zu clip(s) x %zu camera setting(s) x %s, %d "
      "view(s) each, at most %.0f s per clip (looping clips at least "
      "%.1f s), %d solver thread(s)\n",
      options.clips.size(), options.settings.size(),
      options.clean && options.noisy ? "clean and noisy 2D"
      : options.clean                ? "clean 2D"
                                     : "noisy 2D",
      options.num_views, options.max_duration_s, options.min_duration_s,
      options.num_threads);
  for (const FitCameraSetting& setting : options.settings) {
    std::printf("  setting %s: %s\n", setting.name.c_str(),
                setting.description.c_str());
  }
  if (options.noisy) {
    std::printf(
        "  noisy: Gaussian %.1f px, %.0f%% of keypoints dropped, seed "
        "%llu\n",
        options.noise.pixel_sigma_px, 100 * options.noise.drop_probability,
        static_cast<unsigned long long>(options.noise.seed));
  }
  // Seconds are wall time: other work on the cores inflates them.
  double load[1] = {0.0};
  getloadavg(load, 1);
  std::printf("  load average %.2f at start\n\n", load[0]);
  std::fflush(stdout);

  const FitBenchmarkResult result = RunFitBenchmark(*character, options);
  std::printf("\n%s", FormatFitBenchmarkTable(result).c_str());
  if (args.markdown)
    std::printf("\n%s", FormatFitBenchmarkMarkdown(result).c_str());
  std::printf(
      "(per row: mean over its views; errors are absolute; MPJPEroot after "
      "the best rotation about z; %d of %d fits returned; %.0f s in all)\n",
      result.num_fits - result.num_failed_fits, result.num_fits,
      result.wall_seconds);
  if (!args.output.empty()) {
    WriteJsonFileAtomic(args.output, FitBenchmarkToJson(result, options), 2);
    std::printf("wrote %s\n", args.output.c_str());
  }
  return 0;
}

#else

int RunBenchFit(const BenchFitArgs&) {
  throw ConfigError("bench fit: built without the simulation");
}

#endif

}  // namespace

void AddBenchFitSubcommand(CLI::App* bench, CommandRun* run) {
  auto args = std::make_shared<BenchFitArgs>();
  CLI::App* fit = bench->add_subcommand(
      "fit",
      "Fit accuracy table: DeepMimic clips x 2 camera settings x clean/noisy "
      "2D, each view fitted from its 2D alone and measured against the truth "
      "(docs/fit.md)");
  CLI::Option* clips =
      fit->add_option("--clips", args->clips,
                      "Clips (assets/motions/deepmimic/humanoid3d_<clip>.txt)")
          ->delimiter(',')
          ->capture_default_str();
  CLI::Option* views =
      fit->add_option("--views", args->views, "Rig views per bundle")
          ->capture_default_str();
  fit->add_option("--threads", args->threads, "Ceres threads per fit")
      ->capture_default_str();
  fit->add_option("--min-duration", args->min_duration_s,
                  "Repeat a looping clip to at least this long (s, at most "
                  "--max-duration); clips that do not loop keep their length")
      ->capture_default_str();
  fit->add_option("--max-duration", args->max_duration_s,
                  "Cut clips longer than this (s)")
      ->capture_default_str();
  fit->add_option("-o,--output", args->output,
                  "Write the table as JSON (atomically)")
      ->check(WritableFile());
  fit->add_option("--motion-dir", args->motion_dir,
                  "Folder of the clips (default: assets/motions/deepmimic)");
  fit->add_option("--config", args->config,
                  "FitOptions as YAML for every fit (docs/fit.md, "
                  "\"Settings\"); the camera model is each setting's");
  CLI::Option* settings =
      fit->add_option("--settings", args->settings,
                      "Camera settings to run, e.g. A,B (default: all)")
          ->delimiter(',');
  CLI::Option* noise =
      fit->add_option("--noise", args->noise, "clean, noisy or both")
          ->check(CLI::IsMember({"clean", "noisy", "both"}))
          ->capture_default_str();
  fit->add_flag("--markdown", args->markdown,
                "Also print the table as Markdown (for docs/fit.md)");
  fit->add_flag("--from-truth", args->from_truth,
                "Also refine each view from its true camera and poses "
                "(stages 2-4): the objective's minimum near the truth, the "
                "fits whose search missed a lower cost, and stage 3's "
                "terms at the truth and at the fit");
  fit->add_flag("--quick", args->quick,
                "Only the walk, clean 2D, setting A, one view (a smoke test)")
      ->excludes(clips)
      ->excludes(views)
      ->excludes(settings)
      ->excludes(noise);
  fit->callback([run, args] { *run = [args] { return RunBenchFit(*args); }; });
}

}  // namespace m2d::cli
