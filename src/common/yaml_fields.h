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

}  // namespace m2d

#endif  // MIMIC2D_COMMON_YAML_FIELDS_H_
