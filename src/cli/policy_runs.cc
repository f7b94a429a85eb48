#include "cli/policy_runs.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/error.h"
#include "common/file_io.h"
#include "env/task.h"
#include "motion/bundle.h"
#include "render/policy_rollout.h"
#include "rl/checkpoint.h"
#include "rl/torch_policy.h"

namespace m2d::cli {
namespace {

// The task a trained policy runs in: its config's simulation, the sources
// (overridden where asked), noise-free initial states (sigma 0, default
// buffers), whatever the run trained with.
TrackingTaskOptions PolicyTaskOptions(const TrainConfig& config,
                                      const SourceOverrides& overrides) {
  TrackingTaskOptions options;
  options.simulation = config.env.simulation;
  options.sources = config.data.sources();
  if (overrides.initial_states)
    options.sources.initial_states = *overrides.initial_states;
  if (overrides.cameras) options.sources.cameras = *overrides.cameras;
  try {
    options.sources.Validate();
  } catch (const ConfigError& e) {
    throw ConfigError(std::string(e.what()) +
                      " (the checkpoint's config has initial_states: " +
                      SourceName(config.data.initial_states) +
                      ", cameras: " + SourceName(config.data.cameras) +
                      "; pass --starts and --cameras together)");
  }
  return options;
}

std::string Cell(double value, const char* format) {
  if (value < 0) return "-";
  char text[32];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// `view_width`: the view column's width (K views' joined names are long).
void PrintRow(const EvalRow& row, int view_width) {
  std::printf(
      "%-22s %-*s %5d %7.0f %7s %8s %8s %9s %11s %9s %7s\n", row.bundle.c_str(),
      view_width, row.view.c_str(), row.episodes, row.mean_frames,
      Cell(100 * row.succ, "%.1f").c_str(), Cell(row.e2d_px, "%.1f").c_str(),
      Cell(row.eo2d_px, "%.1f").c_str(), Cell(row.e3d_mm, "%.0f").c_str(),
      Cell(row.e3d_root_mm, "%.0f").c_str(),
      Cell(row.e3d_pa_mm, "%.0f").c_str(), Cell(row.jitter, "%.2f").c_str());
}

// The K views' names of a row ("a+b" -> {"a", "b"}).
std::vector<std::string> SplitViewNames(const std::string& joined) {
  std::vector<std::string> names(1);
  for (char c : joined) {
    if (c == '+') {
      names.emplace_back();
    } else {
      names.back() += c;
    }
  }
  return names;
}

// A keypoint's name, "" for none (-1).
std::string KeypointName(const CheckpointEvaluation& evaluation, int index) {
  if (index < 0 || index >= static_cast<int>(evaluation.keypoint_names.size()))
    return "";
  return evaluation.keypoint_names[index];
}

// "ended: 12 early_exit (worst keypoint then: left_wrist 5, ...), 28
// clip_end": how the rollouts ended, and which keypoints failed the early
// exits, most frequent first.
void PrintRolloutEnds(const CheckpointEvaluation& evaluation) {
  std::map<RolloutEnd, int> ends;
  std::map<std::string, int> exit_keypoints;
  for (const EvalRow& row : evaluation.rows) {
    for (const EvalRollout& rollout : row.rollouts) {
      ++ends[rollout.end];
      if (rollout.end == RolloutEnd::kEarlyExit)
        ++exit_keypoints[KeypointName(evaluation, rollout.last_worst_keypoint)];
    }
  }
  std::vector<std::pair<int, std::string>> by_count;
  for (const auto& [name, count] : exit_keypoints)
    by_count.push_back({-count, name.empty() ? "none" : name});
  std::sort(by_count.begin(), by_count.end());
  std::string line = "rollouts ended:";
  const char* separator = " ";
  for (const auto& [end, count] : ends) {
    line += separator + std::to_string(count) + " " + RolloutEndName(end);
    separator = ", ";
    if (end != RolloutEnd::kEarlyExit) continue;
    line += " (worst keypoint then:";
    for (size_t i = 0; i < by_count.size(); ++i) {
      line += (i ? ", " : " ") + by_count[i].second + " " +
              std::to_string(-by_count[i].first);
    }
    line += ")";
  }
  std::printf("%s\n", line.c_str());
}

nlohmann::json RowToJson(const EvalRow& row) {
  auto optional = [](double v) {
    return v < 0 ? nlohmann::json() : nlohmann::json(v);
  };
  nlohmann::json json = {{"clip", row.bundle},
                         {"view", row.view},
                         {"episodes", row.episodes},
                         {"succ", row.succ},
                         {"e2d_px", optional(row.e2d_px)},
                         {"eo2d_px", optional(row.eo2d_px)},
                         {"e3d_mm", optional(row.e3d_mm)},
                         {"e3d_root_mm", optional(row.e3d_root_mm)},
                         {"e3d_pa_mm", optional(row.e3d_pa_mm)},
                         {"jitter", optional(row.jitter)},
                         {"mean_frames", row.mean_frames}};
  if (!row.rollouts.empty()) {
    json["rollouts"] = nlohmann::json::array();
    for (const EvalRollout& rollout : row.rollouts) {
      json["rollouts"].push_back({{"start_frame", rollout.start_frame},
                                  {"frames", rollout.frames},
                                  {"succeeded", rollout.succeeded},
                                  {"e2d_px", rollout.e2d_px},
                                  {"end", RolloutEndName(rollout.end)}});
    }
  }
  return json;
}

}  // namespace

std::string TrainedCharacterPath(const TrainConfig& config) {
  std::string path = config.data.character_config;
  if (!std::filesystem::exists(path) &&
      std::filesystem::path(path).is_relative()) {
    const std::string in_repository =
        std::string(MIMIC2D_SOURCE_DIR) + "/" + path;
    if (std::filesystem::exists(in_repository)) path = in_repository;
  }
  return path;
}

CheckpointEvaluation EvaluateCheckpoint(
    const std::string& checkpoint, const std::vector<std::string>& bundle_paths,
    const EvalOptions& options, const SourceOverrides& sources,
    const std::vector<std::string>& truth_paths) {
  options.Validate();
  TorchPolicy policy(checkpoint, options.num_views);
  const TrainConfig& config = policy.config();
  std::vector<std::string> paths =
      bundle_paths.empty() ? config.data.bundles : bundle_paths;
  CheckpointEvaluation evaluation;
  const TrackingTaskOptions task_options = PolicyTaskOptions(config, sources);
  evaluation.sources = task_options.sources;
  TrackingTask task = BuildTrackingTask(TrainedCharacterPath(config),
                                        config.data.scene, paths, task_options);
  evaluation.checkpoint_buffers = sources.checkpoint_buffers;
  if (sources.checkpoint_buffers) {
    Simulation simulation(task.character, config.env.simulation);
    LoadCheckpointStateBuffers(checkpoint, task.initial_states.get(),
                               simulation.Save());
  }
  // Measurement only: the truth, read again from the files, goes to the
  // evaluator and never into the task the policy runs in.
  if (!truth_paths.empty() && truth_paths.size() != paths.size()) {
    throw ConfigError("--truth names " + std::to_string(truth_paths.size()) +
                      " bundles for " + std::to_string(paths.size()) +
                      " evaluated ones; give one per --bundle, in order");
  }
  std::vector<std::optional<GroundTruth3D>> truth;
  for (size_t b = 0; b < paths.size(); ++b) {
    if (truth_paths.empty()) {
      truth.push_back(ReadBundle(paths[b]).ground_truth);
      continue;
    }
    const ReferenceBundle truth_bundle = ReadBundle(truth_paths[b]);
    if (!truth_bundle.ground_truth) {
      throw InputError(truth_paths[b],
                       "has no ground_truth section to measure E3D against");
    }
    const int expected = task.reference->bundles()[b].num_frames();
    if (truth_bundle.num_frames() != expected) {
      throw InputError(truth_paths[b],
                       "has " + std::to_string(truth_bundle.num_frames()) +
                           " frames; the evaluated bundle " + paths[b] +
                           " has " + std::to_string(expected));
    }
    truth.push_back(truth_bundle.ground_truth);
  }
  evaluation.keypoint_names = task.character->keypoint_layout().keypoint_names;
  evaluation.camera = options.camera.value_or(config.env.camera);
  evaluation.rows =
      EvaluatePolicy(policy, task.character, task.reference,
                     task.initial_states, config.env, options, truth);
  return evaluation;
}

void PrintEvalTable(const CheckpointEvaluation& evaluation) {
  std::printf("%s\n", DescribeSources(evaluation.sources).c_str());
  if (evaluation.checkpoint_buffers) {
    std::printf(
        "episodes start from the checkpoint's ASI buffers: those states as "
        "training refined them in simulation (no 3D truth)\n");
  }
  if (evaluation.camera == EpisodeCamera::kFollowsCharacter) {
    std::printf(
        "the cameras follow the character: each frame's camera moved with "
        "the simulated root's offset from the initial states' motion's root "
        "(env.camera follows_character)\n");
  } else if (evaluation.camera == EpisodeCamera::kDolliesFromStart) {
    std::printf(
        "the cameras dolly from the start: the start frame's camera moved "
        "with the simulated root's offset from the initial states' root "
        "there, held so for the episode (env.camera dollies_from_start, "
        "generate --policy's)\n");
  }
  if (evaluation.sources.cameras == CameraSource::kEstimate) {
    std::printf(
        "E3D against the hidden truth: global not measured (each view's "
        "estimated world differs from the truth's), E3Droot after the best "
        "rotation about z, E3DPA after a similarity per frame\n");
  }
  int view_width = 7;
  for (const EvalRow& row : evaluation.rows)
    view_width = std::max(view_width, static_cast<int>(row.view.size()));
  std::printf("%-22s %-*s %5s %7s %7s %8s %8s %9s %11s %9s %7s\n", "clip",
              view_width, "view", "eps", "frames", "Succ%", "E2D(px)",
              "EO2D(px)", "E3D(mm)", "E3Droot(mm)", "E3DPA(mm)", "Jitter");
  for (const EvalRow& row : evaluation.rows) PrintRow(row, view_width);
  PrintRow(AggregateRows(evaluation.rows), view_width);
  PrintRolloutEnds(evaluation);
}

void WriteEvalFramesCsv(const std::string& path,
                        const CheckpointEvaluation& evaluation) {
  std::string csv =
      "clip,view,rollout,start_frame,step,frame,keypoints_present,mean_px,"
      "worst_px,worst_keypoint,worst_view,pa_mm,end\n";
  char numbers[160];
  for (const EvalRow& row : evaluation.rows) {
    const std::vector<std::string> views = SplitViewNames(row.view);
    for (size_t r = 0; r < row.rollouts.size(); ++r) {
      const EvalRollout& rollout = row.rollouts[r];
      for (size_t step = 0; step < rollout.trace.size(); ++step) {
        const EvalFrame& frame = rollout.trace[step];
        std::snprintf(numbers, sizeof(numbers), "%zu,%d,%zu,%d,%d,%.2f,%.2f,",
                      r, rollout.start_frame, step + 1, frame.frame,
                      frame.keypoints_present, frame.mean_px, frame.worst_px);
        csv += row.bundle + "," + row.view + "," + numbers +
               KeypointName(evaluation, frame.worst_keypoint) + "," +
               views[std::min<size_t>(frame.worst_view, views.size() - 1)] +
               "," + (frame.pa_mm < 0 ? "" : Cell(frame.pa_mm, "%.1f")) + "," +
               (step + 1 == rollout.trace.size() ? RolloutEndName(rollout.end)
                                                 : "") +
               "\n";
      }
    }
  }
  WriteFileAtomic(path, csv);
}

void WriteEvalJson(const std::string& path, const std::string& checkpoint,
                   const EvalOptions& options,
                   const CheckpointEvaluation& evaluation) {
  const std::vector<EvalRow>& rows = evaluation.rows;
  nlohmann::json json = {
      {"checkpoint", checkpoint},
      {"starts", SourceName(evaluation.sources.initial_states)},
      {"cameras", SourceName(evaluation.sources.cameras)},
      {"starts_from_checkpoint_buffers", evaluation.checkpoint_buffers},
      {"camera", SettingName(evaluation.camera)},
      {"episode_s", options.episode_s},
      {"success_threshold_px", options.success_threshold_px},
      {"success_measure", SettingName(options.success_measure)},
      {"views_at_once", options.num_views},
      {"push_force_n", options.pushes.force_n},
      {"push_every_s", options.pushes.every_s},
      {"push_duration_s", options.pushes.duration_s},
      {"object_start_square_m", options.object_start_square_m},
      {"perturbation_seed", options.perturbation_seed},
      {"rows", nlohmann::json::array()},
      {"all", RowToJson(AggregateRows(rows))}};
  for (const EvalRow& row : rows) json["rows"].push_back(RowToJson(row));
  WriteJsonFileAtomic(path, json, 2);
}

EpisodeSummary RenderCheckpointRollout(const std::string& checkpoint,
                                       const ReferenceBundle& bundle,
                                       const BundleReplayOptions& replay,
                                       int start_frame, double episode_s,
                                       const SourceOverrides& sources) {
  TorchPolicy policy(checkpoint);
  const TrainConfig& config = policy.config();
  TrackingTask task = BuildTrackingTask(
      LoadCharacterForSimulation(TrainedCharacterPath(config),
                                 config.data.scene, config.env.simulation),
      {bundle}, PolicyTaskOptions(config, sources));
  const std::shared_ptr<const Character>& character = task.character;
  const TrackingReference& reference = *task.reference;
  int view_index = 0;
  for (size_t v = 0; v < bundle.views.size(); ++v) {
    if (bundle.views[v].name == replay.view) view_index = static_cast<int>(v);
  }
  if (start_frame < 0 || start_frame >= bundle.num_frames() - 1) {
    throw ConfigError("--start-frame must be in [0, " +
                      std::to_string(bundle.num_frames() - 2) + "]");
  }
  // The rollout ends as eval's would (the success rule, no pushes), not at
  // training's own early exit.
  EvalOptions judged;
  judged.episode_s = episode_s;
  const TrackingEnvOptions env_options = JudgedEnvOptions(config.env, judged);
  TrackingEnv env(character, task.reference, task.initial_states, env_options,
                  0);
  RecordedFrames frames(RecordPolicyRollout(
      policy, env, reference, *task.initial_states, view_index, start_frame));
  const Clip2D& clip = bundle.views[view_index].clip;
  EpisodeRenderOptions render = replay.render;
  render.pose_label = "character (policy)";
  return RenderViewFrames(frames, character, config.env.simulation, clip,
                          bundle.fps, render, replay);
}

}  // namespace m2d::cli
