// rl: picks how the networks run while training (LibTorch's thread count,
// the arithmetic precision) from measured speed.
//
// Neither choice can be made once at start-up. Two threads make an
// iteration 1.25x faster on an idle 2-core machine, but 4-30x slower as
// soon as another process competes for a core: every parallel op waits for
// a descheduled thread. And bfloat16 against float32 flips with the load
// on some CPUs (0.63x idle, 1.75x beside another process on one Intel
// Xeon; docs/training.md, "Throughput", items 3 and 5). So the tuner runs
// the chosen setting and, now and then, one probe iteration with another
// candidate (in turn); the faster seconds per sample wins. Probes that
// lose are spaced out further (exponential backoff), so the probing costs
// little in either steady state; a sudden slowdown probes at once.
//
// The tuner knows candidates by index; the caller maps them to settings
// (rl/trainer.cc: threads x precision). Candidate 0 is the starting pick.
// The caller leaves out iterations that span a stop of the process or the
// machine's sleep (common/pauses.h): they measure the pause.
#ifndef MIMIC2D_RL_SPEED_TUNER_H_
#define MIMIC2D_RL_SPEED_TUNER_H_

namespace m2d {

// An exponential running average: `value` itself while `average` is 0 (no
// measurement yet), else (1 - weight) * average + weight * value.
double RunningAverage(double average, double value, double weight);

struct SpeedTunerOptions {
  int num_candidates = 2;        // settings to choose among (>= 2)
  int first_probe_after = 4;     // iterations between probes, at first
  int max_probe_interval = 320;  // backoff cap (iterations)
  double switch_margin = 0.05;   // a probe must be this much faster (5 %)
  double average_weight = 0.2;   // EMA weight of each new measurement
  // An iteration this much slower than the average probes at once (a
  // competing process appeared: do not wait out a long backoff).
  double slowdown_factor = 1.5;

  void Validate() const;
};

class SpeedTuner {
 public:
  explicit SpeedTuner(const SpeedTunerOptions& options);

  // The candidate for the next iteration: the chosen one, or a probe of
  // the next other one in turn.
  int CandidateForNextIteration() const;
  // Reports the iteration's seconds per sample, measured with `candidate`.
  // Returns true if the chosen candidate changed.
  bool Record(int candidate, double seconds_per_sample);

  int chosen() const { return chosen_; }
  // Running average of the chosen candidate's seconds per sample (0: none
  // yet).
  double chosen_seconds_per_sample() const { return chosen_average_; }
  int probe_interval() const { return probe_interval_; }

 private:
  // The candidate probed next: the others in turn, from chosen_ + 1.
  int NextProbe() const;

  SpeedTunerOptions options_;
  int chosen_ = 0;
  double chosen_average_ = 0.0;
  int probe_interval_;
  int iterations_since_probe_ = 0;
  int probe_offset_ = 1;  // in [1, num_candidates - 1]
};

}  // namespace m2d

#endif  // MIMIC2D_RL_SPEED_TUNER_H_
