// env: where a tracking task's cameras and initial states come from — the
// bundle's 3D truth and true cameras, a per-view estimate from `mimic2d
// fit`, or (initial states only) a default pose placed at the 2D root.
#ifndef MIMIC2D_ENV_SOURCES_H_
#define MIMIC2D_ENV_SOURCES_H_

#include <string>

namespace m2d {

enum class InitialStateSource {
  kTruth,     // the bundle's ground-truth poses (one buffer per bundle)
  kEstimate,  // each view's estimated poses (one buffer per view)
  kDefault,   // the default pose placed at the 2D root (one per bundle)
};

enum class CameraSource {
  kTruth,     // each view's true cameras
  kEstimate,  // each view's estimated cameras
};

struct TaskSources {
  InitialStateSource initial_states = InitialStateSource::kTruth;
  CameraSource cameras = CameraSource::kTruth;

  // Truth poses need the true cameras and estimated poses the estimated
  // ones: each lives in its own world frame. Throws ConfigError.
  void Validate() const;
};

// "truth", "estimate", "default".
const char* SourceName(InitialStateSource source);
const char* SourceName(CameraSource source);
// The inverse; ConfigError listing the accepted names otherwise.
InitialStateSource ParseInitialStateSource(const std::string& text);
CameraSource ParseCameraSource(const std::string& text);

// The same as settings (common/settings.h: found by argument-dependent
// lookup when a config field is one of these enums).
inline const char* SettingName(InitialStateSource source) {
  return SourceName(source);
}
inline const char* SettingName(CameraSource source) {
  return SourceName(source);
}
bool ParseSetting(const std::string& text, InitialStateSource* source);
bool ParseSetting(const std::string& text, CameraSource* source);
inline std::string SettingChoices(InitialStateSource) {
  return "truth, estimate, default";
}
inline std::string SettingChoices(CameraSource) { return "truth, estimate"; }

// "starts from <...>, cameras <...>" for logs and tables.
std::string DescribeSources(const TaskSources& sources);

}  // namespace m2d

#endif  // MIMIC2D_ENV_SOURCES_H_
