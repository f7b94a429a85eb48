#include "eval/env_benchmark.h"

#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/error.h"
#include "env/reference.h"
#include "env/task.h"
#include "env/tracking_env.h"
#include "env/vec_env.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "sim/pose_mapping.h"
#include "sim/simulation.h"

namespace m2d {
namespace {

// CPU time this process used (all threads), and that all CPUs were busy
// (user + nice + system + irq + softirq + steal, from /proc/stat; 0 where
// there is none).
double OwnCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double SystemBusySeconds() {
  std::ifstream stat("/proc/stat");
  std::string cpu;
  double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0,
         softirq = 0, steal = 0;
  stat >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >>
      steal;
  if (!stat) return 0.0;
  return (user + nice + system + irq + softirq + steal) /
         static_cast<double>(sysconf(_SC_CLK_TCK));
}

// Runs in which other processes kept less than this many cores busy on
// average count as quiet; the figures are medians over quiet runs (over all
// runs, flagged, when none was quiet).
constexpr double kQuietOtherCores = 0.1;

// Wall time of a timed run, and how many cores other processes kept busy
// meanwhile, so that runs disturbed by, say, a compiler on the same cores
// can be told apart.
class Stopwatch {
 public:
  void Start() {
    start_ = std::chrono::steady_clock::now();
    own_start_s_ = OwnCpuSeconds();
    busy_start_s_ = SystemBusySeconds();
  }
  void Stop() {
    elapsed_s_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_)
            .count();
    const double own_s = OwnCpuSeconds() - own_start_s_;
    const double busy_s = SystemBusySeconds() - busy_start_s_;
    other_cores_ = std::max(0.0, (busy_s - own_s) / elapsed_s_);
  }
  double elapsed_s() const { return elapsed_s_; }
  double other_cores() const { return other_cores_; }

 private:
  std::chrono::steady_clock::time_point start_;
  double own_start_s_ = 0.0, busy_start_s_ = 0.0;
  double elapsed_s_ = 0.0, other_cores_ = 0.0;
};

// Waits until other processes keep fewer than kQuietOtherCores busy over a
// 0.5 s window, or `max_wait_s` passed. Returns whether it got quiet.
bool WaitForQuiet(double max_wait_s) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(max_wait_s);
  do {
    Stopwatch window;
    window.Start();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    window.Stop();
    if (window.other_cores() < kQuietOtherCores) return true;
  } while (std::chrono::steady_clock::now() < deadline);
  return false;
}

// A tracking task: the humanoid on the flat floor and one 4-view bundle.
struct Task {
  std::shared_ptr<const Character> character;
  std::shared_ptr<const TrackingReference> reference;
  std::shared_ptr<InitialStates> initial_states;
  TrackingEnvOptions options;
  std::string description;
};

// Without the shared motion data the reference is the humanoid's default
// standing pose held still (its ground-truth poses give the initial states),
// so the environment still does all of its per-step work.
Motion3D StandingMotion(const Character& character, double duration_s,
                        double fps) {
  Motion3D motion;
  motion.skeleton = character.shared_skeleton();
  motion.fps = fps;
  const Pose3D standing = QposToPose(character, character.model()->qpos0);
  motion.frames.assign(static_cast<size_t>(duration_s * fps) + 1, standing);
  return motion;
}

Task MakeTask(const EnvBenchmarkOptions& options) {
  Task task;
  task.options.simulation.torque_limit = options.torque_limit;
  task.character = LoadCharacterForSimulation(options.character_config, "flat",
                                              task.options.simulation);
  const bool have_motion = std::filesystem::exists(options.motion);
  Motion3D motion = have_motion
                        ? ReadDeepMimicMotion(options.motion,
                                              task.character->shared_skeleton())
                        : StandingMotion(*task.character, options.reference_s,
                                         task.options.simulation.control_hz);
  BundleFromMotionOptions bundle_options;
  bundle_options.fps = task.options.simulation.control_hz;
  bundle_options.duration_s = options.reference_s;
  bundle_options.follow = CameraFollow::kRootDolly;
  std::string name = have_motion
                         ? std::filesystem::path(options.motion).stem().string()
                         : "standing";
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(MakeBundleFromMotion(motion, task.character->keypoint_map(),
                                         bundle_options, name));
  task.description =
      have_motion ? name + " (" + options.motion + ")"
                  : "the default standing pose held still (shared motion "
                    "data absent: " +
                        options.motion + ")";
  TrackingTaskOptions task_options;
  task_options.simulation = task.options.simulation;
  TrackingTask built =
      BuildTrackingTask(task.character, std::move(bundles), task_options);
  task.reference = built.reference;
  task.initial_states = built.initial_states;
  return task;
}

