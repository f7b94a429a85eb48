// rl: learning the tracking policy — configs, networks, PPO with Adaptive
// State Initialization, checkpoints and the training loop. LibTorch is
// confined to this folder (this header does not include it).
#ifndef MIMIC2D_RL_TRAIN_CONFIG_H_
#define MIMIC2D_RL_TRAIN_CONFIG_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "env/sources.h"
#include "env/task.h"
#include "env/tracking_env.h"

namespace m2d {

// What to learn from.
struct DataOptions {
  std::string character_config = "assets/characters/humanoid.yaml";
  std::string scene = "flat";
  std::vector<std::string> bundles;  // reference bundle files
  // Where episodes start and which cameras project (env/sources.h): the
  // bundles' 3D truth and true cameras, or their `mimic2d fit` estimate
  // (2D only); initial states may also be a default pose.
  InitialStateSource initial_states = InitialStateSource::kTruth;
  CameraSource cameras = CameraSource::kTruth;

  // Every setting (common/settings.h): the config's `data` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("character_config", self.character_config, Range::Any(),
      "the character: MJCF, keypoint map and actuation (YAML)");
    v("scene", self.scene, Range::Any(),
      "the scene it is loaded into (flat, ball, ...)");
    v("bundles", self.bundles, Range::Any(),
      "reference bundle files (one or more)");
    v("initial_states", self.initial_states, Range::Any(),
      "where episodes start: the 3D truth, the `mimic2d fit` estimate (2D "
      "only) or a default pose");
    v("cameras", self.cameras, Range::Any(),
      "which cameras project: the true ones or the fit's estimate");
  }
  TaskSources sources() const { return {initial_states, cameras}; }
  void Validate() const;
};

// Network shapes (MimicKit-style "model" config).
struct ModelOptions {
  std::vector<int> encoder_hidden = {256};           // phi's hidden layers
  int encoder_features = 128;                        // phi's output size
  std::vector<int> policy_hidden = {512, 256, 256};  // the paper's MLP
  std::vector<int> critic_hidden = {512, 256, 256};
  double action_std = 0.1;        // Gaussian sigma, in normalized actions
  bool learn_action_std = false;  // fixed sigma, as MimicKit and PHC
  // Normalized observation features are clipped to +-this many running
  // standard deviations (5: Isaac Gym's and rl_games' value). Under a walks'
  // normalizer the zombie walk's wrists and upper arms sit 6-7 sigma out, at
  // the clip; 10 did not make it learn faster (docs/training.md, "The
  // normalizer's clip").
  double observation_clip_std = 5.0;

  // Every setting (common/settings.h): the config's `model` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    const Range width = Range::Closed(1, 65536);
    v("encoder_hidden", self.encoder_hidden, width,
      "hidden layer widths of phi, the per-view 2D encoder");
    v("encoder_features", self.encoder_features, width,
      "phi's output size (averaged over views for 3D tracking)");
    v("policy_hidden", self.policy_hidden, width,
      "hidden layer widths of the policy MLP");
    v("critic_hidden", self.critic_hidden, width,
      "hidden layer widths of the critic MLP");
    v("action_std", self.action_std, Range::Above(0),
      "Gaussian sigma, in normalized action units");
    v("learn_action_std", self.learn_action_std, Range::Any(),
      "learn sigma instead of keeping it fixed");
    v("observation_clip_std", self.observation_clip_std, Range::Above(0),
      "normalized observation features are clipped to +-this (running "
      "standard deviations)");
  }
  void Validate() const;
};

