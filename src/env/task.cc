#include "env/task.h"

#include <spdlog/spdlog.h>

#include "common/error.h"

namespace m2d {

TrackingTask BuildTrackingTask(std::shared_ptr<const Character> character,
                               std::vector<ReferenceBundle> bundles,
                               const TrackingTaskOptions& options,
                               const std::vector<std::string>& bundle_sources) {
  // Messages name bundle b by its file where the caller gave one.
  auto SourceOf = [&](size_t b, const std::string& inner_name) {
    return b < bundle_sources.size() ? bundle_sources[b] : inner_name;
  };
  std::vector<std::string> names;
  for (const ReferenceBundle& bundle : bundles) names.push_back(bundle.name);
  TrackingTask task;
  task.character = std::move(character);
  // `mimic2d fit` fails on such a fit but writes it for inspection: say so
  // when a task is built on it anyway.
  if (options.sources.initial_states == InitialStateSource::kEstimate ||
      options.sources.cameras == CameraSource::kEstimate) {
    for (size_t b = 0; b < bundles.size(); ++b) {
      const ReferenceBundle& bundle = bundles[b];
      if (!bundle.estimate) continue;  // Prepare names the missing estimate
      for (size_t v = 0; v < bundle.estimate->size(); ++v) {
        const FitSummary& fit = (*bundle.estimate)[v].summary;
        if (!fit.Unreliable()) continue;
        spdlog::warn(
            "{}: the fit of view {} did not converge on {} of {} frames "
            "(more than {:.0f}%): starts and cameras from it are "
            "unreliable; fit it again (docs/fit.md)",
            SourceOf(b, bundle.name),
            v < bundle.views.size() ? bundle.views[v].name : "?",
            fit.unconverged_frames.size(), fit.num_frames,
            100 * kMaxUnconvergedFraction);
      }
    }
  }
  try {
    task.reference = TrackingReference::Prepare(
        std::move(bundles), *task.character, options.simulation.control_hz,
        options.sources);
    task.initial_states = std::make_shared<InitialStates>(
        *task.reference, task.character, options.simulation, options.buffer,
        options.initial_state_noise_rad, options.noise_seed);
  } catch (const InputError& e) {
    // Errors raised with a bundle's inner name name its file instead.
    for (size_t b = 0; b < names.size() && b < bundle_sources.size(); ++b) {
      if (e.source() == names[b])
        throw InputError(bundle_sources[b], e.problem());
    }
    throw;
  }
  return task;
}

TrackingTask BuildTrackingTask(const std::string& character_config,
                               const std::string& scene,
                               const std::vector<std::string>& bundle_paths,
                               const TrackingTaskOptions& options) {
  auto character =
      LoadCharacterForSimulation(character_config, scene, options.simulation);
  std::vector<ReferenceBundle> bundles;
  for (const std::string& path : bundle_paths)
    bundles.push_back(ReadBundle(path));
  return BuildTrackingTask(std::move(character), std::move(bundles), options,
                           bundle_paths);
}

}  // namespace m2d
