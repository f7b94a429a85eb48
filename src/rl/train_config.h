// rl: learning the tracking policy — configs, networks, PPO with Adaptive
// State Initialization, checkpoints and the training loop. LibTorch is
// confined to this folder (this header does not include it).
#ifndef MIMIC2D_RL_TRAIN_CONFIG_H_
#define MIMIC2D_RL_TRAIN_CONFIG_H_

#include <cstdint>
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

  void Validate() const;
};

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
  // (rl/thread_tuner.h): more threads collapse when another process competes
  // for the cores.
  bool adapt_torch_threads = false;

  int batch_size() const { return num_envs * steps_per_env; }
  void Validate() const;
};

// Adaptive State Initialization.
struct AsiOptions {
  bool enabled = true;
  int capture_every_steps = 4;        // visited states offered to the buffers
  StateBufferOptions buffer{4, 2.0};  // per frame: 4 states, T = 2 (of V)

  void Validate() const;
};

// The run: where, how long, how often to save.
struct RunOptions {
  std::string run_dir = "runs/default";
  uint64_t seed = 1;
  int64_t total_samples = 20'000'000;  // stop after this many env steps
  double checkpoint_minutes = 5.0;     // periodic atomic checkpoint
  int env_threads = 2;                 // OpenMP threads stepping envs

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

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAIN_CONFIG_H_
