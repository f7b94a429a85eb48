#include "rl/speed_tuner.h"

#include <algorithm>

#include "common/error.h"

namespace m2d {

double RunningAverage(double average, double value, double weight) {
  return average == 0 ? value : (1 - weight) * average + weight * value;
}

void SpeedTunerOptions::Validate() const {
  if (num_candidates < 2)
    throw ConfigError("speed tuner: num_candidates must be >= 2");
  if (first_probe_after < 1 || max_probe_interval < first_probe_after)
    throw ConfigError(
        "speed tuner: need 1 <= first_probe_after <= max_probe_interval");
  if (!(switch_margin >= 0 && switch_margin < 1))
    throw ConfigError("speed tuner: switch_margin must be in [0, 1)");
  if (!(average_weight > 0 && average_weight <= 1))
    throw ConfigError("speed tuner: average_weight must be in (0, 1]");
  if (!(slowdown_factor > 1))
    throw ConfigError("speed tuner: slowdown_factor must be > 1");
}

SpeedTuner::SpeedTuner(const SpeedTunerOptions& options)
    : options_(options), probe_interval_(options.first_probe_after) {
  options_.Validate();
}

int SpeedTuner::NextProbe() const {
  return (chosen_ + probe_offset_) % options_.num_candidates;
}

int SpeedTuner::CandidateForNextIteration() const {
  // No probe before the chosen candidate has a measurement to compare with.
  const bool probe =
      chosen_average_ > 0 && iterations_since_probe_ >= probe_interval_;
  return probe ? NextProbe() : chosen_;
}

bool SpeedTuner::Record(int candidate, double seconds_per_sample) {
  if (!(seconds_per_sample > 0)) return false;  // nothing measured
  if (candidate < 0 || candidate >= options_.num_candidates) return false;
  if (candidate == chosen_) {
    if (chosen_average_ > 0 &&
        seconds_per_sample > options_.slowdown_factor * chosen_average_) {
      probe_interval_ = options_.first_probe_after;
      iterations_since_probe_ = probe_interval_ - 1;  // probe next
    }
    // A running average: single iterations vary by a few percent.
    chosen_average_ = RunningAverage(chosen_average_, seconds_per_sample,
                                     options_.average_weight);
    ++iterations_since_probe_;
    return false;
  }
  // A probe of another candidate; the next probe tries the one after it.
  iterations_since_probe_ = 0;
  probe_offset_ = probe_offset_ % (options_.num_candidates - 1) + 1;
  if (seconds_per_sample < (1 - options_.switch_margin) * chosen_average_) {
    chosen_ = candidate;
    chosen_average_ = seconds_per_sample;
    probe_offset_ = 1;
    // Conditions just changed: look again soon.
    probe_interval_ = options_.first_probe_after;
    return true;
  }
  probe_interval_ = std::min(2 * probe_interval_, options_.max_probe_interval);
  return false;
}

}  // namespace m2d
