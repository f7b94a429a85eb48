#include "rl/trainer.h"

#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Parallel.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include "common/cpus.h"
#include "common/error.h"
#include "common/file_io.h"
#include "common/pauses.h"
#include "env/vec_env.h"
#include "motion/bundle.h"
#include "rl/asi_updater.h"
#include "rl/checkpoint.h"
#include "rl/collector.h"
#include "rl/hard_views.h"
#include "rl/ppo.h"
#include "rl/speed_tuner.h"

namespace m2d {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The ETA's running average of seconds per sample: about the last 20
// iterations (8 s of the dataset training), steady against single
// iterations and quick to follow a change of load.
constexpr double kEtaAverageWeight = 0.05;

// Wall times beyond a century are corrupt (checkpoints written before a fix
// read the double's bits as int64: 4.66e18 s).
bool PlausibleWallTime(double seconds) {
  return std::isfinite(seconds) && seconds >= 0 && seconds < 3.2e9;
}

}  // namespace

struct Trainer::State {
  TrainConfig config;
  std::string log_path, checkpoint_path;
  std::shared_ptr<const Character> character;
  std::shared_ptr<const TrackingReference> reference;
  std::shared_ptr<InitialStates> initial_states;
  std::unique_ptr<VecEnv> envs;
  std::unique_ptr<AsiUpdater> asi;              // with asi.enabled
  std::unique_ptr<HardViewSampler> hard_views;  // with asi.hard_view_share
  ActorCritic model{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer;
  torch::Generator generator;
  SimState state_template;
  CheckpointCounters counters;
  // How the networks run: LibTorch's threads and the arithmetic (never
  // kAuto here). With agent.adapt_torch_threads or training_precision auto,
  // the tuner picks among `network_settings` (threads x precision; [0] the
  // start) by measured speed.
  struct NetworkSetting {
    int torch_threads = 1;
    TrainingPrecision precision = TrainingPrecision::kFp32;
  };
  std::vector<NetworkSetting> network_settings;
  int network_setting = 0;  // this iteration's, an index of the above
  std::unique_ptr<SpeedTuner> speed_tuner;
  const NetworkSetting& Current() const {
    return network_settings[network_setting];
  }

  // Adam's rate, kept in its parameter groups (and so in checkpoints).
  double LearningRate() const {
    return optimizer->param_groups().front().options().get_lr();
  }
  void SetLearningRate(double learning_rate) {
    for (torch::optim::OptimizerParamGroup& group : optimizer->param_groups())
      group.options().set_lr(learning_rate);
  }
  torch::Tensor Normalized(const torch::Tensor& raw) {
    return config.ppo.normalize_observations ? model->Normalize(raw) : raw;
  }
  std::unique_ptr<RolloutCollector> collector;
  // With agent.overlap_update: the policy that acts while `model` learns
  // (the same weights, one update behind during a collection).
  ActorCritic behavior{nullptr};

  PpoLosses Learn(const RolloutStorage& batch) {
    PpoOptions options = config.ppo;
    options.training_precision = Current().precision;
    return PpoUpdate(model, *optimizer, batch, options, generator);
  }
  struct Step;
  Step CollectThenLearn(RolloutStorage& batch);
  Step CollectWhileLearning(RolloutStorage& next,
                            const RolloutStorage* previous);
  void SetUpNetworkSettings(int start_threads,
                            TrainingPrecision start_precision);
  void ChooseNetworkSetting();
  void RecordNetworkSetting(const Step& step);
  torch::Tensor CriticValue(const torch::Tensor& raw) {
    PrecisionScope scope(Current().precision);
    return model->Value(Normalized(raw)).to(torch::kFloat);
  }
  void Save() {
    m2d::SaveCheckpoint(checkpoint_path, config, model, *optimizer, counters,
                        initial_states.get(), state_template);
    if (config.run.keep_checkpoints) {
      // A copy named by what it holds, written atomically as well.
      const std::string kept_dir = config.run.run_dir + "/checkpoints";
      std::filesystem::create_directories(kept_dir);
      WriteFileAtomic(
          kept_dir + "/ckpt_" + std::to_string(counters.samples) + ".pt",
          ReadFileText(checkpoint_path));
    }
  }
  // A fixed sigma is a setting, not learned state: after loading weights the
  // config decides it (e.g. less exploration later in a long run).
  void ApplyConfiguredActionStd() {
    if (config.model.learn_action_std) return;
    const double saved_std = model->LogStd().exp().mean().item<double>();
    if (std::abs(saved_std - config.model.action_std) > 1e-9) {
      spdlog::info("action_std {} -> {} (from the config)", saved_std,
                   config.model.action_std);
    }
    torch::NoGradGuard no_grad;
    model->LogStd().fill_(std::log(config.model.action_std));
  }
  // Fine-tuning: the networks and normalizer of `path` (InputError naming it
  // when its networks do not fit this config); the fixed sigma stays the
  // config's. Optimizer, buffers and counters stay fresh.
  // A source trained with fewer future frames (env.num_future_frames) is
  // widened to this config's (WidenFutureFrames: the new frames' weights
  // start at zero, so the policy starts as the source's).
  CheckpointCounters InitializeNetworksFrom(const std::string& path) {
    int source_actions = 0;
    const ObservationLayout source_layout =
        ReadCheckpointLayout(path, &source_actions);
    const int horizon = model->layout().num_future_frames;
    CheckpointCounters from;
    if (source_layout.num_future_frames < horizon) {
      ActorCritic source(source_layout, ReadCheckpointConfig(path).model,
                         source_actions);
      from = LoadCheckpoint(path, source, /*optimizer=*/nullptr,
                            /*initial_states=*/nullptr, state_template);
      try {
        WidenFutureFrames(*source, *model);
      } catch (const ConfigError& error) {
        throw InputError(path, error.what());
      }
      spdlog::info(
          "future frames widened from {} to {}: the new frames' encoder "
          "weights start at zero, their normalizer statistics at the "
          "source's last future frame's",
          source_layout.num_future_frames, horizon);
    } else {
      from = LoadCheckpoint(path, model, /*optimizer=*/nullptr,
                            /*initial_states=*/nullptr, state_template);
    }
    ApplyConfiguredActionStd();
    spdlog::info("networks initialized from {} ({} samples of training there)",
                 path, from.samples);
    return from;
  }
};

Trainer::Trainer(const TrainConfig& config, bool resume) : state_(new State) {
  State& s = *state_;
  s.config = config;
  const RunOptions& run = config.run;
  // Before anything is written: a bf16 that cannot run here is a setting
  // error, not a crash at the first collection.
  RequirePrecisionRuns(config.ppo.training_precision,
                       "agent.training_precision");
  std::filesystem::create_directories(run.run_dir);
  // Temp files of a run killed mid-write (WriteFileAtomic's "<name>.tmp.
  // <pid>"), also of kept checkpoints: never a checkpoint, only disk space.
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(run.run_dir)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos)
      std::filesystem::remove(entry.path());
  }
  s.log_path = run.run_dir + "/train_log.csv";
  s.checkpoint_path = run.run_dir + "/checkpoint.pt";
  // With overlap, collection (this thread) and update (a second one) each
  // run LibTorch on one thread.
  const int cpus = UsableCpus();
  const int start_threads = config.ppo.overlap_update
                                ? 1
                                : CapThreadsAtCpus(config.ppo.torch_threads,
                                                   cpus, "agent.torch_threads");
  const int env_threads =
      CapThreadsAtCpus(run.env_threads, cpus, "run.env_threads");
  at::set_num_threads(start_threads);
  torch::manual_seed(run.seed);
  s.generator = at::make_generator<at::CPUGeneratorImpl>(run.seed);

  // Outline: character and references -> initial states -> environments ->
  // networks and optimizer -> (resume) checkpoint -> log.
  // Noisy S.I. perturbs the buffers once, here; ASI then replaces states.
  TrackingTask task =
      BuildTrackingTask(config.data.character_config, config.data.scene,
                        config.data.bundles, TrainingTaskOptions(config));
  s.character = task.character;
  s.reference = task.reference;
  s.initial_states = task.initial_states;
  spdlog::info("{} initial-state buffers for {} views",
               s.initial_states->num_buffers(), s.reference->views().size());
  const TrainingPrecision start_precision =
      ResolvePrecision(config.ppo.training_precision);
  if (config.ppo.training_precision == TrainingPrecision::kAuto) {
    const Bf16Support& bf16 = ProbeBf16();
    if (bf16.runs) {
      spdlog::info(
          "training precision auto: {} to start (bf16 measured at {:.2f}x "
          "fp32; bf16 from {:.1f}x); re-measured while training",
          SettingName(start_precision), bf16.speedup, kAutoBf16MinSpeedup);
    } else {
      spdlog::warn("training precision auto: fp32 (bf16 does not run here: {})",
                   bf16.error);
    }
  }
  s.SetUpNetworkSettings(start_threads, start_precision);
  s.envs = std::make_unique<VecEnv>(s.character, s.reference, s.initial_states,
                                    config.env, config.ppo.num_envs, run.seed,
                                    env_threads);
  s.envs->SetReferenceNoise(config.env.training_reference_noise());
  if (config.asi.enabled) {
    s.asi = std::make_unique<AsiUpdater>(s.character, s.reference,
                                         s.initial_states, config.env,
                                         config.asi, run.seed, env_threads);
  }
  if (config.asi.hard_view_share > 0.0) {
    // The records start empty (also on resume: they are not checkpointed);
    // starts stay uniform until episodes have ended.
    s.hard_views = std::make_unique<HardViewSampler>(
        *s.reference, config.asi.hard_view_share,
        config.asi.hard_view_half_life_samples, config.asi.hard_view_measure);
  }
  s.state_template = s.envs->env(0).simulation().Save();
  s.model = ActorCritic(s.envs->layout(), config.model, s.envs->action_size());
  s.optimizer = std::make_unique<torch::optim::Adam>(
      s.model->parameters(),
      torch::optim::AdamOptions(config.ppo.learning_rate));

  if (resume && std::filesystem::exists(s.checkpoint_path)) {
    s.counters = LoadCheckpoint(s.checkpoint_path, s.model, s.optimizer.get(),
                                s.initial_states.get(), s.state_template);
    // A different stream after resuming: the interrupted iteration's
    // randomness is not replayed.
    s.generator = at::make_generator<at::CPUGeneratorImpl>(
        run.seed + s.counters.iteration);
    spdlog::info("resumed from {} at iteration {} ({} samples)",
                 s.checkpoint_path, s.counters.iteration, s.counters.samples);
    s.ApplyConfiguredActionStd();
    const LastLogRow last_row =
        TrainingLog::TrimTo(s.log_path, s.counters.iteration);
    // A fixed rate is a setting; an adaptive one is training state and
    // continues from where it was (from the log for older checkpoints).
    if (config.ppo.target_kl > 0) {
      if (s.counters.learning_rate <= 0 && last_row.learning_rate > 0)
        s.SetLearningRate(last_row.learning_rate);
      spdlog::info("adaptive learning rate continues at {}", s.LearningRate());
    } else {
      if (std::abs(s.LearningRate() - config.ppo.learning_rate) > 1e-15) {
        spdlog::info("learning_rate {} -> {} (from the config)",
                     s.LearningRate(), config.ppo.learning_rate);
      }
      s.SetLearningRate(config.ppo.learning_rate);
    }
    if (!PlausibleWallTime(s.counters.wall_time_s)) {
      const double repaired_s =
          PlausibleWallTime(last_row.wall_time_s) ? last_row.wall_time_s : 0.0;
      spdlog::warn(
          "{}: wall time {} s is corrupt; continuing from {} s (the "
          "log's last row)",
          s.checkpoint_path, s.counters.wall_time_s, repaired_s);
      s.counters.wall_time_s = repaired_s;
    }
  } else {
    if (resume)
      spdlog::warn("--resume: no checkpoint at {}; starting fresh",
                   s.checkpoint_path);
    if (!run.init_from.empty()) {
      const CheckpointCounters from = s.InitializeNetworksFrom(run.init_from);
      // An adaptive rate continues at the source's (within this config's
      // bounds): a fresh Adam's first steps move every weight by about the
      // rate: the walk-family fine-tunes (2e-4, their sources at the 3e-5
      // floor) took a first update of KL 9-165 (docs/training.md).
      if (config.ppo.target_kl > 0 && from.learning_rate > 0) {
        s.SetLearningRate(std::clamp(from.learning_rate,
                                     config.ppo.learning_rate_min,
                                     config.ppo.learning_rate_max));
        spdlog::info("adaptive learning rate starts at {} (the source's)",
                     s.LearningRate());
      }
    }
    TrainingLog::Start(s.log_path);
  }
  // The action noise shares the update's stream, unless the two run at
  // once (agent.overlap_update): then each has its own.
  torch::Generator noise_generator = s.generator;
  if (config.ppo.overlap_update) {
    noise_generator = at::make_generator<at::CPUGeneratorImpl>(
        run.seed + 7919 + s.counters.iteration);
    s.behavior =
        ActorCritic(s.envs->layout(), config.model, s.envs->action_size());
    CopyModelState(s.model, s.behavior, true, true);
  }
  s.collector =
      std::make_unique<RolloutCollector>(*s.envs, config.ppo, noise_generator);
  s.collector->set_precision(start_precision);
  WriteFileAtomic(run.run_dir + "/config.yaml", TrainConfigToYaml(config));
}