// Arithmetic of the networks while training (collection and update).
enum class TrainingPrecision {
  kFp32,  // float32 throughout
  // bfloat16 matrix products (LibTorch's CPU autocast; oneDNN uses AMX or
  // AVX512-BF16 where the CPU has them) with float32 weights, optimizer
  // state, log-probabilities and losses. Collection acts in it too, so the
  // behavior policy is the network the update differentiates.
  kBf16,
  // bf16 where this CPU runs it measurably faster, fp32 elsewhere: a probe
  // at start-up picks, then the trainer's speed tuner re-measures both in
  // real iterations (rl/speed_tuner.h; the answer can flip with the load).
  // The CPU's features do not tell: bf16 trained at 1.47x fp32 with AMX, 0.75x
  // on an Intel CPU with AVX512-BF16 alone and 1.03-1.22x on an AMD Zen 5
  // with AVX512-BF16 alone (1.7x against AVX2 fp32 kernels;
  // docs/training.md), so `auto` times both.
  kAuto,
};
// The bf16 : fp32 speed ratio at which `auto` takes bf16; the margin keeps
// a CPU on which both run alike on fp32, the exact arithmetic.
inline constexpr double kAutoBf16MinSpeedup = 1.2;
const char* SettingName(TrainingPrecision precision);
bool ParseSetting(const std::string& text, TrainingPrecision* precision);
inline std::string SettingChoices(TrainingPrecision) {
  return "fp32, bf16, auto";
}
// Whether bf16 runs here, and how fast against fp32. oneDNN can refuse
// bf16 where LibTorch routes it there (ONEDNN_MAX_CPU_ISA below AVX-512 on
// an AVX-512 CPU: "could not create a primitive descriptor iterator"); then
// `auto` trains in fp32 and an explicit bf16 is a named error, instead of
// the training dying on LibTorch's message.
struct Bf16Support {
  bool runs = false;
  double speedup = 0.0;  // bf16 : fp32 speed; 0 when bf16 does not run
  std::string error;     // LibTorch's message when bf16 does not run
};
// The support measured with `time_step(precision, repeats)` (seconds of the
// fastest of `repeats` steps): one untimed step each, then the ratio of
// the timed ones; a step that throws marks bf16 as not running.
Bf16Support MeasureBf16Support(
    const std::function<double(TrainingPrecision, int)>& time_step);
// This CPU's support on the networks' arithmetic (forward + backward of a
// policy-sized MLP on a 1024-row minibatch, best of 3 each), measured once
// per process (0.27 s on a Zen 5). Defined in rl/networks.cc (LibTorch).
const Bf16Support& ProbeBf16();
// The precision that runs on this CPU: kAuto resolved by ProbeBf16 (bf16
// when it runs at kAutoBf16MinSpeedup or faster); explicit ones as given.
TrainingPrecision ResolvePrecision(TrainingPrecision precision);
// Throws ConfigError naming `setting` when `precision` is bf16 and bf16
// does not run here (ProbeBf16).
void RequirePrecisionRuns(TrainingPrecision precision,
                          const std::string& setting);

// How collection shares the env threads between acting and simulating.
enum class CollectionMode {
  // Per step: one batched forward pass for every environment, then every
  // environment's physics on the env threads. The network's serial parts
  // leave the other cores waiting at each step.
  kBatched,
  // Each env thread acts for its own share of the environments (forward
  // passes of its rows, on one LibTorch thread) and steps them, with no
  // barrier between steps. The observation normalizer's statistics stay
  // fixed during a rollout and take in its observations after it.
  kPerThread,
};
const char* SettingName(CollectionMode mode);
bool ParseSetting(const std::string& text, CollectionMode* mode);
inline std::string SettingChoices(CollectionMode) {
  return "batched, per_thread";
}

// What hard-view sampling (rl/hard_views.h) starts views in proportion to.
enum class HardViewMeasure {
  // The chance that a rollout of the whole view fails: favours the failing
  // views, but while most views fail every view of a long clip nears 1.
  kFullRollout,
  // The early exits per step simulated (the hazard): starts in proportion
  // to it give every failing view about the same samples, however soon its
  // episodes end (a clip lost in 11 frames otherwise gets 1/20 of the
  // samples of one held for 200).
  kHazard,
  // The hazard over the view's mean episode length (steps): starts in
  // proportion to it give every view samples in proportion to its hazard,
  // so a view lost in 25 frames gets 6x the samples of one lost in 150
  // (kHazard: the same samples).
  kHazardSamples,
};
const char* SettingName(HardViewMeasure measure);
bool ParseSetting(const std::string& text, HardViewMeasure* measure);
inline std::string SettingChoices(HardViewMeasure) {
  return "full_rollout, hazard, hazard_samples";
}

