// fit: FitOptions read from a YAML file (`mimic2d fit --config`, `mimic2d
// bench fit --config`), every key named as the FitOptions field it sets.
#ifndef MIMIC2D_FIT_FIT_CONFIG_H_
#define MIMIC2D_FIT_FIT_CONFIG_H_

#include <string>

#include "fit/fit.h"

namespace m2d {

// Starts from `defaults` and sets the keys present in `path` (a flat map;
// `camera_motion: static|moving`). InputError naming the file and key for
// an unknown key or a wrong type; ConfigError from Validate().
FitOptions ReadFitOptions(const std::string& path,
                          const FitOptions& defaults = {});

// Every FitOptions setting with its default, allowed values and meaning, as
// a Markdown table (docs/fit.md; `mimic2d fit --list-settings`).
std::string FitSettingsReference();

}  // namespace m2d

#endif  // MIMIC2D_FIT_FIT_CONFIG_H_
