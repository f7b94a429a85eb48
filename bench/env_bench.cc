// bench: per-control-step cost of the tracking environment and of its parts,
// next to the bare physics it runs on (docs/benchmarks.md). The end-to-end
// comparison on a replayed workload is `mimic2d bench env`; these locate the
// cost. Items = environment (or world) control steps.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "env/reference.h"
#include "env/reference_stream.h"
#include "env/task.h"
#include "env/tracking_env.h"
#include "env/vec_env.h"
#include "motion/bundle.h"
#include "motion/motion_io.h"
#include "sim/pose_mapping.h"
#include "sim/simulation.h"

namespace m2d {
namespace {

// CMake compiles this file by its absolute path: <source>/bench/env_bench.cc.
std::string SourcePath(const std::string& relative) {
  return (std::filesystem::path(__FILE__).parent_path().parent_path() /
          relative)
      .string();
}

// Single-world loops restart every this many control steps (about the mean
// episode length under random actions), cycling through start frames, so
// that the physics-only and the environment loops integrate the same
// trajectories (the environment's early exit is off in them).
constexpr int kEpisodeSteps = 20;
constexpr int kActionRows = 64;

struct BenchTask {
  std::shared_ptr<const Character> character;
  std::shared_ptr<const TrackingReference> reference;
  std::shared_ptr<InitialStates> initial_states;
  TrackingEnvOptions options;
  std::vector<float> actions;  // kActionRows x num_actions, uniform [-1, 1]