// What every loop replays, recorded once from the environment: random
// actions (uniform in [-1, 1], held for a control step) and, per step and
// world, the state the environment restarted that world in.
struct Workload {
  int num_envs = 0;
  int num_steps = 0;  // warm-up + timed
  int warmup_steps = 0;
  int action_size = 0;
  int observation_size = 0;
  std::vector<float> actions;          // steps x envs x action_size
  std::vector<SimState> start_states;  // per world, after VecEnv::Reset
  // Steps x envs: index into restart_states, -1 if no restart followed.
  std::vector<int> restart_index;
  std::vector<SimState> restart_states;

  const float* action(int step, int env) const {
    return actions.data() +
           (static_cast<size_t>(step) * num_envs + env) * action_size;
  }
  int restart(int step, int env) const {
    return restart_index[static_cast<size_t>(step) * num_envs + env];
  }
  int timed_steps() const { return num_steps - warmup_steps; }
};

Workload MakeActions(int num_envs, int num_steps, int warmup_steps,
                     int action_size, uint64_t seed) {
  Workload workload;
  workload.num_envs = num_envs;
  workload.num_steps = num_steps;
  workload.warmup_steps = warmup_steps;
  workload.action_size = action_size;
  workload.actions.resize(static_cast<size_t>(num_steps) * num_envs *
                          action_size);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (float& action : workload.actions) action = uniform(rng);
  return workload;
}

// Runs the environment through the workload's actions and records where
// and into which state it restarted each world.
void RecordRestarts(const Task& task, const EnvBenchmarkOptions& options,
                    Workload* workload) {
  VecEnv envs(task.character, task.reference, task.initial_states, task.options,
              workload->num_envs, options.seed, 1);
  envs.Reset();
  workload->observation_size = envs.observation_size();
  workload->start_states.resize(workload->num_envs);
  for (int i = 0; i < workload->num_envs; ++i)
    envs.env(i).simulation().Save(&workload->start_states[i]);
  workload->restart_index.assign(
      static_cast<size_t>(workload->num_steps) * workload->num_envs, -1);
  workload->restart_states.clear();
  const size_t row =
      static_cast<size_t>(workload->num_envs) * workload->action_size;
  for (int step = 0; step < workload->num_steps; ++step) {
    std::copy_n(workload->action(step, 0), row, envs.actions());
    envs.Step();
    for (int i = 0; i < workload->num_envs; ++i) {
      if (!envs.terminated()[i] && !envs.truncated()[i]) continue;
      workload
          ->restart_index[static_cast<size_t>(step) * workload->num_envs + i] =
          static_cast<int>(workload->restart_states.size());
      workload->restart_states.push_back(envs.env(i).simulation().Save());
    }
  }
}

// One timed run: control steps per second over all worlds, and where the
// worlds ended (to check that the loops integrated the same trajectories).
struct RunResult {
  double steps_per_s = 0.0;
  double other_cores = 0.0;        // see Stopwatch
  std::vector<double> final_qpos;  // worlds x nq
};

RunResult Timed(const Workload& workload, const Stopwatch& stopwatch) {
  RunResult result;
  result.steps_per_s = static_cast<double>(workload.timed_steps()) *
                       workload.num_envs / stopwatch.elapsed_s();
  result.other_cores = stopwatch.other_cores();
  return result;
}

void AppendQpos(const Simulation& simulation, std::vector<double>* qpos) {
  const mjData* data = simulation.data();
  qpos->insert(qpos->end(), data->qpos, data->qpos + simulation.model()->nq);
}

