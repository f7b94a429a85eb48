// cli: what the front end does with a trained checkpoint, shared by `eval`,
// `render` and `demo` — evaluate it (table on stdout, JSON to a file) and
// render one of its rollouts.
#ifndef MIMIC2D_CLI_POLICY_RUNS_H_
#define MIMIC2D_CLI_POLICY_RUNS_H_

#include <string>
#include <vector>

#include "eval/evaluator.h"
#include "motion/bundle.h"
#include "render/episode_renderer.h"

namespace m2d::cli {

// Rolls the checkpoint's policy out on every view of `bundle_paths` (empty:
// the bundles of its training config), with its training character and
// environment settings.
std::vector<EvalRow> EvaluateCheckpoint(
    const std::string& checkpoint, const std::vector<std::string>& bundle_paths,
    const EvalOptions& options);

// One line per row, then the episode-weighted "all" row.
void PrintEvalTable(const std::vector<EvalRow>& rows);

// Writes rows + "all" as JSON, atomically.
void WriteEvalJson(const std::string& path, const std::string& checkpoint,
                   const EvalOptions& options,
                   const std::vector<EvalRow>& rows);

// Rolls the checkpoint's policy out on `replay.view` of `bundle` from
// `start_frame` for at most `episode_s`, and draws it as `replay` says.
EpisodeSummary RenderCheckpointRollout(const std::string& checkpoint,
                                       const ReferenceBundle& bundle,
                                       const BundleReplayOptions& replay,
                                       int start_frame, double episode_s);

}  // namespace m2d::cli

#endif  // MIMIC2D_CLI_POLICY_RUNS_H_
