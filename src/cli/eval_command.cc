// cli: `mimic2d eval` — roll a trained policy out on every view (or set of
// K views) of its bundles and report Succ, E2D, EO2D, E3D and Jitter (table
// + JSON).
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "cli/policy_runs.h"

namespace m2d::cli {
namespace {

struct EvalArgs {
  std::string checkpoint;
  std::vector<std::string> bundles;
  std::vector<std::string> truth_bundles;  // measurement only, per bundle
  std::string output;
  std::string frames_output;  // --frames: per-frame CSV
  EvalOptions options;
  std::string starts;   // "": the checkpoint's config
  std::string cameras;  // "": the checkpoint's config
  std::string camera;   // --camera; "": the checkpoint's config
  bool asi_starts = false;
  std::string success_measure = SettingName(FrameErrorMeasure::kWorst);
};

int RunEval(const EvalArgs& args) {
  SourceOverrides sources;
  if (!args.starts.empty())
    sources.initial_states = ParseInitialStateSource(args.starts);
  if (!args.cameras.empty()) sources.cameras = ParseCameraSource(args.cameras);
  sources.checkpoint_buffers = args.asi_starts;
  EvalOptions options = args.options;
  ParseSetting(args.success_measure, &options.success_measure);  // checked
  if (!args.camera.empty()) {
    EpisodeCamera camera = EpisodeCamera::kRecorded;
    ParseSetting(args.camera, &camera);  // checked
    options.camera = camera;
  }
  options.record_frames = !args.frames_output.empty();
  CheckpointEvaluation evaluation = EvaluateCheckpoint(
      args.checkpoint, args.bundles, options, sources, args.truth_bundles);
  std::printf(
      "Succ: a rollout fails at the first frame whose %s error is > "
      "%g px\n",
      options.success_measure == FrameErrorMeasure::kWorst ? "worst keypoint's"
                                                           : "mean keypoint",
      options.success_threshold_px);
  if (options.pushes.force_n > 0) {
    std::printf(
        "pushes: %g N on the root, horizontal, every %g s for %g s "
        "(directions from seed %llu)\n",
        options.pushes.force_n, options.pushes.every_s,
        options.pushes.duration_s,
        static_cast<unsigned long long>(options.perturbation_seed));
  }
  if (options.object_start_square_m > 0) {
    std::printf(
        "objects start moved uniformly within a %g m square (seed %llu)\n",
        options.object_start_square_m,
        static_cast<unsigned long long>(options.perturbation_seed));
  }
  PrintEvalTable(evaluation);
  if (!args.output.empty()) {
    WriteEvalJson(args.output, args.checkpoint, options, evaluation);
    std::printf("wrote %s\n", args.output.c_str());
  }
  if (!args.frames_output.empty()) {
    WriteEvalFramesCsv(args.frames_output, evaluation);
    std::printf("wrote %s (per-frame errors)\n", args.frames_output.c_str());
  }
  return 0;
}

}  // namespace

void AddEvalCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* eval = app.add_subcommand(
      "eval",
      "Evaluate a policy: Succ, E2D, EO2D, E3D, Jitter per clip and view");
  eval->add_option("checkpoint", args->checkpoint,
                   "Checkpoint (.pt) written by train")
      ->required();
  eval->add_option("--bundle", args->bundles,
                   "Reference bundles (default: the training bundles)");
  eval->add_option(
      "--truth", args->truth_bundles,
      "Bundles holding the 3D truth of the evaluated ones, one per bundle "
      "in the same order (a stripped bundle's original), for E3D only: the "
      "policy and its task never read them");
  eval->add_option("--episodes", args->options.episodes_per_view,
                   "Episodes per view")
      ->capture_default_str();
  eval->add_option("--episode-s", args->options.episode_s, "Episode length (s)")
      ->capture_default_str();
  eval->add_option(
          "--success-px", args->options.success_threshold_px,
          "A frame whose error (--success-measure) is off by more fails the "
          "rollout (px)")
      ->capture_default_str();
  eval->add_option("--success-measure", args->success_measure,
                   "Which frame error --success-px bounds: worst_keypoint "
                   "(the paper's 'max reprojection' as read here; every "
                   "table of docs/) or mean_keypoint (PHC's success rule in "
                   "pixels, for comparison)")
      ->check(CLI::IsMember({SettingName(FrameErrorMeasure::kWorst),
                             SettingName(FrameErrorMeasure::kMean)}))
      ->capture_default_str();
  eval->add_option("--views", args->options.num_views,
                   "K: views tracked at once (zero-shot multi-view: phi "
                   "averaged over each view and the K-1 next views of its "
                   "bundle); K > 1 needs --cameras truth")
      ->capture_default_str();
  eval->add_option("--starts", args->starts,
                   "Initial states from: truth, estimate (mimic2d fit) or "
                   "default (default: the checkpoint's config)")
      ->check(CLI::IsMember({"truth", "estimate", "default"}));
  eval->add_option("--cameras", args->cameras,
                   "Cameras from: truth or estimate (default: the "
                   "checkpoint's config)")
      ->check(CLI::IsMember({"truth", "estimate"}));
  eval->add_option("--camera", args->camera,
                   "The episodes' camera: recorded (each frame's as the "
                   "cameras source has it), follows_character (moved "
                   "with the simulated root's offset from the initial "
                   "states' root) or dollies_from_start (the start "
                   "frame's follows_character camera, then moved with the "
                   "simulated root alone: generate --policy's camera); "
                   "default: the checkpoint's env.camera")
      ->check(CLI::IsMember({SettingName(EpisodeCamera::kRecorded),
                             SettingName(EpisodeCamera::kFollowsCharacter),
                             SettingName(EpisodeCamera::kDolliesFromStart)}));
  eval->add_flag("--asi-starts", args->asi_starts,
                 "Start episodes from the checkpoint's ASI buffers (the "
                 "starts as training refined them) instead of fresh ones; "
                 "needs the training's sources and bundles");
  eval->add_option("--push", args->options.pushes.force_n,
                   "Robustness: a horizontal push of this force on the root "
                   "(N; the paper: 300), every --push-every-s for "
                   "--push-duration-s, in a direction drawn per push; 0: none")
      ->capture_default_str();
  eval->add_option("--push-every-s", args->options.pushes.every_s,
                   "Period of the pushes (s)")
      ->capture_default_str();
  eval->add_option("--push-duration-s", args->options.pushes.duration_s,
                   "Length of each push (s)")
      ->capture_default_str();
  eval->add_option("--object-start-square", args->options.object_start_square_m,
                   "Robustness: move each tracked object's start (the ball) "
                   "by an offset drawn uniformly in a square of this side on "
                   "the floor (m; the paper: 1); 0: none")
      ->capture_default_str();
  eval->add_option("--perturbation-seed", args->options.perturbation_seed,
                   "Seed of the push directions and object offsets")
      ->capture_default_str();
  eval->add_option("-o,--output", args->output, "Write the table as JSON here")
      ->check(WritableFile());
  eval->add_option("--frames", args->frames_output,
                   "Write every rollout's per-frame errors here as CSV (mean "
                   "and worst keypoint in px, which keypoint, PA-MPJPE with "
                   "truth, how the rollout ended): where a rollout starts "
                   "to fail")
      ->check(WritableFile());
  eval->callback([run, args] { *run = [args] { return RunEval(*args); }; });
}

}  // namespace m2d::cli