// The environment: VecEnv::Step with its auto-reset, `threads` threads.
RunResult RunEnv(const Task& task, const EnvBenchmarkOptions& options,
                 const Workload& workload, int threads) {
  VecEnv envs(task.character, task.reference, task.initial_states, task.options,
              workload.num_envs, options.seed, threads);
  envs.Reset();
  const size_t row =
      static_cast<size_t>(workload.num_envs) * workload.action_size;
  Stopwatch stopwatch;
  for (int step = 0; step < workload.num_steps; ++step) {
    if (step == workload.warmup_steps) stopwatch.Start();
    std::copy_n(workload.action(step, 0), row, envs.actions());
    envs.Step();
  }
  stopwatch.Stop();
  RunResult result = Timed(workload, stopwatch);
  for (int i = 0; i < workload.num_envs; ++i)
    AppendQpos(envs.env(i).simulation(), &result.final_qpos);
  return result;
}

enum class PhysicsLoop {
  kBareMjStep,      // PD targets into ctrl, then mj_step x substeps
  kSimulationStep,  // Simulation::Step (adds torque bookkeeping, checks)
  // The bare physics, but each thread runs its worlds through all steps
  // without waiting for the others at every step: the scaling the hardware
  // allows this work when no synchronization or imbalance gets in the way.
  kBareFreeRunning,
};

// A world of the physics-only loops and its PD-target scratch.
struct PhysicsWorld {
  std::unique_ptr<Simulation> sim;
  std::vector<double> targets_rad;
};

// The workload's worlds in their start states.
std::vector<PhysicsWorld> MakeWorlds(const Task& task,
                                     const Workload& workload) {
  std::vector<PhysicsWorld> worlds(workload.num_envs);
  for (int i = 0; i < workload.num_envs; ++i) {
    worlds[i].sim =
        std::make_unique<Simulation>(task.character, task.options.simulation);
    worlds[i].sim->Restore(workload.start_states[i]);
    worlds[i].targets_rad.resize(task.character->num_actions());
  }
  return worlds;
}

// One control step of world `i`, then its restart if the environment
// restarted it after this step.
void StepWorld(const Task& task, const Workload& workload, PhysicsLoop loop,
               int step, int i, PhysicsWorld* world) {
  const float* action = workload.action(step, i);
  if (loop == PhysicsLoop::kSimulationStep) {
    world->sim->Step(action);
  } else {
    const mjModel* model = task.character->model();
    const std::vector<ActuatedHinge>& hinges = task.character->hinges();
    mjData* data = world->sim->mutable_data();
    world->sim->ActionsToTargets(action, world->targets_rad.data());
    for (size_t h = 0; h < hinges.size(); ++h)
      data->ctrl[hinges[h].actuator_id] = world->targets_rad[h];
    try {
      for (int s = 0; s < task.options.simulation.physics_substeps; ++s)
        mj_step(model, data);
    } catch (const MujocoError&) {
      mj_resetData(model, data);  // as Simulation does; then restarted
    }
  }
  const int restart = workload.restart(step, i);
  if (restart >= 0) world->sim->Restore(workload.restart_states[restart]);
}

// The physics alone, replaying the environment's actions and restarts.
// Restarts go through Simulation::Restore, as the environment's do.
RunResult RunPhysics(const Task& task, const Workload& workload,
                     PhysicsLoop loop, int threads) {
  const int num_worlds = workload.num_envs;
  std::vector<PhysicsWorld> worlds = MakeWorlds(task, workload);
  // Warm-up (and, but for free running, the timed steps) in lockstep and
  // scheduled as VecEnv steps its environments.
  const int lockstep_end = loop == PhysicsLoop::kBareFreeRunning
                               ? workload.warmup_steps
                               : workload.num_steps;
  Stopwatch stopwatch;
  for (int step = 0; step < lockstep_end; ++step) {
    if (step == workload.warmup_steps) stopwatch.Start();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < num_worlds; ++i)
      StepWorld(task, workload, loop, step, i, &worlds[i]);
  }
  if (loop == PhysicsLoop::kBareFreeRunning) {
    stopwatch.Start();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int i = 0; i < num_worlds; ++i) {
      for (int step = workload.warmup_steps; step < workload.num_steps; ++step)
        StepWorld(task, workload, loop, step, i, &worlds[i]);
    }
  }
  stopwatch.Stop();
  RunResult result = Timed(workload, stopwatch);
  for (const PhysicsWorld& world : worlds)
    AppendQpos(*world.sim, &result.final_qpos);
  return result;
}

// How much a world's control step costs, and how evenly that lets a
// lockstep loop (every thread waits for the others after each step) split
// the worlds between threads.
struct LoadBalance {
  double mean_us = 0.0, cv = 0.0, p10_us = 0.0, p50_us = 0.0, p90_us = 0.0;
  // Speedup over one thread if only the waiting cost anything.
  double static_bound = 1.0;   // contiguous blocks of worlds per thread
  double dynamic_bound = 1.0;  // next free thread takes the next world
};

