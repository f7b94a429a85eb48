#include "rl/train_config.h"

#include "common/error.h"
#include "common/file_io.h"
#include "common/yaml_fields.h"

namespace m2d {

void DataOptions::Validate() const {
  if (bundles.empty())
    throw ConfigError("data.bundles: list at least one bundle");
  if (character_config.empty())
    throw ConfigError("data.character_config is empty");
  try {
    sources().Validate();
  } catch (const ConfigError& e) {
    throw ConfigError(std::string("data: ") + e.what());
  }
}

TrackingTaskOptions TrainingTaskOptions(const TrainConfig& config) {
  TrackingTaskOptions options;
  options.simulation = config.env.simulation;
  options.sources = config.data.sources();
  options.buffer = config.asi.buffer;
  options.initial_state_noise_rad = config.env.initial_state_noise_rad;
  options.noise_seed = config.run.seed + 2'000'003;
  return options;
}

void ModelOptions::Validate() const {
  // Upper bounds far above useful sizes: a typo (or a damaged checkpoint's
  // config) is named instead of allocating beyond memory.
  constexpr int kMaxWidth = 65536, kMaxLayers = 64;
  if (encoder_features < 1 || encoder_features > kMaxWidth)
    throw ConfigError("model.encoder_features must be in [1, 65536]");
  for (const auto* layers : {&encoder_hidden, &policy_hidden, &critic_hidden}) {
    if (layers->size() > kMaxLayers)
      throw ConfigError("model: at most 64 hidden layers per network");
    for (int width : *layers) {
      if (width < 1 || width > kMaxWidth)
        throw ConfigError("model: layer widths must be in [1, 65536]");
    }
  }
  if (!(action_std > 0)) throw ConfigError("model.action_std must be > 0");
}

void PpoOptions::Validate() const {
  if (num_envs < 1 || steps_per_env < 1)
    throw ConfigError("agent: num_envs and steps_per_env must be >= 1");
  if (!(discount > 0 && discount < 1))
    throw ConfigError("agent.discount must be in (0, 1)");
  if (!(gae_lambda >= 0 && gae_lambda <= 1))
    throw ConfigError("agent.gae_lambda must be in [0, 1]");
  if (!(clip_ratio > 0)) throw ConfigError("agent.clip_ratio must be > 0");
  if (!(advantage_clip > 0))
    throw ConfigError("agent.advantage_clip must be > 0");
  if (epochs < 1) throw ConfigError("agent.epochs must be >= 1");
  if (minibatch_size < 1 || minibatch_size > batch_size()) {
    throw ConfigError(
        "agent.minibatch_size must be in [1, num_envs * steps_per_env]");
  }
  if (!(learning_rate > 0))
    throw ConfigError("agent.learning_rate must be > 0");
  if (!(target_kl >= 0)) throw ConfigError("agent.target_kl must be >= 0");
  if (!(learning_rate_min > 0 && learning_rate_min <= learning_rate_max)) {
    throw ConfigError(
        "agent.learning_rate_min must be > 0 and <= learning_rate_max");
  }
  if (!(max_grad_norm > 0))
    throw ConfigError("agent.max_grad_norm must be > 0");
  if (torch_threads < 1) throw ConfigError("agent.torch_threads must be >= 1");
  if (adapt_torch_threads && torch_threads < 2) {
    throw ConfigError(
        "agent.adapt_torch_threads needs agent.torch_threads >= 2 (it "
        "chooses between 1 and torch_threads)");
  }
}

void AsiOptions::Validate() const {
  if (capture_every_steps < 1)
    throw ConfigError("asi.capture_every_steps must be >= 1");
  buffer.Validate();
}

void RunOptions::Validate() const {
  if (run_dir.empty()) throw ConfigError("run.run_dir is empty");
  if (total_samples < 1) throw ConfigError("run.total_samples must be >= 1");
  if (!(checkpoint_minutes > 0))
    throw ConfigError("run.checkpoint_minutes must be > 0");
}

void TrainConfig::Validate() const {
  data.Validate();
  env.Validate();
  model.Validate();
  ppo.Validate();
  asi.Validate();
  run.Validate();
}

namespace {

// A top-level section: inline mapping, or a path to a YAML file with it.
YamlSection OpenSection(YamlSection& root, const YAML::Node& node,
                        const std::string& key, const std::string& source,
                        std::vector<YAML::Node>* keep_alive,
                        std::string* section_source) {
  *section_source = source;
  if (node[key] && node[key].IsScalar()) {
    std::string path = ResolveRelative(source, node[key].as<std::string>());
    keep_alive->push_back(ReadYamlFile(path));
    std::string ignored;
    root.Optional(key, &ignored);
    *section_source = path;
    return YamlSection(keep_alive->back(), path, "");
  }
  return root.Section(key);
}

}  // namespace

namespace {

TrainConfig ParseTrainConfig(const YAML::Node& node,
                             const std::string& yaml_path) {
  TrainConfig config;
  config.source_path = yaml_path;
  YamlSection root(node, yaml_path, "");
  std::vector<YAML::Node> files;
  std::string source;

  YamlSection data =
      OpenSection(root, node, "data", yaml_path, &files, &source);
  data.Optional("character_config", &config.data.character_config);
  data.Optional("scene", &config.data.scene);
  data.Optional("bundles", &config.data.bundles);
  std::string initial_states = SourceName(config.data.initial_states);
  std::string cameras = SourceName(config.data.cameras);
  data.Optional("initial_states", &initial_states);
  data.Optional("cameras", &cameras);
  try {
    config.data.initial_states = ParseInitialStateSource(initial_states);
  } catch (const ConfigError& e) {
    data.Fail("initial_states", std::string("is not known: ") + e.what());
  }
  try {
    config.data.cameras = ParseCameraSource(cameras);
  } catch (const ConfigError& e) {
    data.Fail("cameras", std::string("is not known: ") + e.what());
  }
  data.RejectUnknownKeys();

  YamlSection env = OpenSection(root, node, "env", yaml_path, &files, &source);
  TrackingEnvOptions& e = config.env;
  env.Optional("control_hz", &e.simulation.control_hz);
  env.Optional("physics_substeps", &e.simulation.physics_substeps);
  env.Optional("num_future_frames", &e.num_future_frames);
  env.Optional("max_episode_s", &e.max_episode_s);
  env.Optional("early_exit", &e.early_exit);
  env.Optional("early_exit_max_error_px", &e.early_exit_max_error_px);
  env.Optional("initial_state_noise_rad", &e.initial_state_noise_rad);
  YamlSection reward = env.Section("reward");
  reward.Optional("pose_weight", &e.reward.pose_weight);
  reward.Optional("pose_alpha_per_px", &e.reward.pose_alpha_per_px);
  reward.Optional("energy_weight", &e.reward.energy_weight);
  reward.Optional("object_weight", &e.reward.object_weight);
  reward.Optional("object_alpha_per_px", &e.reward.object_alpha_per_px);
  reward.RejectUnknownKeys();
  env.RejectUnknownKeys();

  YamlSection model =
      OpenSection(root, node, "model", yaml_path, &files, &source);
  model.Optional("encoder_hidden", &config.model.encoder_hidden);
  model.Optional("encoder_features", &config.model.encoder_features);
  model.Optional("policy_hidden", &config.model.policy_hidden);
  model.Optional("critic_hidden", &config.model.critic_hidden);
  model.Optional("action_std", &config.model.action_std);
  model.Optional("learn_action_std", &config.model.learn_action_std);
  model.RejectUnknownKeys();

  YamlSection agent =
      OpenSection(root, node, "agent", yaml_path, &files, &source);
  PpoOptions& p = config.ppo;
  agent.Optional("num_envs", &p.num_envs);
  agent.Optional("steps_per_env", &p.steps_per_env);
  agent.Optional("discount", &p.discount);
  agent.Optional("gae_lambda", &p.gae_lambda);
  agent.Optional("clip_ratio", &p.clip_ratio);
  agent.Optional("advantage_clip", &p.advantage_clip);
  agent.Optional("epochs", &p.epochs);
  agent.Optional("minibatch_size", &p.minibatch_size);
  agent.Optional("learning_rate", &p.learning_rate);
  agent.Optional("target_kl", &p.target_kl);
  agent.Optional("learning_rate_min", &p.learning_rate_min);
  agent.Optional("learning_rate_max", &p.learning_rate_max);
  agent.Optional("max_grad_norm", &p.max_grad_norm);
  agent.Optional("value_loss_weight", &p.value_loss_weight);
  agent.Optional("entropy_weight", &p.entropy_weight);
  agent.Optional("action_bound_weight", &p.action_bound_weight);
  agent.Optional("normalize_observations", &p.normalize_observations);
  agent.Optional("torch_threads", &p.torch_threads);
  agent.Optional("adapt_torch_threads", &p.adapt_torch_threads);
  agent.RejectUnknownKeys();

  YamlSection asi = OpenSection(root, node, "asi", yaml_path, &files, &source);
  asi.Optional("enabled", &config.asi.enabled);
  asi.Optional("capture_every_steps", &config.asi.capture_every_steps);
  asi.Optional("capacity_per_frame", &config.asi.buffer.capacity_per_frame);
  asi.Optional("temperature", &config.asi.buffer.temperature);
  asi.Optional("anchor_share", &config.asi.buffer.anchor_share);
  asi.RejectUnknownKeys();

  YamlSection run = OpenSection(root, node, "run", yaml_path, &files, &source);
  run.Optional("run_dir", &config.run.run_dir);
  run.Optional("seed", &config.run.seed);
  run.Optional("total_samples", &config.run.total_samples);
  run.Optional("checkpoint_minutes", &config.run.checkpoint_minutes);
  run.Optional("env_threads", &config.run.env_threads);
  run.RejectUnknownKeys();
  root.RejectUnknownKeys();

  try {
    config.Validate();
  } catch (const ConfigError& e) {
    throw InputError(yaml_path, e.what());
  }
  return config;
}

}  // namespace

TrainConfig LoadTrainConfig(const std::string& yaml_path) {
  return ParseTrainConfig(ReadYamlFile(yaml_path), yaml_path);
}

TrainConfig LoadTrainConfigText(const std::string& yaml_text,
                                const std::string& source) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(source, std::string("malformed YAML: ") + e.what());
  }
  return ParseTrainConfig(node, source);
}

