#include "env/state_buffer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

SimState StateWithTime(double time_s) {
  SimState state;
  state.time_s = time_s;
  return state;
}

TEST(StateBuffer, KeepsTheHighestScoresPerFrame) {
  StateBufferOptions options;
  options.capacity_per_frame = 2;
  StateBuffer buffer(3, options);
  EXPECT_EQ(buffer.Sample(1, *std::make_unique<std::mt19937_64>(1)), -1);
  EXPECT_TRUE(buffer.Insert(1, StateWithTime(1), 1.0));
  EXPECT_TRUE(buffer.Insert(1, StateWithTime(2), 3.0));
  EXPECT_FALSE(buffer.Insert(1, StateWithTime(3), 0.5));  // lower than both
  EXPECT_TRUE(buffer.Insert(1, StateWithTime(4), 2.0));   // replaces score 1
  ASSERT_EQ(buffer.size(1), 2);
  double times =
      buffer.entry(1, 0).state.time_s + buffer.entry(1, 1).state.time_s;
  EXPECT_DOUBLE_EQ(times, 6.0);
  EXPECT_EQ(buffer.size(0), 0);
}

TEST(StateBuffer, SamplesProportionalToExpScoreOverTemperature) {
  StateBufferOptions options;
  options.capacity_per_frame = 2;
  options.temperature = 0.5;
  StateBuffer buffer(1, options);
  buffer.Insert(0, StateWithTime(0), 0.0);
  buffer.Insert(0, StateWithTime(1), 1.0);
  std::mt19937_64 rng(9);
  int count_high = 0;
  const int draws = 20000;
  for (int i = 0; i < draws; ++i) count_high += buffer.Sample(0, rng) == 1;
  double expected = std::exp(2.0) / (1.0 + std::exp(2.0));  // exp(1/0.5)
  EXPECT_NEAR(static_cast<double>(count_high) / draws, expected, 0.01);
  buffer.Rescore(0, 1, -1.0);
  count_high = 0;
  for (int i = 0; i < draws; ++i) count_high += buffer.Sample(0, rng) == 1;
  EXPECT_NEAR(static_cast<double>(count_high) / draws,
              1.0 / (1.0 + std::exp(2.0)), 0.01);
}

TEST(StateBuffer, OptionsAreValidated) {
  StateBufferOptions options;
  options.capacity_per_frame = 0;
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
  options = StateBufferOptions();
  options.temperature = 0.0;
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
}

}  // namespace
}  // namespace m2d
