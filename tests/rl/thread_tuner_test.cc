// The LibTorch thread tuner against scripted iteration speeds.
#include "rl/thread_tuner.h"

#include <gtest/gtest.h>

#include <functional>

#include "common/error.h"

namespace m2d {
namespace {

// Runs `iterations` iterations in which `threads` threads take
// seconds_per_sample(threads); returns how many ran with each count.
struct Counts {
  int one = 0, two = 0;
};
Counts RunIterations(ThreadTuner& tuner, int iterations,
                     const std::function<double(int)>& seconds_per_sample) {
  Counts counts;
  for (int i = 0; i < iterations; ++i) {
    const int threads = tuner.ThreadsForNextIteration();
    (threads == 1 ? counts.one : counts.two)++;
    tuner.Record(threads, seconds_per_sample(threads));
  }
  return counts;
}

// Idle 2-core machine: 2 threads are 1.25x faster (bench train).
double Idle(int threads) { return threads == 2 ? 1.0 : 1.25; }
// Another process on one core: 2 threads collapse (measured 0.27x).
double Loaded(int threads) { return threads == 2 ? 3.7 : 1.05; }

TEST(ThreadTuner, StaysOnTheFasterCountAndSpacesOutLosingProbes) {
  ThreadTuner tuner{ThreadTunerOptions()};
  Counts counts = RunIterations(tuner, 1000, Idle);
  EXPECT_EQ(tuner.chosen_threads(), 2);
  // Probes after 4, 8, ..., 256, then every 320 iterations: 8 in 1000.
  EXPECT_EQ(counts.one, 8);
  EXPECT_EQ(tuner.probe_interval(), 320);
}

TEST(ThreadTuner, ACompetingProcessSwitchesToOneThreadAtOnceAndBack) {
  ThreadTuner tuner{ThreadTunerOptions()};
  RunIterations(tuner, 1000, Idle);
  ASSERT_EQ(tuner.probe_interval(), 320);
  // The load appears: the first slow iteration triggers a probe, which wins.
  Counts loaded = RunIterations(tuner, 3, Loaded);
  EXPECT_EQ(tuner.chosen_threads(), 1);
  EXPECT_EQ(loaded.two, 1);
  EXPECT_EQ(loaded.one, 2);
  // While loaded, losing probes of 2 threads are spaced out again: the
  // slow probes cost little.
  Counts steady = RunIterations(tuner, 1000, Loaded);
  EXPECT_EQ(tuner.chosen_threads(), 1);
  EXPECT_LE(steady.two, 8);
  // The load ends: the next probe finds 2 threads faster again.
  RunIterations(tuner, 400, Idle);
  EXPECT_EQ(tuner.chosen_threads(), 2);
}

TEST(ThreadTuner, NoiseWithinTheMarginDoesNotFlip) {
  ThreadTuner tuner{ThreadTunerOptions()};
  // Equal speeds, +-2 % noise: the 5 % margin keeps the first choice.
  int i = 0;
  RunIterations(tuner, 2000, [&](int) { return (++i % 2) ? 0.98 : 1.02; });
  EXPECT_EQ(tuner.chosen_threads(), 2);
}

TEST(ThreadTuner, InvalidOptionsAreRejected) {
  ThreadTunerOptions options;
  options.max_threads = 1;
  EXPECT_THROW(ThreadTuner{options}, ConfigError);
  options = ThreadTunerOptions();
  options.max_probe_interval = 2;  // below first_probe_after
  EXPECT_THROW(ThreadTuner{options}, ConfigError);
}

}  // namespace
}  // namespace m2d