// Per step, the time the slowest of `threads` threads needs for its share.
double StaticMakespan(const double* costs, int num_worlds, int threads) {
  const int block = (num_worlds + threads - 1) / threads;
  double slowest = 0.0;
  for (int start = 0; start < num_worlds; start += block) {
    double sum = 0.0;
    for (int i = start; i < std::min(num_worlds, start + block); ++i)
      sum += costs[i];
    slowest = std::max(slowest, sum);
  }
  return slowest;
}

double DynamicMakespan(const double* costs, int num_worlds, int threads) {
  std::vector<double> busy_until(threads, 0.0);
  for (int i = 0; i < num_worlds; ++i)
    *std::min_element(busy_until.begin(), busy_until.end()) += costs[i];
  return *std::max_element(busy_until.begin(), busy_until.end());
}

// `costs_s`: per step, one cost per world.
LoadBalance SummarizeCosts(std::vector<double> costs_s, int num_worlds,
                           int threads) {
  LoadBalance balance;
  double serial_s = 0.0, static_s = 0.0, dynamic_s = 0.0;
  for (size_t row = 0; row < costs_s.size(); row += num_worlds) {
    static_s += StaticMakespan(&costs_s[row], num_worlds, threads);
    dynamic_s += DynamicMakespan(&costs_s[row], num_worlds, threads);
  }
  double squares = 0.0;
  for (double cost : costs_s) {
    serial_s += cost;
    squares += cost * cost;
  }
  const double count = static_cast<double>(costs_s.size());
  const double mean_s = serial_s / count;
  balance.mean_us = 1e6 * mean_s;
  balance.cv =
      std::sqrt(std::max(0.0, squares / count - mean_s * mean_s)) / mean_s;
  std::sort(costs_s.begin(), costs_s.end());
  balance.p10_us = 1e6 * costs_s[costs_s.size() / 10];
  balance.p50_us = 1e6 * costs_s[costs_s.size() / 2];
  balance.p90_us = 1e6 * costs_s[costs_s.size() * 9 / 10];
  balance.static_bound = serial_s / static_s;
  balance.dynamic_bound = serial_s / dynamic_s;
  return balance;
}

// Times every world's step of the bare-physics loop on one thread.
LoadBalance MeasureLoadBalance(const Task& task, const Workload& workload,
                               int threads) {
  std::vector<PhysicsWorld> worlds = MakeWorlds(task, workload);
  std::vector<double> costs_s;  // timed steps x worlds
  for (int step = 0; step < workload.num_steps; ++step) {
    for (int i = 0; i < workload.num_envs; ++i) {
      const auto start = std::chrono::steady_clock::now();
      StepWorld(task, workload, PhysicsLoop::kBareMjStep, step, i, &worlds[i]);
      const std::chrono::duration<double> cost =
          std::chrono::steady_clock::now() - start;
      if (step >= workload.warmup_steps) costs_s.push_back(cost.count());
    }
  }
  return SummarizeCosts(std::move(costs_s), workload.num_envs, threads);
}

double MaxAbsDifference(const std::vector<double>& a,
                        const std::vector<double>& b) {
  double worst = 0.0;
  for (size_t k = 0; k < a.size() && k < b.size(); ++k)
    worst = std::max(worst, std::abs(a[k] - b[k]));
  return worst;
}

struct Series {
  std::string label;
  int threads = 1;
  std::vector<RunResult> runs;

  std::vector<double> Rates(bool quiet_only) const {
    std::vector<double> rates;
    for (const RunResult& run : runs) {
      if (!quiet_only || run.other_cores < kQuietOtherCores)
        rates.push_back(run.steps_per_s);
    }
    return rates;
  }
  int num_quiet() const { return static_cast<int>(Rates(true).size()); }
  double Median() const {
    std::vector<double> rates = Rates(num_quiet() > 0);
    std::sort(rates.begin(), rates.end());
    const size_t n = rates.size();
    return n % 2 ? rates[n / 2] : 0.5 * (rates[n / 2 - 1] + rates[n / 2]);
  }
  double Best() const {
    std::vector<double> rates = Rates(false);
    return *std::max_element(rates.begin(), rates.end());
  }
  double MaxOtherCores() const {
    double worst = 0.0;
    for (const RunResult& run : runs) worst = std::max(worst, run.other_cores);
    return worst;
  }
};

