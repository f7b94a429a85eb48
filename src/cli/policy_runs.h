// cli: what the front end does with a trained checkpoint, shared by `eval`,
// `render` and `demo` — evaluate it (table on stdout, JSON to a file) and
// render one of its rollouts.
#ifndef MIMIC2D_CLI_POLICY_RUNS_H_
#define MIMIC2D_CLI_POLICY_RUNS_H_

#include <optional>
#include <string>
#include <vector>

#include "env/sources.h"
#include "eval/evaluator.h"
#include "motion/bundle.h"
#include "render/episode_renderer.h"
#include "rl/train_config.h"

namespace m2d::cli {

// The character config a checkpoint trained with. Checkpoints keep the
// training's paths, relative to where it ran (the repository root); from
// elsewhere, it is found there.
std::string TrainedCharacterPath(const TrainConfig& config);

// Where a policy run's starts and cameras come from: each unset field
// keeps the checkpoint's training config.
struct SourceOverrides {
  std::optional<InitialStateSource> initial_states;  // eval --starts
  std::optional<CameraSource> cameras;               // eval --cameras
  // eval --asi-starts: the starts' buffers as training left them (the
  // sources' states refined by ASI), read from the checkpoint.
  bool checkpoint_buffers = false;
};

struct CheckpointEvaluation {
  TaskSources sources;              // the ones the rollouts used
  bool checkpoint_buffers = false;  // starts from the checkpoint's buffers
  EpisodeCamera camera = EpisodeCamera::kRecorded;  // the episodes'
  std::vector<std::string> keypoint_names;          // the character's, by index
  std::vector<EvalRow> rows;
};

// Rolls the checkpoint's policy out on every view of `bundle_paths` (empty:
// the bundles of its training config), with its training character and
// environment settings and noise-free initial states. E3D is measured
// against the truth read, apart from the task, from `truth_paths` (one per
// bundle: e.g. the originals of stripped bundles; empty: the bundle files
// themselves). A truth bundle must have the evaluated one's frame count.
CheckpointEvaluation EvaluateCheckpoint(
    const std::string& checkpoint, const std::vector<std::string>& bundle_paths,
    const EvalOptions& options, const SourceOverrides& sources = {},
    const std::vector<std::string>& truth_paths = {});

// A header naming the sources, one line per row, then the episode-weighted
// "all" row, then how the rollouts ended (and on which keypoints the early
// exits failed).
void PrintEvalTable(const CheckpointEvaluation& evaluation);

// Writes the sources, rows + "all" as JSON, atomically.
void WriteEvalJson(const std::string& path, const std::string& checkpoint,
                   const EvalOptions& options,
                   const CheckpointEvaluation& evaluation);

// Writes every rollout's per-frame errors (EvalOptions::record_frames) as
// CSV, one line per simulated step, atomically: clip, view, rollout,
// start_frame, step, frame, keypoints_present, mean_px, worst_px,
// worst_keypoint (its name), worst_view, pa_mm (empty without truth), end
// (on a rollout's last step: early_exit, diverged, clip_end or time_limit).
void WriteEvalFramesCsv(const std::string& path,
                        const CheckpointEvaluation& evaluation);

// Rolls the checkpoint's policy out on `replay.view` of `bundle` from
// `start_frame` for at most `episode_s`, ending as eval's rollouts do
// (JudgedEnvOptions: the success rule, no pushes), and draws it as
// `replay` says.
EpisodeSummary RenderCheckpointRollout(const std::string& checkpoint,
                                       const ReferenceBundle& bundle,
                                       const BundleReplayOptions& replay,
                                       int start_frame, double episode_s,
                                       const SourceOverrides& sources = {});

}  // namespace m2d::cli

#endif  // MIMIC2D_CLI_POLICY_RUNS_H_