std::string TrainConfigToYaml(const TrainConfig& config) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "data" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "character_config" << YAML::Value
      << config.data.character_config;
  out << YAML::Key << "scene" << YAML::Value << config.data.scene;
  out << YAML::Key << "bundles" << YAML::Value << YAML::Flow
      << config.data.bundles;
  out << YAML::Key << "initial_states" << YAML::Value
      << SourceName(config.data.initial_states);
  out << YAML::Key << "cameras" << YAML::Value
      << SourceName(config.data.cameras);
  out << YAML::EndMap;

  const TrackingEnvOptions& e = config.env;
  out << YAML::Key << "env" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "control_hz" << YAML::Value << e.simulation.control_hz;
  out << YAML::Key << "physics_substeps" << YAML::Value
      << e.simulation.physics_substeps;
  out << YAML::Key << "num_future_frames" << YAML::Value << e.num_future_frames;
  out << YAML::Key << "max_episode_s" << YAML::Value << e.max_episode_s;
  out << YAML::Key << "early_exit" << YAML::Value << e.early_exit;
  out << YAML::Key << "early_exit_max_error_px" << YAML::Value
      << e.early_exit_max_error_px;
  out << YAML::Key << "initial_state_noise_rad" << YAML::Value
      << e.initial_state_noise_rad;
  out << YAML::Key << "reward" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "pose_weight" << YAML::Value << e.reward.pose_weight;
  out << YAML::Key << "pose_alpha_per_px" << YAML::Value
      << e.reward.pose_alpha_per_px;
  out << YAML::Key << "energy_weight" << YAML::Value << e.reward.energy_weight;
  out << YAML::Key << "object_weight" << YAML::Value << e.reward.object_weight;
  out << YAML::Key << "object_alpha_per_px" << YAML::Value
      << e.reward.object_alpha_per_px;
  out << YAML::EndMap << YAML::EndMap;

  const ModelOptions& m = config.model;
  out << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "encoder_hidden" << YAML::Value << YAML::Flow
      << m.encoder_hidden;
  out << YAML::Key << "encoder_features" << YAML::Value << m.encoder_features;
  out << YAML::Key << "policy_hidden" << YAML::Value << YAML::Flow
      << m.policy_hidden;
  out << YAML::Key << "critic_hidden" << YAML::Value << YAML::Flow
      << m.critic_hidden;
  out << YAML::Key << "action_std" << YAML::Value << m.action_std;
  out << YAML::Key << "learn_action_std" << YAML::Value << m.learn_action_std;
  out << YAML::EndMap;

  const PpoOptions& p = config.ppo;
  out << YAML::Key << "agent" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "num_envs" << YAML::Value << p.num_envs;
  out << YAML::Key << "steps_per_env" << YAML::Value << p.steps_per_env;
  out << YAML::Key << "discount" << YAML::Value << p.discount;
  out << YAML::Key << "gae_lambda" << YAML::Value << p.gae_lambda;
  out << YAML::Key << "clip_ratio" << YAML::Value << p.clip_ratio;
  out << YAML::Key << "advantage_clip" << YAML::Value << p.advantage_clip;
  out << YAML::Key << "epochs" << YAML::Value << p.epochs;
  out << YAML::Key << "minibatch_size" << YAML::Value << p.minibatch_size;
  out << YAML::Key << "learning_rate" << YAML::Value << p.learning_rate;
  out << YAML::Key << "target_kl" << YAML::Value << p.target_kl;
  out << YAML::Key << "learning_rate_min" << YAML::Value << p.learning_rate_min;
  out << YAML::Key << "learning_rate_max" << YAML::Value << p.learning_rate_max;
  out << YAML::Key << "max_grad_norm" << YAML::Value << p.max_grad_norm;
  out << YAML::Key << "value_loss_weight" << YAML::Value << p.value_loss_weight;
  out << YAML::Key << "entropy_weight" << YAML::Value << p.entropy_weight;
  out << YAML::Key << "action_bound_weight" << YAML::Value
      << p.action_bound_weight;
  out << YAML::Key << "normalize_observations" << YAML::Value
      << p.normalize_observations;
  out << YAML::Key << "torch_threads" << YAML::Value << p.torch_threads;
  out << YAML::Key << "adapt_torch_threads" << YAML::Value
      << p.adapt_torch_threads;
  out << YAML::EndMap;

  out << YAML::Key << "asi" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << config.asi.enabled;
  out << YAML::Key << "capture_every_steps" << YAML::Value
      << config.asi.capture_every_steps;
  out << YAML::Key << "capacity_per_frame" << YAML::Value
      << config.asi.buffer.capacity_per_frame;
  out << YAML::Key << "temperature" << YAML::Value
      << config.asi.buffer.temperature;
  out << YAML::Key << "anchor_share" << YAML::Value
      << config.asi.buffer.anchor_share;
  out << YAML::EndMap;

  out << YAML::Key << "run" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "run_dir" << YAML::Value << config.run.run_dir;
  out << YAML::Key << "seed" << YAML::Value << config.run.seed;
  out << YAML::Key << "total_samples" << YAML::Value
      << config.run.total_samples;
  out << YAML::Key << "checkpoint_minutes" << YAML::Value
      << config.run.checkpoint_minutes;
  out << YAML::Key << "env_threads" << YAML::Value << config.run.env_threads;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace m2d
