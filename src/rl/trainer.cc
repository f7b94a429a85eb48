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

#include "common/error.h"
#include "common/file_io.h"
#include "env/vec_env.h"
#include "motion/bundle.h"
#include "rl/asi_updater.h"
#include "rl/checkpoint.h"
#include "rl/ppo.h"
#include "rl/thread_tuner.h"

namespace m2d {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

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
  std::unique_ptr<AsiUpdater> asi;  // with asi.enabled
  ActorCritic model{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer;
  torch::Generator generator;
  SimState state_template;
  CheckpointCounters counters;
  int torch_threads = 1;
  std::unique_ptr<ThreadTuner> thread_tuner;  // with adapt_torch_threads

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
  void Collect(RolloutStorage& storage, std::vector<FinishedEpisode>* finished);
  torch::Tensor CriticValue(const torch::Tensor& raw) {
    return model->Value(Normalized(raw));
  }
  void Save() {
    m2d::SaveCheckpoint(checkpoint_path, config, model, *optimizer, counters,
                        initial_states.get(), state_template);
  }
};

Trainer::Trainer(const TrainConfig& config, bool resume) : state_(new State) {
  State& s = *state_;
  s.config = config;
  const RunOptions& run = config.run;
  std::filesystem::create_directories(run.run_dir);
  // Temp files of a run killed mid-write (WriteFileAtomic's "<name>.tmp.
  // <pid>"): never a checkpoint, only disk space.
  for (const auto& entry : std::filesystem::directory_iterator(run.run_dir)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos)
      std::filesystem::remove(entry.path());
  }
  s.log_path = run.run_dir + "/train_log.csv";
  s.checkpoint_path = run.run_dir + "/checkpoint.pt";
  s.torch_threads = config.ppo.torch_threads;
  at::set_num_threads(s.torch_threads);
  if (config.ppo.adapt_torch_threads) {
    ThreadTunerOptions tuner;
    tuner.max_threads = config.ppo.torch_threads;
    s.thread_tuner = std::make_unique<ThreadTuner>(tuner);
  }
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
  s.envs = std::make_unique<VecEnv>(s.character, s.reference, s.initial_states,
                                    config.env, config.ppo.num_envs, run.seed,
                                    run.env_threads);
  if (config.asi.enabled) {
    s.asi =
        std::make_unique<AsiUpdater>(s.character, s.reference, s.initial_states,
                                     config.env, config.asi, run.seed);
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
    // A fixed sigma is a setting, not learned state: the config decides it
    // (e.g. lowering exploration noise for the later part of a long run).
    if (!config.model.learn_action_std) {
      const double saved_std = s.model->LogStd().exp().mean().item<double>();
      if (std::abs(saved_std - config.model.action_std) > 1e-9) {
        spdlog::info("action_std {} -> {} (from the config)", saved_std,
                     config.model.action_std);
      }
      torch::NoGradGuard no_grad;
      s.model->LogStd().fill_(std::log(config.model.action_std));
    }
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
    TrainingLog::Start(s.log_path);
  }
  WriteFileAtomic(run.run_dir + "/config.yaml", TrainConfigToYaml(config));
}

Trainer::~Trainer() = default;

const std::string& Trainer::checkpoint_path() const {
  return state_->checkpoint_path;
}

void Trainer::SaveCheckpoint() { state_->Save(); }

void Trainer::State::Collect(RolloutStorage& storage,
                             std::vector<FinishedEpisode>* finished) {
  // Outline per step: normalize observations, sample actions from the
  // Gaussian policy, step every environment in parallel, fold the value of
  // truncated episodes' last observations into their reward, offer visited
  // states to ASI.
  torch::NoGradGuard no_grad;
  VecEnv& vec = *envs;
  const int num_envs = vec.num_envs();
  const int observation_size = vec.observation_size();
  const int action_size = vec.action_size();
  const int steps = config.ppo.steps_per_env;
  const double discount = config.ppo.discount;
  if (asi) asi->BeginRollout();

  for (int t = 0; t < steps; ++t) {
    torch::Tensor raw =
        torch::from_blob(vec.observations(), {num_envs, observation_size});
    if (config.ppo.normalize_observations) model->UpdateNormalizer(raw);
    torch::Tensor obs = Normalized(raw);
    torch::Tensor mean = model->ActionMean(obs);
    torch::Tensor value = model->Value(obs);
    torch::Tensor noise = at::randn({num_envs, action_size}, generator);
    torch::Tensor action = (mean + model->LogStd().exp() * noise).contiguous();
    storage.observations[t].copy_(obs);
    storage.actions[t].copy_(action);
    storage.log_probs[t].copy_(model->LogProb(mean, action));
    storage.values[t].copy_(value);
    std::memcpy(vec.actions(), action.data_ptr<float>(),
                sizeof(float) * num_envs * action_size);

    vec.Step(finished);

    torch::Tensor reward =
        torch::from_blob(const_cast<float*>(vec.rewards()), {num_envs}).clone();
    std::vector<int64_t> truncated_rows;
    for (int i = 0; i < num_envs; ++i) {
      storage.dones[t][i] =
          (vec.terminated()[i] || vec.truncated()[i]) ? 1.0f : 0.0f;
      if (vec.truncated()[i]) truncated_rows.push_back(i);
    }
    if (!truncated_rows.empty()) {
      // Time limits are not failures: bootstrap with V(last observation).
      torch::Tensor rows = torch::tensor(truncated_rows, torch::kLong);
      torch::Tensor final_raw =
          torch::from_blob(const_cast<float*>(vec.final_observations()),
                           {num_envs, observation_size})
              .index_select(0, rows);
      reward.index_add_(0, rows,
                        discount * model->Value(Normalized(final_raw)));
    }
    storage.rewards[t].copy_(reward);

    if (asi) asi->Capture(vec, t);
  }
  torch::Tensor last_raw =
      torch::from_blob(vec.observations(), {num_envs, observation_size});
  torch::Tensor last_values = model->Value(Normalized(last_raw));
  ComputeGae(storage.rewards, storage.values, storage.dones, last_values,
             discount, config.ppo.gae_lambda, &storage.advantages,
             &storage.returns);
}