// Timed steps for about `seconds` of the slowest loop (the environment on
// one thread), from a short calibration run.
int CalibrateTimedSteps(const Task& task, const EnvBenchmarkOptions& options,
                        int action_size) {
  const int calibration_steps = 20;
  Workload probe =
      MakeActions(options.num_envs, options.warmup_steps + calibration_steps,
                  options.warmup_steps, action_size, options.seed);
  RecordRestarts(task, options, &probe);
  const double rate = RunEnv(task, options, probe, 1).steps_per_s;
  return std::max(10,
                  static_cast<int>(options.seconds * rate / options.num_envs));
}

void PrintHeader(const Task& task, const EnvBenchmarkOptions& options,
                 const Workload& workload) {
  const SimulationOptions& sim = task.options.simulation;
  const TrackedView& view = task.reference->views().front();
  int episodes = 0;
  for (int index : workload.restart_index) episodes += index >= 0;
  double load[1] = {0.0};
  getloadavg(load, 1);
  std::printf("mimic2d bench env\n");
  std::printf("  reference   %s: %zu views x %d frames\n",
              task.description.c_str(), task.reference->views().size(),
              view.num_frames);
  std::printf(
      "  physics     humanoid on the flat floor, %d substeps per control "
      "step (%.0f Hz control, %.0f Hz physics), torque_limit %s\n",
      sim.physics_substeps, sim.control_hz,
      sim.control_hz * sim.physics_substeps, SettingName(sim.torque_limit));
  std::printf("  observation %d floats, %d actions\n",
              workload.observation_size, workload.action_size);
  std::printf(
      "  workload    %d worlds; %d warm-up + %d timed control steps; actions "
      "uniform in [-1, 1] held per step; %d episode restarts (mean episode "
      "%.1f steps), replayed identically by every loop\n",
      workload.num_envs, workload.warmup_steps, workload.timed_steps(),
      episodes,
      episodes ? static_cast<double>(workload.num_steps) * workload.num_envs /
                     episodes
               : 0.0);
  std::printf(
      "  machine     %d cores, load average %.2f at start; %d runs "
      "per loop, median reported\n\n",
      omp_get_num_procs(), load[0], options.repeats);
}

void PrintTable(const std::vector<Series>& series) {
  std::printf("%-44s %7s %12s %12s %7s %12s\n", "loop", "threads", "steps/s",
              "best", "quiet", "other load");
  for (const Series& s : series) {
    std::printf("%-44s %7d %12.0f %12.0f %3d/%-3d %8.2f max\n", s.label.c_str(),
                s.threads, s.Median(), s.Best(), s.num_quiet(),
                static_cast<int>(s.runs.size()), s.MaxOtherCores());
  }
  std::printf(
      "(steps/s: median over quiet runs, those in which other processes kept "
      "< %.1f cores busy; other load: cores they kept busy, worst run)\n\n",
      kQuietOtherCores);
}

const char* Verdict(double value, double target) {
  return value >= target ? "met" : "MISSED";
}

}  // namespace

