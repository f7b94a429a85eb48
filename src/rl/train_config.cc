#include "rl/train_config.h"

#include "common/error.h"
#include "common/file_io.h"
#include "common/settings.h"
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

const char* SettingName(TrainingPrecision precision) {
  switch (precision) {
    case TrainingPrecision::kFp32:
      return "fp32";
    case TrainingPrecision::kBf16:
      return "bf16";
    case TrainingPrecision::kAuto:
      return "auto";
  }
  return "?";
}

bool ParseSetting(const std::string& text, TrainingPrecision* precision) {
  return ParseSettingByName(text,
                            {TrainingPrecision::kFp32, TrainingPrecision::kBf16,
                             TrainingPrecision::kAuto},
                            precision);
}

Bf16Support MeasureBf16Support(
    const std::function<double(TrainingPrecision, int)>& time_step) {
  Bf16Support support;
  // The untimed steps warm oneDNN's kernels and autocast's casts; the bf16
  // ones are where oneDNN refuses, if it does.
  time_step(TrainingPrecision::kFp32, 1);
  try {
    time_step(TrainingPrecision::kBf16, 1);
    const double fp32_s = time_step(TrainingPrecision::kFp32, 3);
    support.speedup = fp32_s / time_step(TrainingPrecision::kBf16, 3);
    support.runs = true;
  } catch (const std::exception& e) {
    support.error = e.what();
    // LibTorch appends a C++ backtrace to its messages: keep the first line.
    support.error = support.error.substr(0, support.error.find('\n'));
  }
  return support;
}

TrainingPrecision ResolvePrecision(TrainingPrecision precision) {
  if (precision != TrainingPrecision::kAuto) return precision;
  const Bf16Support& bf16 = ProbeBf16();
  return bf16.runs && bf16.speedup >= kAutoBf16MinSpeedup
             ? TrainingPrecision::kBf16
             : TrainingPrecision::kFp32;
}

void RequirePrecisionRuns(TrainingPrecision precision,
                          const std::string& setting) {
  if (precision != TrainingPrecision::kBf16) return;
  const Bf16Support& bf16 = ProbeBf16();
  if (bf16.runs) return;
  throw ConfigError(setting + ": bf16 does not run on this CPU and LibTorch (" +
                    bf16.error + "); use fp32, or auto to choose");
}

const char* SettingName(CollectionMode mode) {
  return mode == CollectionMode::kPerThread ? "per_thread" : "batched";
}

bool ParseSetting(const std::string& text, CollectionMode* mode) {
  return ParseSettingByName(
      text, {CollectionMode::kBatched, CollectionMode::kPerThread}, mode);
}

const char* SettingName(HardViewMeasure measure) {
  switch (measure) {
    case HardViewMeasure::kFullRollout:
      return "full_rollout";
    case HardViewMeasure::kHazard:
      return "hazard";
    case HardViewMeasure::kHazardSamples:
      return "hazard_samples";
  }
  return "?";
}

bool ParseSetting(const std::string& text, HardViewMeasure* measure) {
  return ParseSettingByName(
      text,
      {HardViewMeasure::kFullRollout, HardViewMeasure::kHazard,
       HardViewMeasure::kHazardSamples},
      measure);
}

void ModelOptions::Validate() const {
  CheckRanges(*this, "model");
  // Far above useful depths: a typo (or a damaged checkpoint's config) is
  // named instead of allocating beyond memory.
  constexpr size_t kMaxLayers = 64;
  for (const auto* layers : {&encoder_hidden, &policy_hidden, &critic_hidden}) {
    if (layers->size() > kMaxLayers)
      throw ConfigError("model: at most 64 hidden layers per network");
  }
}

void PpoOptions::Validate() const {
  CheckRanges(*this, "agent");
  if (minibatch_size > batch_size()) {
    throw ConfigError(
        "agent.minibatch_size must be in [1, num_envs * steps_per_env]");
  }
  if (learning_rate_min > learning_rate_max) {
    throw ConfigError(
        "agent.learning_rate_min must be > 0 and <= learning_rate_max");
  }
  if (adapt_torch_threads && torch_threads < 2) {
    throw ConfigError(
        "agent.adapt_torch_threads needs agent.torch_threads >= 2 (it "
        "chooses between 1 and torch_threads)");
  }
  if (overlap_update && adapt_torch_threads) {
    throw ConfigError(
        "agent.overlap_update and agent.adapt_torch_threads exclude each "
        "other (with overlap, collection and update each run on one "
        "LibTorch thread)");
  }
  if (overlap_update && collection == CollectionMode::kPerThread) {
    throw ConfigError(
        "agent.overlap_update and agent.collection: per_thread exclude each "
        "other (overlap collects on one thread)");
  }
}

void AsiOptions::Validate() const { CheckRanges(*this, "asi"); }

void RunOptions::Validate() const {
  CheckRanges(*this, "run");
  if (run_dir.empty()) throw ConfigError("run.run_dir is empty");
}

void TrainConfig::Validate() const {
  data.Validate();
  env.Validate();
  model.Validate();
  ppo.Validate();
  asi.Validate();
  run.Validate();
  if (env.critic_observes_3d &&
      data.sources().initial_states == InitialStateSource::kDefault) {
    throw ConfigError(
        "env.critic_observes_3d needs a 3D reference for the critic: "
        "data.initial_states truth or estimate, not default");
  }
}

namespace {

// The sections of a training config, in file order, with their structs.
template <typename Config, typename Visit>
void ForEachSection(Config& config, Visit visit) {
  visit("data", config.data);
  visit("env", config.env);
  visit("model", config.model);
  visit("agent", config.ppo);
  visit("asi", config.asi);
  visit("run", config.run);
}

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

  // Each section's fields come from its struct's VisitFields; a wrong type
  // or an out-of-range value names the file and key here, before Validate.
  ForEachSection(config, [&](const char* key, auto& options) {
    YamlSection section =
        OpenSection(root, node, key, yaml_path, &files, &source);
    ReadFields(section, options);
    section.RejectUnknownKeys();
  });
  root.RejectUnknownKeys();

  try {
    config.Validate();
  } catch (const ConfigError& e) {
    throw InputError(yaml_path, e.what());
  }
  return config;
}

// yaml-cpp's conversions throw YAML::Exception on shapes the typed readers
// did not foresee: still the file's fault, so named as such.
TrainConfig ParseTrainConfigNamingErrors(const YAML::Node& node,
                                         const std::string& source) {
  try {
    return ParseTrainConfig(node, source);
  } catch (const YAML::Exception& e) {
    throw InputError(source, std::string("malformed YAML: ") + e.what());
  }
}

}  // namespace

TrainConfig LoadTrainConfig(const std::string& yaml_path) {
  return ParseTrainConfigNamingErrors(ReadYamlFile(yaml_path), yaml_path);
}

TrainConfig LoadTrainConfigText(const std::string& yaml_text,
                                const std::string& source) {
  return ParseTrainConfigNamingErrors(ParseYamlText(yaml_text, source), source);
}

std::string TrainConfigToYaml(const TrainConfig& config) {
  return SectionsToYaml(
      config, [](const auto& c, auto visit) { ForEachSection(c, visit); });
}

std::string TrainSettingsReference() {
  return SectionsSettingsReference<TrainConfig>(
      [](const auto& c, auto visit) { ForEachSection(c, visit); });
}

}  // namespace m2d
