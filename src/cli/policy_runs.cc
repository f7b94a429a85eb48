#include "cli/policy_runs.h"

#include <cstdio>
#include <filesystem>
#include <memory>

#include "common/error.h"
#include "common/file_io.h"
#include "motion/bundle.h"
#include "render/policy_rollout.h"
#include "rl/torch_policy.h"

namespace m2d::cli {
namespace {

// Checkpoints keep the training's paths, relative to where it ran (the
// repository root); from elsewhere, find the character there.
std::shared_ptr<const Character> LoadTrainedCharacter(
    const TrainConfig& config) {
  std::string path = config.data.character_config;
  if (!std::filesystem::exists(path) &&
      std::filesystem::path(path).is_relative()) {
    const std::string in_repository =
        std::string(MIMIC2D_SOURCE_DIR) + "/" + path;
    if (std::filesystem::exists(in_repository)) path = in_repository;
  }
  return LoadCharacterForSimulation(path, config.data.scene,
                                    config.env.simulation);
}

std::string Cell(double value, const char* format) {
  if (value < 0) return "-";
  char text[32];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

void PrintRow(const EvalRow& row) {
  std::printf(
      "%-22s %-7s %5d %7.0f %7s %8s %8s %9s %11s %7s\n", row.bundle.c_str(),
      row.view.c_str(), row.episodes, row.mean_frames,
      Cell(100 * row.succ, "%.1f").c_str(), Cell(row.e2d_px, "%.1f").c_str(),
      Cell(row.eo2d_px, "%.1f").c_str(), Cell(row.e3d_mm, "%.0f").c_str(),
      Cell(row.e3d_root_mm, "%.0f").c_str(), Cell(row.jitter, "%.2f").c_str());
}

nlohmann::json RowToJson(const EvalRow& row) {
  auto optional = [](double v) {
    return v < 0 ? nlohmann::json() : nlohmann::json(v);
  };
  nlohmann::json json = {{"clip", row.bundle},
                         {"view", row.view},
                         {"episodes", row.episodes},
                         {"succ", row.succ},
                         {"e2d_px", row.e2d_px},
                         {"eo2d_px", optional(row.eo2d_px)},
                         {"e3d_mm", optional(row.e3d_mm)},
                         {"e3d_root_mm", optional(row.e3d_root_mm)},
                         {"jitter", row.jitter},
                         {"mean_frames", row.mean_frames}};
  if (!row.rollouts.empty()) {
    json["rollouts"] = nlohmann::json::array();
    for (const EvalRollout& rollout : row.rollouts) {
      json["rollouts"].push_back({{"start_frame", rollout.start_frame},
                                  {"frames", rollout.frames},
                                  {"succeeded", rollout.succeeded},
                                  {"e2d_px", rollout.e2d_px}});
    }
  }
  return json;
}

}  // namespace

std::vector<EvalRow> EvaluateCheckpoint(
    const std::string& checkpoint, const std::vector<std::string>& bundle_paths,
    const EvalOptions& options) {
  TorchPolicy policy(checkpoint);
  const TrainConfig& config = policy.config();
  std::vector<std::string> paths =
      bundle_paths.empty() ? config.data.bundles : bundle_paths;
  auto character = LoadTrainedCharacter(config);
  std::vector<ReferenceBundle> bundles;
  for (const std::string& path : paths) bundles.push_back(ReadBundle(path));
  auto reference = TrackingReference::Prepare(std::move(bundles), *character,
                                              config.env.simulation.control_hz);
  // Noise-free initial states (sigma 0), whatever the run trained with.
  auto states = std::make_shared<InitialStates>(
      *reference, character, config.env.simulation, StateBufferOptions());
  return EvaluatePolicy(policy, character, reference, states, config.env,
                        options);
}

void PrintEvalTable(const std::vector<EvalRow>& rows) {
  std::printf("%-22s %-7s %5s %7s %7s %8s %8s %9s %11s %7s\n", "clip", "view",
              "eps", "frames", "Succ%", "E2D(px)", "EO2D(px)", "E3D(mm)",
              "E3Droot(mm)", "Jitter");
  for (const EvalRow& row : rows) PrintRow(row);
  PrintRow(AggregateRows(rows));
}

void WriteEvalJson(const std::string& path, const std::string& checkpoint,
                   const EvalOptions& options,
                   const std::vector<EvalRow>& rows) {
  nlohmann::json json = {{"checkpoint", checkpoint},
                         {"episode_s", options.episode_s},
                         {"success_threshold_px", options.success_threshold_px},
                         {"rows", nlohmann::json::array()},
                         {"all", RowToJson(AggregateRows(rows))}};
  for (const EvalRow& row : rows) json["rows"].push_back(RowToJson(row));
  WriteJsonFileAtomic(path, json, 2);
}

EpisodeSummary RenderCheckpointRollout(const std::string& checkpoint,
                                       const ReferenceBundle& bundle,
                                       const BundleReplayOptions& replay,
                                       int start_frame, double episode_s) {
  TorchPolicy policy(checkpoint);
  const TrainConfig& config = policy.config();
  auto character = LoadTrainedCharacter(config);
  auto reference = TrackingReference::Prepare({bundle}, *character,
                                              config.env.simulation.control_hz);
  // Noise-free initial states (sigma 0), whatever the run trained with.
  auto states = std::make_shared<InitialStates>(
      *reference, character, config.env.simulation, StateBufferOptions());
  int view_index = 0;
  for (size_t v = 0; v < bundle.views.size(); ++v) {
    if (bundle.views[v].name == replay.view) view_index = static_cast<int>(v);
  }
  if (start_frame < 0 || start_frame >= bundle.num_frames() - 1) {
    throw ConfigError("--start-frame must be in [0, " +
                      std::to_string(bundle.num_frames() - 2) + "]");
  }
  TrackingEnvOptions env_options = config.env;
  env_options.max_episode_s = episode_s;
  TrackingEnv env(character, reference, states, env_options, 0);
  RecordedFrames frames(RecordPolicyRollout(policy, env, *reference, *states,
                                            view_index, start_frame));
  const Clip2D& clip = bundle.views[view_index].clip;
  EpisodeRenderOptions render = replay.render;
  render.pose_label = "character (policy)";
  EpisodeRenderer renderer(character, config.env.simulation,
                           character->keypoint_layout(), clip.image_width_px,
                           clip.image_height_px, render);
  return RenderEpisode(frames, renderer, replay.output);
}

}  // namespace m2d::cli