void RunEnvBenchmark(EnvBenchmarkOptions options) {
  // Outline: build the task, record a workload from the environment, time
  // each loop on it (interleaved, repeated), print medians and targets.
  options.Validate();
  Task task = MakeTask(options);
  const int action_size = task.character->num_actions();
  const int timed_steps = CalibrateTimedSteps(task, options, action_size);
  Workload workload =
      MakeActions(options.num_envs, options.warmup_steps + timed_steps,
                  options.warmup_steps, action_size, options.seed);
  RecordRestarts(task, options, &workload);
  PrintHeader(task, options, workload);

  std::vector<int> thread_counts;
  for (int t = 1; t <= options.threads_max; ++t) thread_counts.push_back(t);
  const std::string substeps =
      std::to_string(task.options.simulation.physics_substeps);
  std::vector<Series> free_running, bare, simulation, env;
  for (int threads : thread_counts) {
    free_running.push_back({"bare physics, no per-step barrier", threads, {}});
    bare.push_back(
        {"bare physics: PD targets + mj_step x" + substeps, threads, {}});
    simulation.push_back({"Simulation::Step", threads, {}});
    env.push_back({"TrackingEnv via VecEnv::Step (auto-reset)", threads, {}});
  }
  auto settle = [&options] {
    if (options.quiet_wait_s > 0) WaitForQuiet(options.quiet_wait_s);
  };
  double worst_replay_gap = 0.0;
  for (int repeat = 0; repeat < options.repeats; ++repeat) {
    for (size_t t = 0; t < thread_counts.size(); ++t) {
      settle();
      free_running[t].runs.push_back(RunPhysics(
          task, workload, PhysicsLoop::kBareFreeRunning, thread_counts[t]));
      settle();
      RunResult bare_run = RunPhysics(task, workload, PhysicsLoop::kBareMjStep,
                                      thread_counts[t]);
      settle();
      RunResult sim_run = RunPhysics(
          task, workload, PhysicsLoop::kSimulationStep, thread_counts[t]);
      settle();
      RunResult env_run = RunEnv(task, options, workload, thread_counts[t]);
      bare[t].runs.push_back(bare_run);
      simulation[t].runs.push_back(sim_run);
      env[t].runs.push_back(env_run);
      // Under a PD limit the bare loops still drive MuJoCo's servos as
      // under kServo: the same work, not the same trajectories.
      if (options.torque_limit == TorqueLimit::kServo) {
        worst_replay_gap =
            std::max(worst_replay_gap,
                     MaxAbsDifference(bare_run.final_qpos, env_run.final_qpos));
      }
      worst_replay_gap =
          std::max(worst_replay_gap,
                   MaxAbsDifference(sim_run.final_qpos, env_run.final_qpos));
    }
  }

  std::vector<Series> rows;
  for (size_t t = 0; t < thread_counts.size(); ++t) {
    rows.push_back(free_running[t]);
    rows.push_back(bare[t]);
    rows.push_back(simulation[t]);
    rows.push_back(env[t]);
  }
  PrintTable(rows);
  if (options.threads_max > 1) {
    LoadBalance balance =
        MeasureLoadBalance(task, workload, options.threads_max);
    std::printf(
        "one world's control step (bare physics): mean %.0f us, cv %.2f, "
        "p10 %.0f / p50 %.0f / p90 %.0f us\n"
        "lockstep bound on the %d-thread speedup from that spread: static "
        "schedule %.3f, dynamic %.3f (VecEnv's)\n\n",
        balance.mean_us, balance.cv, balance.p10_us, balance.p50_us,
        balance.p90_us, options.threads_max, balance.static_bound,
        balance.dynamic_bound);
  }
  const double ratio = env[0].Median() / bare[0].Median();
  std::printf(
      "env / bare physics, 1 thread        %5.3f  (target >= 0.85: "
      "%s)\n",
      ratio, Verdict(ratio, 0.85));
  std::printf("Simulation::Step / bare, 1 thread   %5.3f\n",
              simulation[0].Median() / bare[0].Median());
  if (thread_counts.size() > 1) {
    const Series& env_top = env.back();
    const double speedup = env_top.Median() / env[0].Median();
    std::printf(
        "env speedup, %d threads / 1         %5.3f  (target >= %.1f: "
        "%s)\n",
        env_top.threads, speedup, 0.9 * env_top.threads,
        Verdict(speedup, 0.9 * env_top.threads));
    std::printf("bare physics speedup, %d / 1        %5.3f  (same lockstep)\n",
                env_top.threads, bare.back().Median() / bare[0].Median());
    std::printf(
        "no-barrier speedup, %d / 1          %5.3f  (what the cores allow "
        "this work)\n",
        env_top.threads,
        free_running.back().Median() / free_running[0].Median());
  }
  for (const Series& series : env) {
    if (series.threads > 1 && series.num_quiet() == 0) {
      std::printf(
          "warning: other processes shared the cores during every %d-thread "
          "run, so its figures are not meaningful (docs/benchmarks.md, "
          "\"Shared machines\")\n",
          series.threads);
    }
  }
  std::printf(
      "replay check: worlds end within %.3g of the environment's qpos "
      "(0 = identical trajectories%s)\n",
      worst_replay_gap,
      options.torque_limit == TorqueLimit::kServo
          ? ""
          : "; Simulation::Step only: the bare loops drive the servos as "
            "under torque_limit servo");
}

}  // namespace m2d