// PPO (CleanRL-style "agent" config). Every field is documented in
// configs/README.md with the reasoning behind its default.
struct PpoOptions {
  int num_envs = 64;            // parallel environments
  int steps_per_env = 32;       // rollout horizon per iteration
  double discount = 0.99;       // gamma
  double gae_lambda = 0.95;     // lambda of GAE / TD(lambda)
  double clip_ratio = 0.2;      // PPO surrogate clip
  double advantage_clip = 4.0;  // clip of normalized advantages (MimicKit)
  int epochs = 3;               // passes over each batch
  int minibatch_size = 512;     // samples per gradient step
  double learning_rate = 2e-4;  // Adam; with target_kl > 0, the start value
  // > 0: after each iteration the learning rate follows rl_games' adaptive
  // rule toward this KL between the rollout's and the updated policy (see
  // AdaptLearningRate); 0: the rate stays fixed.
  double target_kl = 0.0;
  double learning_rate_min = 1e-6;  // bounds of the adaptive rate
  double learning_rate_max = 1e-3;
  double max_grad_norm = 1.0;  // global gradient-norm clip
  double value_loss_weight = 0.5;
  double entropy_weight = 0.0;         // only matters with a learned sigma
  double action_bound_weight = 10.0;   // penalty on means beyond [-1, 1]
  bool normalize_observations = true;  // running mean/std, saved with model
  int torch_threads = 1;  // LibTorch intra-op threads; 1 measured fastest here
  // Probe 1 thread against torch_threads while training and keep the faster
  // (rl/speed_tuner.h): more threads collapse when another process competes
  // for the cores.
  bool adapt_torch_threads = false;
  // Learn from the previous batch on a second thread while the next one is
  // collected (each side with one LibTorch thread): the update works on a
  // batch one policy update old, which PPO's clipped ratio against the
  // stored log-probabilities allows (docs/training.md, "Throughput").
  bool overlap_update = false;
  TrainingPrecision training_precision = TrainingPrecision::kFp32;
  CollectionMode collection = CollectionMode::kBatched;
  // An episode cut by the time limit gets gamma * V(last observation) on
  // its last reward; one that reached its reference's last frame has ended
  // its task and gets nothing, unless this is set. That last observation is
  // never a training sample (the env resets) and its future frames all
  // repeat the last one, so V there is an extrapolation which, bootstrapped,
  // can run away (docs/training.md, "The clip's end").
  bool bootstrap_at_reference_end = false;

  // Every setting (common/settings.h): the config's `agent` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("num_envs", self.num_envs, Range::Closed(1, 65536),
      "parallel environments");
    v("steps_per_env", self.steps_per_env, Range::Closed(1, 65536),
      "rollout horizon per iteration (batch = num_envs x steps_per_env)");
    v("discount", self.discount, Range::Open(0, 1), "gamma");
    v("gae_lambda", self.gae_lambda, Range::Closed(0, 1), "lambda of GAE");
    v("bootstrap_at_reference_end", self.bootstrap_at_reference_end,
      Range::Any(),
      "add gamma * V(last observation) when an episode reaches its "
      "reference's last frame, as at a time limit (false: the task ended)");
    v("clip_ratio", self.clip_ratio, Range::Above(0), "PPO surrogate clip");
    v("advantage_clip", self.advantage_clip, Range::Above(0),
      "clip of normalized advantages");
    v("epochs", self.epochs, Range::Closed(1, 1000), "passes over each batch");
    v("minibatch_size", self.minibatch_size, Range::AtLeast(1),
      "samples per gradient step (at most the batch)");
    v("learning_rate", self.learning_rate, Range::Above(0),
      "Adam's rate; with target_kl > 0 the first iteration's (with "
      "run.init_from: the source's rate, within the bounds)");
    v("target_kl", self.target_kl, Range::AtLeast(0),
      "> 0: adapt the rate toward this KL per update (rl_games rule); 0: "
      "fixed rate");
    v("learning_rate_min", self.learning_rate_min, Range::Above(0),
      "lower bound of the adaptive rate");
    v("learning_rate_max", self.learning_rate_max, Range::Above(0),
      "upper bound of the adaptive rate");
    v("max_grad_norm", self.max_grad_norm, Range::Above(0),
      "global gradient-norm clip");
    v("value_loss_weight", self.value_loss_weight, Range::AtLeast(0),
      "weight of the critic's loss");
    v("entropy_weight", self.entropy_weight, Range::AtLeast(0),
      "entropy bonus (only matters with a learned sigma)");
    v("action_bound_weight", self.action_bound_weight, Range::AtLeast(0),
      "penalty on Gaussian means beyond [-1, 1]");
    v("normalize_observations", self.normalize_observations, Range::Any(),
      "running mean/std of observations, saved in checkpoints");
    v("torch_threads", self.torch_threads, Range::Closed(1, 1024),
      "LibTorch intra-op threads (capped at the CPUs this process may use)");
    v("adapt_torch_threads", self.adapt_torch_threads, Range::Any(),
      "probe 1 thread against torch_threads while training and keep the "
      "faster (re-probed as the load changes)");
    v("overlap_update", self.overlap_update, Range::Any(),
      "learn from the previous batch on a second thread while collecting "
      "the next");
    v("training_precision", self.training_precision, Range::Any(),
      "arithmetic of the networks' matrix products in collection and "
      "update: fp32, bf16 (float32 weights and losses), or auto (bf16 "
      "where a probe at start-up times it at least 1.2x fp32, else fp32; "
      "then both re-measured in training iterations as the load changes)");
    v("collection", self.collection, Range::Any(),
      "batched: one forward pass for all environments per step, then their "
      "physics on the env threads; per_thread: each env thread acts for and "
      "steps its own share, with no barrier between steps");
  }
  int batch_size() const { return num_envs * steps_per_env; }
  void Validate() const;
};

