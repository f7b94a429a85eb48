// env: a tracking task — the character, its prepared reference (cameras
// and what else the sources allow) and its initial-state buffers, built in
// one place for training, evaluation, rendering, benchmarks and tests.
#ifndef MIMIC2D_ENV_TASK_H_
#define MIMIC2D_ENV_TASK_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "env/reference.h"
#include "env/sources.h"
#include "env/state_buffer.h"
#include "motion/bundle.h"
#include "sim/simulation.h"

namespace m2d {

struct TrackingTaskOptions {
  SimulationOptions simulation;  // control rate = the bundles' fps
  TaskSources sources;           // where cameras and initial states come from
  StateBufferOptions buffer;     // ASI buffers (evaluation: the defaults)
  // Noisy S.I. (rad): added once to the buffers' joint angles; 0 for
  // evaluation.
  double initial_state_noise_rad = 0.0;
  uint64_t noise_seed = 0;
};

struct TrackingTask {
  std::shared_ptr<const Character> character;
  std::shared_ptr<const TrackingReference> reference;
  std::shared_ptr<InitialStates> initial_states;
};

// Prepares `bundles` for `character` under the options' sources and fills
// the initial states. Warnings and input errors name each bundle by
// `bundle_sources` (its file; empty: the bundles' inner names).
TrackingTask BuildTrackingTask(
    std::shared_ptr<const Character> character,
    std::vector<ReferenceBundle> bundles, const TrackingTaskOptions& options,
    const std::vector<std::string>& bundle_sources = {});

// The same for the character of `character_config` in `scene` (loaded for
// the options' simulation) and the bundle files `bundle_paths`.
TrackingTask BuildTrackingTask(const std::string& character_config,
                               const std::string& scene,
                               const std::vector<std::string>& bundle_paths,
                               const TrackingTaskOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_ENV_TASK_H_
