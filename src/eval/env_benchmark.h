// eval: `mimic2d bench env` — throughput of the tracking environment
// against the bare physics it runs on, and its scaling from 1 to N threads
// (docs/benchmarks.md). Every measured loop replays one recorded workload:
// the same actions and the same episode restarts at the same steps, so the
// physics integrates the same trajectories (same contacts) in all of them.
#ifndef MIMIC2D_EVAL_ENV_BENCHMARK_H_
#define MIMIC2D_EVAL_ENV_BENCHMARK_H_

#include <cstdint>
#include <string>

#include "common/error.h"
#include "sim/simulation.h"

namespace m2d {

struct EnvBenchmarkOptions {
  std::string character_config;  // the humanoid's character YAML
  std::string motion;        // DeepMimic motion to track; "" = standing pose
  int num_envs = 16;         // parallel worlds in every loop
  double seconds = 1.0;      // target length of one timed run (s)
  int threads_max = 2;       // threads 1..threads_max are measured
  int repeats = 5;           // timed runs per loop; the median is reported
  int warmup_steps = 30;     // untimed control steps before each timed run
  double reference_s = 4.0;  // length of the reference clip (s)
  // Before each timed run, wait up to this long for other processes to go
  // idle (for shared machines); 0 runs at once.
  double quiet_wait_s = 0.0;
  uint64_t seed = 1;
  // What the torque limits bound in the environment and Simulation loops
  // (the bare loops drive MuJoCo's servos directly, as under kServo).
  TorqueLimit torque_limit = TorqueLimit::kServo;

  void Validate() const {
    if (character_config.empty())
      throw ConfigError("bench: no character config");
    if (num_envs < 1) throw ConfigError("bench: --envs must be >= 1");
    if (!(seconds > 0)) throw ConfigError("bench: --seconds must be > 0");
    if (threads_max < 1) throw ConfigError("bench: --threads-max must be >= 1");
    if (repeats < 1) throw ConfigError("bench: --repeats must be >= 1");
    if (warmup_steps < 0) throw ConfigError("bench: --warmup must be >= 0");
    if (!(quiet_wait_s >= 0))
      throw ConfigError("bench: --quiet-wait must be >= 0");
  }
};

// Runs every loop (interleaved, repeated) and prints the report: the
// workload, a table of medians, the load-balance bound, the targets.
void RunEnvBenchmark(EnvBenchmarkOptions options);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_ENV_BENCHMARK_H_