// Adaptive State Initialization.
struct AsiOptions {
  bool enabled = true;
  int capture_every_steps = 4;  // visited states offered to the buffers
  // Every kept entry is rescored by the critic about this often (the
  // critic moves; an entry's stored score ages): each iteration rescores
  // the next whole frames, in turn, holding 1/rescore_every_iterations of
  // the kept entries.
  int rescore_every_iterations = 10;
  // ...but at most this many entries per sample of the iteration (0: no
  // cap), so that rescoring costs at most about one more critic pass over
  // the rollout: buffers of long references (the nine long walks: 36 views,
  // 32k frames, 130k entries) otherwise cost 2/3 of training time
  // (docs/training.md, item 10). A sweep then takes longer than
  // rescore_every_iterations.
  double rescore_max_entries_per_sample = 1.0;
  StateBufferOptions buffer{4, 2.0};  // per frame: 4 states, T = 2 (of V)
  // A state is kept for frame t only while its worst keypoint, projected by
  // the view it is seen from, lies within this of frame t's 2D (px); entries
  // beyond it are replaced by the frame's anchor at rescoring. Without it
  // the best-scored entries lie 2-3x farther from the 2D than the fit's
  // states, yet 40 px learned the walk slower (docs/training.md, "ASI"):
  // 0, no bound (any state of a running episode), by default.
  double max_entry_error_px = 0.0;
  // Hard-view sampling (rl/hard_views.h): the share of episode starts drawn
  // in proportion to each view's estimated chance that a rollout of the
  // whole view fails; 0: every view alike. Independent of `enabled`.
  double hard_view_share = 0.0;
  // The failure records forget with this half life (samples of training).
  double hard_view_half_life_samples = 2e6;
  // What the share's starts are in proportion to.
  HardViewMeasure hard_view_measure = HardViewMeasure::kFullRollout;

  // Every setting (common/settings.h): the config's `asi` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("enabled", self.enabled, Range::Any(),
      "Adaptive State Initialization on/off");
    v("capture_every_steps", self.capture_every_steps, Range::AtLeast(1),
      "visited states are offered to the buffers every this many steps");
    v("rescore_every_iterations", self.rescore_every_iterations,
      Range::AtLeast(1),
      "every kept entry is rescored by the critic about every this many "
      "iterations (the next share of the buffers' frames each iteration)");
    v("rescore_max_entries_per_sample", self.rescore_max_entries_per_sample,
      Range::AtLeast(0),
      "at most this many entries are rescored per sample of an iteration "
      "(long references then sweep their buffers more slowly); 0: no cap");
    decltype(self.buffer)::VisitFields(self.buffer, v);
    v("max_entry_error_px", self.max_entry_error_px, Range::AtLeast(0),
      "states are kept only while their worst keypoint is within this of "
      "their frame's 2D (px); 0: no bound");
    v("hard_view_share", self.hard_view_share, Range::Closed(0, 1),
      "share of episode starts drawn in proportion to each view's estimated "
      "chance of failing a whole rollout (hard-view sampling); 0: uniform "
      "over views");
    v("hard_view_half_life_samples", self.hard_view_half_life_samples,
      Range::Above(0),
      "half life (samples) of the failure records hard-view sampling reads");
    v("hard_view_measure", self.hard_view_measure, Range::Any(),
      "what hard-view starts are in proportion to: full_rollout (a view's "
      "chance of failing a whole rollout), hazard (its early exits per "
      "step: every failing view gets about the same samples) or "
      "hazard_samples (the hazard over its mean episode length: samples in "
      "proportion to the hazard)");
  }
  void Validate() const;
};

