#include "env/sources.h"

#include "common/error.h"
#include "common/settings.h"

namespace m2d {

void TaskSources::Validate() const {
  if (initial_states == InitialStateSource::kTruth &&
      cameras != CameraSource::kTruth) {
    throw ConfigError(
        "initial_states: truth needs cameras: truth (the true poses are in "
        "the true cameras' world frame)");
  }
  if (initial_states == InitialStateSource::kEstimate &&
      cameras != CameraSource::kEstimate) {
    throw ConfigError(
        "initial_states: estimate needs cameras: estimate (each view's "
        "estimated poses are in that view's own estimated world frame)");
  }
}

const char* SourceName(InitialStateSource source) {
  switch (source) {
    case InitialStateSource::kTruth:
      return "truth";
    case InitialStateSource::kEstimate:
      return "estimate";
    case InitialStateSource::kDefault:
      return "default";
  }
  return "?";
}

const char* SourceName(CameraSource source) {
  return source == CameraSource::kTruth ? "truth" : "estimate";
}

InitialStateSource ParseInitialStateSource(const std::string& text) {
  InitialStateSource source;
  if (ParseSetting(text, &source)) return source;
  throw ConfigError("unknown initial-state source '" + text +
                    "': truth, estimate or default");
}

CameraSource ParseCameraSource(const std::string& text) {
  CameraSource source;
  if (ParseSetting(text, &source)) return source;
  throw ConfigError("unknown camera source '" + text + "': truth or estimate");
}

bool ParseSetting(const std::string& text, InitialStateSource* source) {
  return ParseSettingByName(
      text,
      {InitialStateSource::kTruth, InitialStateSource::kEstimate,
       InitialStateSource::kDefault},
      source);
}

bool ParseSetting(const std::string& text, CameraSource* source) {
  return ParseSettingByName(
      text, {CameraSource::kTruth, CameraSource::kEstimate}, source);
}

std::string DescribeSources(const TaskSources& sources) {
  std::string starts;
  switch (sources.initial_states) {
    case InitialStateSource::kTruth:
      starts = "the 3D ground truth";
      break;
    case InitialStateSource::kEstimate:
      starts = "the fitted estimate";
      break;
    case InitialStateSource::kDefault:
      starts = "the default pose placed at the 2D root";
      break;
  }
  const std::string buffers =
      sources.initial_states == InitialStateSource::kEstimate
          ? ", one buffer per view"
          : "";
  return "initial states from " + starts + " (" +
         SourceName(sources.initial_states) + buffers + "), cameras from the " +
         (sources.cameras == CameraSource::kTruth ? "true cameras"
                                                  : "fitted estimate") +
         " (" + SourceName(sources.cameras) + ")";
}

}  // namespace m2d
