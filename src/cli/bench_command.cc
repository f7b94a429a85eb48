// cli: `mimic2d bench` — parses the benchmarks' options and runs them
// (the measurements themselves live in eval/: env_benchmark, fit_benchmark;
// `bench train` in bench_train_command.cc).
#include <memory>
#include <string>

#include "cli/commands.h"
#include "common/error.h"
#include "eval/env_benchmark.h"

namespace m2d::cli {
namespace {

// The walk the env tests track (DeepMimic, MIT, in the repository).
std::string DefaultMotionPath() {
  return AssetPath("motions/deepmimic/humanoid3d_walk.txt");
}

int RunBenchEnv(const EnvBenchmarkOptions& options) {
#ifdef MIMIC2D_HAVE_SIM
  RunEnvBenchmark(options);
  return 0;
#else
  (void)options;
  throw ConfigError("bench env: this build has no simulation (src/sim)");
#endif
}

}  // namespace

void AddBenchCommand(CLI::App& app, CommandRun* run) {
  CLI::App* bench =
      app.add_subcommand("bench", "Measure throughput (docs/benchmarks.md)");
  bench->require_subcommand(1);
  auto options = std::make_shared<EnvBenchmarkOptions>();
  options->motion = DefaultMotionPath();
  options->character_config = AssetPath("characters/humanoid.yaml");
  CLI::App* env = bench->add_subcommand(
      "env",
      "Tracking-environment steps/s against bare mj_step on the same "
      "workload, and the speedup from 1 to N threads");
  env->add_option("--motion", options->motion,
                  "DeepMimic motion to track (absent: the standing pose)")
      ->capture_default_str();
  env->add_option("--envs", options->num_envs, "Parallel worlds")
      ->capture_default_str();
  env->add_option("--seconds", options->seconds,
                  "Length of one timed run of the environment (s)")
      ->capture_default_str();
  env->add_option("--threads-max", options->threads_max,
                  "Measure 1..this many threads")
      ->capture_default_str();
  env->add_option("--repeats", options->repeats,
                  "Timed runs per loop (median reported)")
      ->capture_default_str();
  env->add_option("--warmup", options->warmup_steps,
                  "Untimed control steps before each timed run")
      ->capture_default_str();
  env->add_option("--quiet-wait", options->quiet_wait_s,
                  "Before each timed run, wait up to this long (s) for other "
                  "processes to go idle")
      ->capture_default_str();
  env->add_option("--seed", options->seed, "Seed of actions and episodes")
      ->capture_default_str();
  auto torque_limit = std::make_shared<std::string>("servo");
  env->add_option("--torque-limit", *torque_limit,
                  "What the torque limits bound in the environment's loops: "
                  "servo or pd (env.torque_limit; docs/simulation.md)")
      ->check(CLI::IsMember({"servo", "pd"}))
      ->capture_default_str();
  env->callback([run, options, torque_limit] {
    ParseSetting(*torque_limit, &options->torque_limit);
    *run = [options] { return RunBenchEnv(*options); };
  });
  AddBenchTrainSubcommand(bench, run);
  AddBenchFitSubcommand(bench, run);
}

}  // namespace m2d::cli
