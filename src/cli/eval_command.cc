// cli: `mimic2d eval` — roll a trained policy out on every view of its
// bundles and report Succ, E2D, EO2D, E3D and Jitter (table + JSON).
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "common/file_io.h"
#include "eval/evaluator.h"
#include "motion/bundle.h"
#include "rl/torch_policy.h"

namespace m2d::cli {
namespace {

struct EvalArgs {
  std::string checkpoint;
  std::vector<std::string> bundles;
  std::string output;
  EvalOptions options;
};

std::string Cell(double value, const char* format) {
  if (value < 0) return "-";
  char text[32];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

void PrintRow(const EvalRow& row) {
  std::printf(
      "%-22s %-7s %5d %7s %8s %8s %9s %11s %7s\n", row.bundle.c_str(),
      row.view.c_str(), row.episodes, Cell(100 * row.succ, "%.1f").c_str(),
      Cell(row.e2d_px, "%.1f").c_str(), Cell(row.eo2d_px, "%.1f").c_str(),
      Cell(row.e3d_mm, "%.0f").c_str(), Cell(row.e3d_root_mm, "%.0f").c_str(),
      Cell(row.jitter, "%.2f").c_str());
}

nlohmann::json RowToJson(const EvalRow& row) {
  auto optional = [](double v) {
    return v < 0 ? nlohmann::json() : nlohmann::json(v);
  };
  return {{"clip", row.bundle},
          {"view", row.view},
          {"episodes", row.episodes},
          {"succ", row.succ},
          {"e2d_px", row.e2d_px},
          {"eo2d_px", optional(row.eo2d_px)},
          {"e3d_mm", optional(row.e3d_mm)},
          {"e3d_root_mm", optional(row.e3d_root_mm)},
          {"jitter", row.jitter},
          {"mean_frames", row.mean_frames}};
}

int RunEval(const EvalArgs& args) {
  TorchPolicy policy(args.checkpoint);
  const TrainConfig& config = policy.config();
  std::vector<std::string> paths =
      args.bundles.empty() ? config.data.bundles : args.bundles;
  auto character = LoadCharacterForSimulation(
      config.data.character_config, config.data.scene, config.env.simulation);
  std::vector<ReferenceBundle> bundles;
  for (const std::string& path : paths) bundles.push_back(ReadBundle(path));
  auto reference = TrackingReference::Prepare(std::move(bundles), *character,
                                              config.env.simulation.control_hz);
  auto states = std::make_shared<InitialStates>(
      *reference, character, config.env.simulation, StateBufferOptions());
  std::vector<EvalRow> rows = EvaluatePolicy(policy, character, reference,
                                             states, config.env, args.options);
  std::printf("%-22s %-7s %5s %7s %8s %8s %9s %11s %7s\n", "clip", "view",
              "eps", "Succ%", "E2D(px)", "EO2D(px)", "E3D(mm)", "E3Droot(mm)",
              "Jitter");
  for (const EvalRow& row : rows) PrintRow(row);
  EvalRow all = AggregateRows(rows);
  PrintRow(all);
  if (!args.output.empty()) {
    nlohmann::json json = {
        {"checkpoint", args.checkpoint},
        {"episode_s", args.options.episode_s},
        {"success_threshold_px", args.options.success_threshold_px},
        {"rows", nlohmann::json::array()},
        {"all", RowToJson(all)}};
    for (const EvalRow& row : rows) json["rows"].push_back(RowToJson(row));
    WriteJsonFileAtomic(args.output, json, 2);
    std::printf("wrote %s\n", args.output.c_str());
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
  eval->add_option("--episodes", args->options.episodes_per_view,
                   "Episodes per view")
      ->capture_default_str();
  eval->add_option("--episode-s", args->options.episode_s, "Episode length (s)")
      ->capture_default_str();
  eval->add_option(
          "--success-px", args->options.success_threshold_px,
          "A frame whose worst keypoint is off by more fails the rollout (px)")
      ->capture_default_str();
  eval->add_option("-o,--output", args->output, "Write the table as JSON here");
  eval->callback([run, args] { *run = [args] { return RunEval(*args); }; });
}

}  // namespace m2d::cli
