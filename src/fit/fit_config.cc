#include "fit/fit_config.h"

#include "common/file_io.h"
#include "common/yaml_fields.h"

namespace m2d {

namespace {

FitOptions ParseFitOptions(const YAML::Node& root, const std::string& path,
                           const FitOptions& defaults) {
  if (root && !root.IsNull() && !root.IsMap())
    throw InputError(path, "expected a map of FitOptions fields");
  FitOptions options = defaults;
  YamlSection section(root, path, "");
  ReadFields(section, options);  // names the file and key on bad values
  section.RejectUnknownKeys();
  try {
    options.Validate();
  } catch (const ConfigError& e) {
    throw InputError(path, e.what());
  }
  return options;
}

}  // namespace

FitOptions ReadFitOptions(const std::string& path, const FitOptions& defaults) {
  const YAML::Node root = ReadYamlFile(path);
  try {
    return ParseFitOptions(root, path, defaults);
  } catch (const YAML::Exception& e) {
    // A shape the typed reads did not foresee: still the file's fault.
    throw InputError(path, std::string("malformed YAML: ") + e.what());
  }
}

std::string FitSettingsReference() {
  std::vector<SettingRow> rows;
  AppendSettingRows("", FitOptions(), &rows);
  for (SettingRow& row : rows) row.key = row.key.substr(1);  // no section
  return SettingsTableMarkdown(rows);
}

}  // namespace m2d