Trainer::~Trainer() = default;

const std::string& Trainer::checkpoint_path() const {
  return state_->checkpoint_path;
}

void Trainer::SaveCheckpoint() { state_->Save(); }

// One iteration's collection and update: what was learned (nothing in an
// overlapped run's first iteration) and how long each side took.
struct Trainer::State::Step {
  std::vector<FinishedEpisode> finished;
  bool learned = false;
  PpoLosses losses;
  double collect_s = 0.0, update_s = 0.0;
};

Trainer::State::Step Trainer::State::CollectThenLearn(RolloutStorage& batch) {
  Step step;
  Clock::time_point start = Clock::now();
  collector->Collect(model, asi.get(), batch, &step.finished);
  step.collect_s = SecondsSince(start);
  start = Clock::now();
  step.losses = Learn(batch);
  step.update_s = SecondsSince(start);
  step.learned = true;
  return step;
}

Trainer::State::Step Trainer::State::CollectWhileLearning(
    RolloutStorage& next, const RolloutStorage* previous) {
  // The behavior copy collects `next` on this thread while the model learns
  // from `previous` on a second one. PPO's ratio is taken against the
  // log-probabilities stored at collection, so a batch one update old is
  // still a valid sample (the clip bounds the step). Then the behavior
  // takes the new weights, and the model the normalizer statistics the
  // collection updated.
  Step step;
  std::thread learner;
  if (previous != nullptr) {
    learner = std::thread([&] {
      at::set_num_threads(1);
      const Clock::time_point start = Clock::now();
      step.losses = Learn(*previous);
      step.update_s = SecondsSince(start);
    });
  }
  const Clock::time_point start = Clock::now();
  collector->Collect(behavior, asi.get(), next, &step.finished);
  step.collect_s = SecondsSince(start);
  if (learner.joinable()) learner.join();
  step.learned = previous != nullptr;
  CopyModelState(model, behavior, /*parameters=*/true, /*buffers=*/false);
  CopyModelState(behavior, model, /*parameters=*/false, /*buffers=*/true);
  return step;
}

