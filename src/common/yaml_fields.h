// common: typed reading of YAML config sections at the edge. Every key is
// read into a typed field once; unknown keys and wrong types are errors that
// name the file and the key, so a typo never silently keeps a default.
#ifndef MIMIC2D_COMMON_YAML_FIELDS_H_
#define MIMIC2D_COMMON_YAML_FIELDS_H_

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "common/error.h"
#include "common/settings.h"

namespace m2d {

class YamlSection {
 public:
  // `node` may be null/undefined (an absent section: every key keeps its
  // default). `where` is the section's path, e.g. "env.reward".
  YamlSection(YAML::Node node, std::string source, std::string where);

  // Reads `key` into `*value` when present; InputError on a wrong type.
  template <typename T>
  void Optional(const std::string& key, T* value) {
    YAML::Node child = Child(key);
    if (!child || child.IsNull()) return;  // absent or empty: keep the default
    T read;
    try {
      read = child.as<T>();
    } catch (const YAML::Exception&) {
      Fail(key, "has the wrong type");
    }
    // No setting of ours means infinity or NaN (`.inf` trained to NaN and
    // `max_episode_s: .inf` made 1-frame episodes): reject them here, once.
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(read)) Fail(key, "must be a finite number");
    }
    *value = read;
  }
  // A nested section (absent -> empty section).
  YamlSection Section(const std::string& key);
  bool Has(const std::string& key) const;

  // InputError naming every key that was never read.
  void RejectUnknownKeys() const;
  [[noreturn]] void Fail(const std::string& key,
                         const std::string& problem) const;

 private:
  YAML::Node Child(const std::string& key);

  YAML::Node node_;
  std::string source_;
  std::string where_;
  std::set<std::string> read_keys_;
};

// Reads every field `Options::VisitFields` lists (common/settings.h) from
// `section`: absent keys keep their values; a wrong type, an unknown enum
// name or a value outside its range is an InputError naming the file and
// the key. Unknown keys are left to the caller's RejectUnknownKeys() (one
// section may hold the fields of several structs).
class YamlFieldReader {
 public:
  explicit YamlFieldReader(YamlSection& section) : section_(section) {}

  template <typename T>
  void operator()(const char* key, T& value, const Range& range,
                  const char* meaning) {
    if constexpr (std::is_enum_v<T>) {
      std::string name = SettingName(value);
      section_.Optional(key, &name);
      if (!ParseSetting(name, &value))
        section_.Fail(key, "must be one of " + SettingChoices(value));
    } else {
      section_.Optional(key, &value);
      // The same check Validate() runs, named here by file and key.
      try {
        RangeChecker("")(key, value, range, meaning);
      } catch (const ConfigError&) {
        section_.Fail(key, "must be in " + range.ToString());
      }
    }
  }
  template <typename Options>
  void Nested(const char* key, Options& options) {
    YamlSection inner = section_.Section(key);
    YamlFieldReader reader(inner);
    Options::VisitFields(options, reader);
    inner.RejectUnknownKeys();
  }

 private:
  YamlSection& section_;
};

template <typename Options>
void ReadFields(YamlSection& section, Options& options) {
  YamlFieldReader reader(section);
  Options::VisitFields(options, reader);
}

// Emits every field as `key: value` pairs into the open map of `out`
// (lists in flow style, enums by name, sub-sections as nested maps).
class YamlFieldWriter {
 public:
  explicit YamlFieldWriter(YAML::Emitter& out) : out_(out) {}

  template <typename T>
  void operator()(const char* key, const T& value, const Range& /*range*/,
                  const char* /*meaning*/) {
    out_ << YAML::Key << key << YAML::Value;
    WriteValue(out_, value);
  }
  template <typename Options>
  void Nested(const char* key, const Options& options) {
    out_ << YAML::Key << key << YAML::Value << YAML::BeginMap;
    Options::VisitFields(options, *this);
    out_ << YAML::EndMap;
  }

  template <typename T>
  static void WriteValue(YAML::Emitter& out, const T& value) {
    if constexpr (std::is_enum_v<T>) {
      out << SettingName(value);
    } else if constexpr (IsVector<T>::value) {
      out << YAML::Flow << value;
    } else {
      out << value;
    }
  }

 private:
  YAML::Emitter& out_;
};

template <typename Options>
void WriteFields(YAML::Emitter& out, const Options& options) {
  YamlFieldWriter writer(out);
  Options::VisitFields(options, writer);
}

// One row of the settings reference: "section.key", the default as YAML,
// the allowed range (or the enum's names) and the meaning.
struct SettingRow {
  std::string key;
  std::string default_value;
  std::string range;
  std::string meaning;
};

class SettingRowCollector {
 public:
  SettingRowCollector(std::string section, std::vector<SettingRow>* rows)
      : section_(std::move(section)), rows_(rows) {}

  template <typename T>
  void operator()(const char* key, const T& value, const Range& range,
                  const char* meaning) {
    YAML::Emitter text;
    text.SetDoublePrecision(6);  // for reading; configs keep full precision
    YamlFieldWriter::WriteValue(text, value);
    std::string allowed;
    if constexpr (std::is_enum_v<T>) {
      allowed = SettingChoices(value);
    } else {
      allowed = range.ToString();
    }
    rows_->push_back({section_ + "." + key, text.c_str(), allowed, meaning});
  }
  template <typename Options>
  void Nested(const char* key, const Options& options) {
    SettingRowCollector inner(section_ + "." + key, rows_);
    Options::VisitFields(options, inner);
  }

 private:
  std::string section_;
  std::vector<SettingRow>* rows_;
};

template <typename Options>
void AppendSettingRows(const std::string& section, const Options& defaults,
                       std::vector<SettingRow>* rows) {
  SettingRowCollector collector(section, rows);
  Options::VisitFields(defaults, collector);
}

// The rows as a Markdown table (setting | default | allowed | meaning).
std::string SettingsTableMarkdown(const std::vector<SettingRow>& rows);

// YAML text as a node; InputError naming `source` when it is malformed.
YAML::Node ParseYamlText(const std::string& text, const std::string& source);

// A config made of sections, each an options struct: `for_each_section(
// config, visit)` calls visit(key, options) for every section in order.
// Every setting of every section as YAML (what checkpoints embed).
template <typename Config, typename ForEachSection>
std::string SectionsToYaml(const Config& config,
                           ForEachSection for_each_section) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  for_each_section(config, [&](const char* key, const auto& options) {
    out << YAML::Key << key << YAML::Value << YAML::BeginMap;
    WriteFields(out, options);
    out << YAML::EndMap;
  });
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// The reference table of every setting of a default-constructed Config.
template <typename Config, typename ForEachSection>
std::string SectionsSettingsReference(ForEachSection for_each_section) {
  const Config defaults;
  std::vector<SettingRow> rows;
  for_each_section(defaults, [&](const char* key, const auto& options) {
    AppendSettingRows(key, options, &rows);
  });
  return SettingsTableMarkdown(rows);
}

}  // namespace m2d

#endif  // MIMIC2D_COMMON_YAML_FIELDS_H_
