// cli: `mimic2d bench train` — parses and calls rl/train_benchmark.h
// (docs/benchmarks.md).
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "rl/train_benchmark.h"

namespace m2d::cli {

void AddBenchTrainSubcommand(CLI::App* bench, CommandRun* run) {
  auto options = std::make_shared<TrainBenchmarkOptions>();
  CLI::App* train = bench->add_subcommand(
      "train",
      "End-to-end training samples/s (simulation + inference + PPO update + "
      "ASI) of a config, per LibTorch thread count, precision and collection "
      "mode and overlapped, against its simulation-only bound");
  train->add_option("config", options->config_path, "Training config (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  train
      ->add_option("--iterations", options->iterations,
                   "Timed iterations per setting")
      ->capture_default_str();
  train
      ->add_option("--warmup", options->warmup_iterations,
                   "Untimed iterations before timing")
      ->capture_default_str();
  train
      ->add_option("--torch-threads", options->torch_threads,
                   "LibTorch thread counts to measure; the first is the "
                   "baseline")
      ->delimiter(',')
      ->capture_default_str();
  auto precisions = std::make_shared<std::vector<std::string>>();
  train
      ->add_option("--precision", *precisions,
                   "Arithmetic precisions to measure at each thread count "
                   "(fp32, bf16; default: the config's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"fp32", "bf16"}));
  auto collections = std::make_shared<std::vector<std::string>>();
  train
      ->add_option("--collection", *collections,
                   "Collection modes to measure at each thread count and "
                   "precision (batched, per_thread; default: the config's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"batched", "per_thread"}));
  train->add_flag("--overlap,!--no-overlap", options->overlap,
                  "Also measure agent.overlap_update (default on)");
  train
      ->add_option("--bound-steps", options->bound_steps,
                   "Control steps of the simulation-only bound")
      ->capture_default_str();
  train->callback([run, options, precisions, collections] {
    // CLI::IsMember checked the names.
    for (const std::string& text : *precisions) {
      TrainingPrecision precision;
      ParseSetting(text, &precision);
      options->precisions.push_back(precision);
    }
    for (const std::string& text : *collections) {
      CollectionMode collection;
      ParseSetting(text, &collection);
      options->collections.push_back(collection);
    }
    *run = [options] {
      RunTrainBenchmark(*options);
      return 0;
    };
  });
}

}  // namespace m2d::cli