  const float* action(int step) const {
    return actions.data() +
           static_cast<size_t>(step % kActionRows) * character->num_actions();
  }
  // Episode e starts in view e mod V at a frame that leaves kEpisodeSteps.
  int view(int episode) const {
    return episode % static_cast<int>(reference->views().size());
  }
  int start_frame(int episode) const {
    const int span = reference->views()[0].num_frames - 1 - kEpisodeSteps;
    return span > 0 ? (7 * episode) % span : 0;
  }
  const SimState& start_state(int episode) const {
    return initial_states->BufferOfView(view(episode))
        .entry(start_frame(episode), 0)
        .state;
  }
};

// The DeepMimic walk (in the repository); the humanoid's default standing
// pose held still if it is missing, so the benchmarks always run.
Motion3D LoadMotion(const Character& character, double control_hz) {
  const std::string walk =
      SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt");
  if (std::filesystem::exists(walk))
    return ReadDeepMimicMotion(walk, character.shared_skeleton());
  Motion3D standing;
  standing.skeleton = character.shared_skeleton();
  standing.fps = control_hz;
  standing.frames.assign(121, QposToPose(character, character.model()->qpos0));
  return standing;
}

BenchTask MakeBenchTask() {
  BenchTask task;
  task.character =
      LoadCharacterForSimulation(SourcePath("assets/characters/humanoid.yaml"),
                                 "flat", task.options.simulation);
  BundleFromMotionOptions bundle_options;
  bundle_options.fps = task.options.simulation.control_hz;
  bundle_options.duration_s = 4.0;
  bundle_options.follow = CameraFollow::kRootDolly;
  std::vector<ReferenceBundle> bundles;
  bundles.push_back(MakeBundleFromMotion(
      LoadMotion(*task.character, task.options.simulation.control_hz),
      task.character->keypoint_map(), bundle_options, "bench"));
  TrackingTaskOptions task_options;
  task_options.simulation = task.options.simulation;
  TrackingTask built =
      BuildTrackingTask(task.character, std::move(bundles), task_options);
  task.reference = built.reference;
  task.initial_states = built.initial_states;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  task.actions.resize(static_cast<size_t>(kActionRows) *
                      task.character->num_actions());
  for (float& action : task.actions) action = uniform(rng);
  return task;
}

const BenchTask& Task() {
  static const BenchTask task = MakeBenchTask();
  return task;
}

// PD targets into ctrl, then mj_step x substeps: the physics floor.
void BM_BarePhysicsStep(benchmark::State& state) {
  const BenchTask& task = Task();
  Simulation simulation(task.character, task.options.simulation);
  const mjModel* model = simulation.model();
  mjData* data = simulation.mutable_data();
  const std::vector<ActuatedHinge>& hinges = task.character->hinges();
  std::vector<double> targets_rad(hinges.size());
  int step = 0;
  for (auto _ : state) {
    if (step % kEpisodeSteps == 0)
      simulation.Restore(task.start_state(step / kEpisodeSteps));
    simulation.ActionsToTargets(task.action(step), targets_rad.data());
    for (size_t h = 0; h < hinges.size(); ++h)
      data->ctrl[hinges[h].actuator_id] = targets_rad[h];
    for (int s = 0; s < task.options.simulation.physics_substeps; ++s)
      mj_step(model, data);
    ++step;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BarePhysicsStep);

// Simulation::Step: the physics plus its torque and divergence bookkeeping.
void BM_SimulationStep(benchmark::State& state) {
  const BenchTask& task = Task();
  Simulation simulation(task.character, task.options.simulation);
  int step = 0;
  for (auto _ : state) {
    if (step % kEpisodeSteps == 0)
      simulation.Restore(task.start_state(step / kEpisodeSteps));
    benchmark::DoNotOptimize(simulation.Step(task.action(step)));
    ++step;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimulationStep);

// TrackingEnv::Step (physics, projection, reward, observation) with
// ResetTo on the same schedule as the physics loops.
void BM_TrackingEnvStep(benchmark::State& state) {
  const BenchTask& task = Task();
  TrackingEnvOptions options = task.options;
  options.early_exit = false;  // episodes end on the shared schedule
  TrackingEnv env(task.character, task.reference, task.initial_states, options,
                  1);
  std::vector<float> observation(env.observation_size());
  int step = 0;
  for (auto _ : state) {
    if (step % kEpisodeSteps == 0) {
      const int episode = step / kEpisodeSteps;
      env.ResetTo(task.view(episode), task.start_frame(episode),
                  task.start_state(episode), observation.data());
    }
    benchmark::DoNotOptimize(env.Step(task.action(step), observation.data()));
    ++step;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TrackingEnvStep);

// A control step of a rollout that follows a streamed reference
// (StreamedRollout: the window of L + 1 frames prepared again and a
// TrackingEnv started on it every step), actions replayed from the same
// table; against BM_TrackingEnvStep, what streaming costs per step.
void BM_StreamedRolloutStep(benchmark::State& state) {
  const BenchTask& task = Task();
  TrackingEnvOptions options = task.options;
  options.early_exit = false;
  class ReplayPolicy : public Policy {
   public:
    ReplayPolicy(const BenchTask& task, int size) : task_(task), size_(size) {}
    void Act(const float*, int, float* actions) override {
      const float* row = task_.action(step++);
      std::copy(row, row + task_.character->num_actions(), actions);
    }
    int observation_size() const override { return size_; }
    int action_size() const override { return task_.character->num_actions(); }
    int step = 0;

   private:
    const BenchTask& task_;
    int size_;
  } policy(task, 0);
  std::unique_ptr<ClipStream> stream;
  std::unique_ptr<StreamedRollout> rollout;
  int step = 0;
  for (auto _ : state) {
    if (step % kEpisodeSteps == 0) {
      state.PauseTiming();
      const int episode = step / kEpisodeSteps;
      const ReferenceView& view =
          task.reference->bundles()[0].views[task.view(episode)];
      stream = std::make_unique<ClipStream>(view.clip);
      rollout = std::make_unique<StreamedRollout>(
          task.character, options, stream.get(),
          [&view](int frame, const SimState&, double) {
            return view.CameraAt(frame);
          },
          task.initial_states->BufferOfView(task.view(episode))
              .entry(0, 0)
              .state);
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(rollout->Step(policy));
    ++step;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_StreamedRolloutStep);

// The observation alone (body kinematics, proprioception, 2D block).
void BM_WriteObservation(benchmark::State& state) {
  const BenchTask& task = Task();
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 1);
  std::vector<float> observation(env.observation_size());
  env.ResetTo(0, task.start_frame(0), task.start_state(0), observation.data());
  env.Step(task.action(0), observation.data());  // moving bodies
  for (auto _ : state) {
    env.WriteObservation(observation.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_WriteObservation);

// An episode start: buffer draw, Restore (one forward pass), observation.
void BM_EnvReset(benchmark::State& state) {
  const BenchTask& task = Task();
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  task.options, 1);
  std::vector<float> observation(env.observation_size());
  for (auto _ : state) {
    env.Reset(observation.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EnvReset);

// VecEnv::Step with early exit and auto-reset; args: envs, threads.
void BM_VecEnvStep(benchmark::State& state) {
  const BenchTask& task = Task();
  const int num_envs = static_cast<int>(state.range(0));
  const int num_threads = static_cast<int>(state.range(1));
  VecEnv envs(task.character, task.reference, task.initial_states, task.options,
              num_envs, 1, num_threads);
  envs.Reset();
  const int action_size = envs.action_size();
  int step = 0;
  for (auto _ : state) {
    for (int i = 0; i < num_envs; ++i) {
      std::copy_n(task.action(step * num_envs + i), action_size,
                  envs.actions() + static_cast<size_t>(i) * action_size);
    }
    envs.Step();
    ++step;
  }
  state.SetItemsProcessed(state.iterations() * num_envs);
}
BENCHMARK(BM_VecEnvStep)
    ->ArgNames({"envs", "threads"})
    ->Args({16, 1})
    ->Args({16, 2})
    ->Args({64, 1})
    ->Args({64, 2})
    ->UseRealTime();

}  // namespace
}  // namespace m2d

BENCHMARK_MAIN();