void Trainer::State::SetUpNetworkSettings(int start_threads,
                                          TrainingPrecision start_precision) {
  // The candidates: the start's threads, and 1 with adapt_torch_threads;
  // the start-up precision, and the other with auto where bf16 runs.
  // Ordered so that the first probe is a thread count (the common change).
  std::vector<int> thread_counts = {start_threads};
  if (config.ppo.adapt_torch_threads && start_threads > 1)
    thread_counts.push_back(1);
  std::vector<TrainingPrecision> precisions = {start_precision};
  if (config.ppo.training_precision == TrainingPrecision::kAuto &&
      ProbeBf16().runs) {
    precisions.push_back(start_precision == TrainingPrecision::kBf16
                             ? TrainingPrecision::kFp32
                             : TrainingPrecision::kBf16);
  }
  network_settings.clear();
  network_setting = 0;
  for (TrainingPrecision p : precisions) {
    for (int threads : thread_counts) network_settings.push_back({threads, p});
  }
  if (network_settings.size() < 2) return;
  SpeedTunerOptions options;
  options.num_candidates = static_cast<int>(network_settings.size());
  speed_tuner = std::make_unique<SpeedTuner>(options);
}

void Trainer::State::ChooseNetworkSetting() {
  if (!speed_tuner) return;
  const NetworkSetting before = Current();
  network_setting = speed_tuner->CandidateForNextIteration();
  if (Current().torch_threads != before.torch_threads)
    at::set_num_threads(Current().torch_threads);
  if (Current().precision != before.precision) {
    // With overlap_update the batch learned next was collected in the
    // other arithmetic: that one update's first ratios carry bfloat16's
    // rounding (about KL 0.004; docs/training.md, "Throughput", item 5).
    collector->set_precision(Current().precision);
  }
}

