#include "rl/thread_tuner.h"

#include <algorithm>

#include "common/error.h"

namespace m2d {

void ThreadTunerOptions::Validate() const {
  if (max_threads < 2)
    throw ConfigError("thread tuner: max_threads must be >= 2");
  if (first_probe_after < 1 || max_probe_interval < first_probe_after)
    throw ConfigError(
        "thread tuner: need 1 <= first_probe_after <= max_probe_interval");
  if (!(switch_margin >= 0 && switch_margin < 1))
    throw ConfigError("thread tuner: switch_margin must be in [0, 1)");
  if (!(average_weight > 0 && average_weight <= 1))
    throw ConfigError("thread tuner: average_weight must be in (0, 1]");
  if (!(slowdown_factor > 1))
    throw ConfigError("thread tuner: slowdown_factor must be > 1");
}

ThreadTuner::ThreadTuner(const ThreadTunerOptions& options)
    : options_(options),
      chosen_threads_(options.max_threads),
      probe_interval_(options.first_probe_after) {
  options_.Validate();
}

int ThreadTuner::Other() const {
  return chosen_threads_ == 1 ? options_.max_threads : 1;
}

int ThreadTuner::ThreadsForNextIteration() {
  // No probe before the chosen count has a measurement to compare with.
  const bool probe =
      chosen_average_ > 0 && iterations_since_probe_ >= probe_interval_;
  return probe ? Other() : chosen_threads_;
}

bool ThreadTuner::Record(int threads, double seconds_per_sample) {
  if (!(seconds_per_sample > 0)) return false;  // nothing measured
  if (threads == chosen_threads_) {
    if (chosen_average_ > 0 &&
        seconds_per_sample > options_.slowdown_factor * chosen_average_) {
      probe_interval_ = options_.first_probe_after;
      iterations_since_probe_ = probe_interval_ - 1;  // probe next
    }
    // A running average: single iterations vary by a few percent.
    chosen_average_ = chosen_average_ == 0
                          ? seconds_per_sample
                          : (1 - options_.average_weight) * chosen_average_ +
                                options_.average_weight * seconds_per_sample;
    ++iterations_since_probe_;
    return false;
  }
  // A probe of the other count.
  iterations_since_probe_ = 0;
  if (seconds_per_sample < (1 - options_.switch_margin) * chosen_average_) {
    chosen_threads_ = threads;
    chosen_average_ = seconds_per_sample;
    // Conditions just changed: look again soon.
    probe_interval_ = options_.first_probe_after;
    return true;
  }
  probe_interval_ = std::min(2 * probe_interval_, options_.max_probe_interval);
  return false;
}

}  // namespace m2d
