#include "gen/gen_config.h"

#include "common/error.h"
#include "common/file_io.h"
#include "common/yaml_fields.h"

namespace m2d {

void GenDataOptions::Validate() const {
  CheckRanges(*this, "data");
  if (motions.empty())
    throw ConfigError("data.motions: list at least one motion");
  try {
    views.Validate();
  } catch (const ConfigError& e) {
    throw ConfigError(std::string("data.") + e.what());
  }
}

void VqVaeOptions::Validate() const {
  CheckRanges(*this, "tokenizer");
  if (window_frames % frames_per_token() != 0) {
    throw ConfigError("tokenizer.window_frames must be a multiple of " +
                      std::to_string(frames_per_token()) +
                      " (2^down_levels frames per token)");
  }
}

void GptOptions::Validate() const {
  CheckRanges(*this, "prior");
  if (embedding % num_heads != 0)
    throw ConfigError("prior.embedding must be a multiple of prior.num_heads");
}

void GenConfig::Validate() const {
  data.Validate();
  tokenizer.Validate();
  prior.Validate();
  if (prior.condition_on_motion && !prior.condition_on_view)
    throw ConfigError(
        "prior.condition_on_motion needs prior.condition_on_view (the token "
        "names a view and a motion)");
  CheckRanges(run, "run");
  if (run.run_dir.empty()) throw ConfigError("run.run_dir is empty");
  if (run.adapt_torch_threads && run.torch_threads < 2)
    throw ConfigError(
        "run.adapt_torch_threads needs run.torch_threads >= 2 (it probes 1 "
        "thread against torch_threads)");
}

namespace {

template <typename Config, typename Visit>
void ForEachGenSection(Config& config, Visit visit) {
  visit("data", config.data);
  visit("tokenizer", config.tokenizer);
  visit("prior", config.prior);
  visit("run", config.run);
}

GenConfig ParseGenConfig(const YAML::Node& node, const std::string& source) {
  GenConfig config;
  config.source_path = source;
  try {
    YamlSection root(node, source, "");
    ForEachGenSection(config, [&](const char* key, auto& options) {
      YamlSection section = root.Section(key);
      ReadFields(section, options);
      section.RejectUnknownKeys();
    });
    root.RejectUnknownKeys();
  } catch (const YAML::Exception& e) {
    throw InputError(source, std::string("malformed YAML: ") + e.what());
  }
  try {
    config.Validate();
  } catch (const ConfigError& e) {
    throw InputError(source, e.what());
  }
  return config;
}

}  // namespace

GenConfig LoadGenConfig(const std::string& yaml_path) {
  return ParseGenConfig(ReadYamlFile(yaml_path), yaml_path);
}

GenConfig LoadGenConfigText(const std::string& yaml_text,
                            const std::string& source) {
  return ParseGenConfig(ParseYamlText(yaml_text, source), source);
}

std::string GenConfigToYaml(const GenConfig& config) {
  return SectionsToYaml(
      config, [](const auto& c, auto visit) { ForEachGenSection(c, visit); });
}

std::string GenSettingsReference() {
  return SectionsSettingsReference<GenConfig>(
      [](const auto& c, auto visit) { ForEachGenSection(c, visit); });
}

void SamplingOptions::Validate() const {
  if (!(temperature > 0) || top_k < 0 || kept_context_tokens < 0)
    throw ConfigError(
        "sampling: temperature must be > 0, top_k and kept_context_tokens "
        ">= 0");
}

}  // namespace m2d