// The run: where, how long, how often to save.
struct RunOptions {
  std::string run_dir = "runs/default";
  uint64_t seed = 1;
  int64_t total_samples = 20'000'000;  // stop after this many env steps
  double checkpoint_minutes = 5.0;     // periodic atomic checkpoint
  int env_threads = 2;                 // OpenMP threads stepping envs
  // Also keep every checkpoint as checkpoints/ckpt_<samples>.pt: the
  // learning curve of a run is then measured afterwards by evaluating
  // them (32 MB each for the dataset's networks, every checkpoint_minutes).
  bool keep_checkpoints = false;
  // A fresh run's networks (and observation normalizer) start from this
  // checkpoint's: fine-tuning a trained policy on new references. Empty:
  // random weights. Ignored when resuming the run's own checkpoint.
  std::string init_from;

  // Every setting (common/settings.h): the config's `run` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("run_dir", self.run_dir, Range::Any(),
      "checkpoint.pt, train_log.csv and config.yaml go here");
    v("seed", self.seed, Range::Any(), "seed of every random stream");
    v("total_samples", self.total_samples, Range::AtLeast(1),
      "stop after this many environment steps");
    v("checkpoint_minutes", self.checkpoint_minutes, Range::Above(0),
      "period of the atomic checkpoint (minutes)");
    v("keep_checkpoints", self.keep_checkpoints, Range::Any(),
      "also keep every checkpoint as checkpoints/ckpt_<samples>.pt in the "
      "run folder (for learning curves)");
    v("env_threads", self.env_threads, Range::Closed(1, 1024),
      "OpenMP threads stepping environments (capped at the CPUs this "
      "process may use)");
    v("init_from", self.init_from, Range::Any(),
      "a fresh run starts from this checkpoint's networks and observation "
      "normalizer (same character, observation and network sizes; a "
      "source with fewer future frames is widened, the new frames' weights "
      "at zero); the optimizer, initial-state buffers and counters start "
      "fresh, an adaptive rate at the source's; empty: random weights");
  }
  void Validate() const;
};

struct TrainConfig {
  std::string source_path;  // the YAML file it came from
  DataOptions data;
  TrackingEnvOptions env;
  ModelOptions model;
  PpoOptions ppo;
  AsiOptions asi;
  RunOptions run;

  void Validate() const;  // throws ConfigError
};

// The tracking task the config trains on: its sources, ASI buffer options
// and Noisy S.I. (seeded from run.seed).
TrackingTaskOptions TrainingTaskOptions(const TrainConfig& config);

// Reads a training config. Each top-level section (data, env, model,
// agent, asi, run) is a mapping, or a path to a YAML file holding it
// (relative to this file), so env/agent/model configs can be shared.
// Relative data paths are resolved against the current directory.
TrainConfig LoadTrainConfig(const std::string& yaml_path);

// The config as one self-contained YAML document (every section inline,
// every setting explicit); LoadTrainConfigText() reads it back. Checkpoints
// embed it, so a checkpoint alone rebuilds its networks and environment.
std::string TrainConfigToYaml(const TrainConfig& config);
TrainConfig LoadTrainConfigText(const std::string& yaml_text,
                                const std::string& source);

// Every setting of a training config with its default, allowed values and
// meaning, as a Markdown table (configs/README.md; `mimic2d train
// --list-settings`).
std::string TrainSettingsReference();

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAIN_CONFIG_H_
