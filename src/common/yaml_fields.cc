#include "common/yaml_fields.h"

namespace m2d {

YamlSection::YamlSection(YAML::Node node, std::string source, std::string where)
    : node_(node), source_(std::move(source)), where_(std::move(where)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw InputError(source_, (where_.empty() ? "top level" : where_) +
                                  ": expected a mapping of settings");
  }
  // yaml-cpp keeps the first of two equal keys; a second one is a mistake
  // the user should hear about, not a silently ignored setting.
  if (node_ && node_.IsMap()) {
    std::set<std::string> seen;
    for (const auto& entry : node_) {
      if (!entry.first.IsScalar()) {
        throw InputError(source_, (where_.empty() ? "top level" : where_) +
                                      ": a key is not a plain name (a list "
                                      "or mapping used as a key)");
      }
      const std::string key = entry.first.Scalar();
      if (!seen.insert(key).second) Fail(key, "appears twice");
    }
  }
}

YAML::Node YamlSection::Child(const std::string& key) {
  read_keys_.insert(key);
  if (!node_ || !node_.IsMap()) return YAML::Node();
  return node_[key];
}

bool YamlSection::Has(const std::string& key) const {
  return node_ && node_.IsMap() && node_[key];
}

YamlSection YamlSection::Section(const std::string& key) {
  return YamlSection(Child(key), source_,
                     where_.empty() ? key : where_ + "." + key);
}

void YamlSection::RejectUnknownKeys() const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& entry : node_) {
    std::string key = entry.first.as<std::string>();
    if (read_keys_.count(key) == 0) Fail(key, "is not a known setting");
  }
}

void YamlSection::Fail(const std::string& key,
                       const std::string& problem) const {
  throw InputError(source_, "'" + (where_.empty() ? key : where_ + "." + key) +
                                "' " + problem);
}

std::string SettingsTableMarkdown(const std::vector<SettingRow>& rows) {
  std::string table =
      "| setting | default | allowed | meaning |\n|---|---|---|---|\n";
  for (const SettingRow& row : rows) {
    std::string default_value = row.default_value;
    if (default_value.empty()) default_value = "\"\"";
    table += "| `" + row.key + "` | `" + default_value + "` | " + row.range +
             " | " + row.meaning + " |\n";
  }
  return table;
}

YAML::Node ParseYamlText(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source, std::string("malformed YAML: ") + e.what());
  }
}

}  // namespace m2d