TrainSummary Trainer::Run(
    int max_iterations, const std::atomic<bool>* stop,
    const std::function<void(const TrainProgress&)>& on_progress) {
  State& s = *state_;
  const TrainConfig& config = s.config;
  TrainSummary summary;
  summary.checkpoint_path = s.checkpoint_path;
  RolloutStorage storage(config.ppo.steps_per_env, config.ppo.num_envs,
                         s.envs->observation_size(), s.envs->action_size());
  s.envs->Reset();
  Clock::time_point last_checkpoint = Clock::now();
  TrainingLog log(s.log_path);

  while (s.counters.samples < config.run.total_samples) {
    if (stop != nullptr && stop->load()) {
      summary.interrupted = true;
      break;
    }
    if (max_iterations > 0 && summary.iterations_run >= max_iterations) break;
    // 0. LibTorch's thread count (adaptive: the tuner's pick or probe).
    if (s.thread_tuner) {
      const int threads = s.thread_tuner->ThreadsForNextIteration();
      if (threads != s.torch_threads) {
        s.torch_threads = threads;
        at::set_num_threads(threads);
      }
    }
    // 1. Collect a batch of experience.
    Clock::time_point start = Clock::now();
    std::vector<FinishedEpisode> finished;
    s.Collect(storage, &finished);
    double collect_s = SecondsSince(start);
    // 2. Learn from it (and, if adaptive, set the next update's rate).
    Clock::time_point update_start = Clock::now();
    const double learning_rate = s.LearningRate();
    PpoLosses losses =
        PpoUpdate(s.model, *s.optimizer, storage, config.ppo, s.generator);
    if (config.ppo.target_kl > 0) {
      s.SetLearningRate(
          AdaptLearningRate(learning_rate, losses.approx_kl, config.ppo));
    }
    double update_s = SecondsSince(update_start);
    if (s.thread_tuner) {
      const int previous = s.thread_tuner->chosen_threads();
      const double previous_s = s.thread_tuner->chosen_seconds_per_sample();
      if (s.thread_tuner->Record(
              s.torch_threads,
              (collect_s + update_s) / config.ppo.batch_size())) {
        spdlog::info(
            "LibTorch threads {} -> {}: {:.0f} -> {:.0f} samples/s (collect + "
            "update)",
            previous, s.torch_threads, 1.0 / previous_s,
            1.0 / s.thread_tuner->chosen_seconds_per_sample());
      }
    }
    // 3. Refresh the initial-state buffers (ASI).
    Clock::time_point asi_start = Clock::now();
    ++s.counters.iteration;
    if (s.asi) {
      s.asi->Update(
          [&](const torch::Tensor& raw) { return s.CriticValue(raw); },
          s.counters.iteration);
    }
    double asi_s = SecondsSince(asi_start);

    // 4. Report.
    double iteration_s = SecondsSince(start);
    s.counters.samples += config.ppo.batch_size();
    s.counters.wall_time_s += iteration_s;
    TrainProgress progress;
    progress.iteration = s.counters.iteration;
    progress.samples = s.counters.samples;
    progress.wall_time_s = s.counters.wall_time_s;
    progress.samples_per_s = config.ppo.batch_size() / iteration_s;
    progress.collect_s = collect_s;
    progress.update_s = update_s;
    progress.asi_s = asi_s;
    progress.torch_threads = s.torch_threads;
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
    log.Append(progress);
    if (on_progress) on_progress(progress);
    summary.last = progress;
    ++summary.iterations_run;

    // 5. Checkpoint every few minutes.
    if (SecondsSince(last_checkpoint) > 60.0 * config.run.checkpoint_minutes) {
      s.Save();
      last_checkpoint = Clock::now();
    }
  }
  s.Save();
  return summary;
}

}  // namespace m2d