void Trainer::State::RecordNetworkSetting(const Step& step) {
  if (!speed_tuner) return;
  const NetworkSetting previous = network_settings[speed_tuner->chosen()];
  const double previous_s = speed_tuner->chosen_seconds_per_sample();
  if (speed_tuner->Record(network_setting, (step.collect_s + step.update_s) /
                                               config.ppo.batch_size())) {
    spdlog::info(
        "networks {} thread(s) {} -> {} thread(s) {}: {:.0f} -> {:.0f} "
        "samples/s (collect + update)",
        previous.torch_threads, SettingName(previous.precision),
        Current().torch_threads, SettingName(Current().precision),
        1.0 / previous_s, 1.0 / speed_tuner->chosen_seconds_per_sample());
  }
}

namespace {

// The log row of an iteration: counters, timing, the episodes that ended,
// the update's losses.
TrainProgress MakeProgress(const CheckpointCounters& counters,
                           const Trainer::IterationTiming& timing,
                           const std::vector<FinishedEpisode>& finished,
                           const PpoLosses& losses, double learning_rate,
                           int torch_threads, TrainingPrecision precision,
                           int batch_size) {
  TrainProgress progress;
  progress.iteration = counters.iteration;
  progress.samples = counters.samples;
  progress.wall_time_s = counters.wall_time_s;
  progress.samples_per_s = batch_size / timing.iteration_s;
  progress.collect_s = timing.collect_s;
  progress.update_s = timing.update_s;
  progress.asi_s = timing.asi_s;
  progress.torch_threads = torch_threads;
  progress.bf16 = precision == TrainingPrecision::kBf16;
  if (!finished.empty()) {
    double returns = 0, lengths = 0, successes = 0, errors = 0;
    for (const FinishedEpisode& episode : finished) {
      returns += episode.stats.total_reward;
      lengths += episode.stats.steps;
      successes += episode.stats.failed ? 0.0 : 1.0;
      errors += episode.stats.mean_error_px();
    }
    const double count = static_cast<double>(finished.size());
    progress.mean_return = returns / count;
    progress.mean_episode_length = lengths / count;
    progress.succ = successes / count;
    progress.e2d_px = errors / count;
  }
  progress.policy_loss = losses.policy_loss;
  progress.value_loss = losses.value_loss;
  progress.entropy = losses.entropy;
  progress.approx_kl = losses.approx_kl;
  progress.clip_fraction = losses.clip_fraction;
  progress.learning_rate = learning_rate;
  return progress;
}

}  // namespace

