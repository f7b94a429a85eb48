// rl: picks LibTorch's thread count while training, from measured speed.
//
// Two threads make an iteration 1.25x faster on an idle 2-core machine, but
// 4-30x slower as soon as another process competes for a core: every
// parallel op waits for a descheduled thread (docs/training.md,
// "Throughput"). The tuner runs the chosen count and, now and then, one
// probe iteration with the other; the faster seconds per sample wins.
// Probes that lose are spaced out further (exponential backoff), so the
// probing costs little in either steady state; a sudden slowdown probes at
// once.
#ifndef MIMIC2D_RL_THREAD_TUNER_H_
#define MIMIC2D_RL_THREAD_TUNER_H_

namespace m2d {

struct ThreadTunerOptions {
  int max_threads = 2;           // the candidates are 1 and max_threads
  int first_probe_after = 4;     // iterations between probes, at first
  int max_probe_interval = 320;  // backoff cap (iterations)
  double switch_margin = 0.05;   // a probe must be this much faster (5 %)
  double average_weight = 0.2;   // EMA weight of each new measurement
  // An iteration this much slower than the average probes at once (a
  // competing process appeared: do not wait out a long backoff).
  double slowdown_factor = 1.5;

  void Validate() const;
};

class ThreadTuner {
 public:
  explicit ThreadTuner(const ThreadTunerOptions& options);

  // The thread count for the next iteration (a probe runs the other one).
  int ThreadsForNextIteration();
  // Reports the iteration's seconds per sample, measured with `threads`.
  // Returns true if the chosen count changed.
  bool Record(int threads, double seconds_per_sample);

  int chosen_threads() const { return chosen_threads_; }
  // Running average of the chosen count's seconds per sample (0: none yet).
  double chosen_seconds_per_sample() const { return chosen_average_; }
  int probe_interval() const { return probe_interval_; }

 private:
  int Other() const;

  ThreadTunerOptions options_;
  int chosen_threads_;
  double chosen_average_ = 0.0;
  int probe_interval_;
  int iterations_since_probe_ = 0;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_THREAD_TUNER_H_