TrainSummary Trainer::Run(
    int max_iterations, const std::atomic<bool>* stop,
    const std::function<void(const TrainProgress&)>& on_progress) {
  State& s = *state_;
  const TrainConfig& config = s.config;
  TrainSummary summary;
  summary.checkpoint_path = s.checkpoint_path;
  const bool overlap = config.ppo.overlap_update;
  // The batch being collected and (with overlap) the one being learned from.
  std::vector<RolloutStorage> batches;
  for (int b = 0; b < (overlap ? 2 : 1); ++b) {
    batches.emplace_back(config.ppo.steps_per_env, config.ppo.num_envs,
                         s.envs->observation_size(), s.envs->action_size());
  }
  int collecting = 0;
  bool batch_waiting = false;  // overlap: a collected batch not learned yet
  s.envs->Reset();
  Clock::time_point last_checkpoint = Clock::now();
  double recent_seconds_per_sample = 0.0;  // for the ETA
  TrainingLog log(s.log_path);

  while (s.counters.samples < config.run.total_samples) {
    if (stop != nullptr && stop->load()) {
      summary.interrupted = true;
      break;
    }
    if (max_iterations > 0 && summary.iterations_run >= max_iterations) break;
    const Clock::time_point start = Clock::now();
    const PauseMark pauses_at_start = MarkPauses();
    const double learning_rate = s.LearningRate();
    // 0. How the networks run (adaptive: the tuner's pick or probe).
    s.ChooseNetworkSetting();
    // 1-2. Collect a batch of experience and learn from it (overlapped:
    // learn from the previous batch while collecting the next).
    State::Step step;
    if (overlap) {
      step = s.CollectWhileLearning(
          batches[collecting],
          batch_waiting ? &batches[1 - collecting] : nullptr);
      batch_waiting = true;
      collecting = 1 - collecting;
    } else {
      step = s.CollectThenLearn(batches[0]);
    }
    if (step.learned && config.ppo.target_kl > 0) {
      s.SetLearningRate(
          AdaptLearningRate(learning_rate, step.losses.approx_kl, config.ppo));
    }
    // A stop (Ctrl-Z, kill -STOP) or the machine's sleep within the
    // iteration makes its samples/s the pause's: one such reading in the
    // tuner's running average read as a slowdown and moved it off its
    // pick (docs/training.md, "Throughput", item 3).
    if (PausedBetween(pauses_at_start, MarkPauses())) {
      spdlog::info(
          "iteration {}: the process was stopped or the machine slept; its "
          "timing is left out of the choice of threads and precision",
          s.counters.iteration + 1);
    } else {
      s.RecordNetworkSetting(step);
    }
    // 3. Refresh the initial-state buffers (ASI).
    const Clock::time_point asi_start = Clock::now();
    ++s.counters.iteration;
    if (s.asi) {
      const int64_t replaced_before = s.asi->num_entries_replaced();
      s.asi->Update(
          [&](const torch::Tensor& raw) { return s.CriticValue(raw); },
          config.ppo.batch_size());
      const int64_t replaced = s.asi->num_entries_replaced() - replaced_before;
      if (replaced > 0) {
        // Said once (a resumed run's old entries); later ones at debug level.
        spdlog::log(
            replaced_before == 0 ? spdlog::level::info : spdlog::level::debug,
            "ASI: {} entries farther than asi.max_entry_error_px "
            "({} px) from their frame's 2D replaced by the frame's "
            "anchor",
            replaced, config.asi.max_entry_error_px);
      }
    }
    // 3b. Where episodes start: views weighed by their failures.
    if (s.hard_views) {
      s.hard_views->Record(step.finished, config.ppo.batch_size());
      s.initial_states->SetViewWeights(s.hard_views->Weights());
    }
    // 4. Report.
    IterationTiming timing{SecondsSince(start), step.collect_s, step.update_s,
                           SecondsSince(asi_start)};
    s.counters.samples += config.ppo.batch_size();
    s.counters.wall_time_s += timing.iteration_s;
    TrainProgress progress =
        MakeProgress(s.counters, timing, step.finished, step.losses,
                     learning_rate, s.Current().torch_threads,
                     s.Current().precision, config.ppo.batch_size());
    if (!PausedBetween(pauses_at_start, MarkPauses())) {
      recent_seconds_per_sample =
          RunningAverage(recent_seconds_per_sample,
                         1.0 / progress.samples_per_s, kEtaAverageWeight);
    }
    progress.eta_s =
        static_cast<double>(config.run.total_samples - s.counters.samples) *
        recent_seconds_per_sample;
    log.Append(progress);
    if (on_progress) on_progress(progress);
    summary.last = progress;
    ++summary.iterations_run;
    // 5. Checkpoint every few minutes.
    if (SecondsSince(last_checkpoint) > 60.0 * config.run.checkpoint_minutes) {
      s.Save();
      if (s.hard_views) {
        spdlog::info("hard views: {}", s.hard_views->Report(5));
      }
      last_checkpoint = Clock::now();
    }
  }
  s.Save();
  return summary;
}

}  // namespace m2d
