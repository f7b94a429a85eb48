#include "env/state_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

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

TEST(StateBuffer, AnchorIsDrawnAtItsShareAndNeverReplaced) {
  StateBufferOptions options;
  options.capacity_per_frame = 1;
  options.anchor_share = 0.25;
  StateBuffer buffer(2, options);
  buffer.SetAnchor(0, StateWithTime(-1));
  std::mt19937_64 rng(3);
  // With no entries yet, the anchor is the only start.
  EXPECT_EQ(buffer.Draw(0, rng).time_s, -1);
  EXPECT_THROW(buffer.Draw(1, rng), std::logic_error);  // nothing at all
  // A visited state fills the one slot; replacing it leaves the anchor.
  buffer.Insert(0, StateWithTime(5), 1.0);
  buffer.Insert(0, StateWithTime(6), 2.0);
  ASSERT_EQ(buffer.size(0), 1);
  EXPECT_EQ(buffer.entry(0, 0).state.time_s, 6);
  ASSERT_NE(buffer.anchor(0), nullptr);
  EXPECT_EQ(buffer.anchor(0)->time_s, -1);
  EXPECT_EQ(buffer.anchor(1), nullptr);
  int count_anchor = 0;
  const int draws = 20000;
  for (int i = 0; i < draws; ++i)
    count_anchor += buffer.Draw(0, rng).time_s < 0;
  EXPECT_NEAR(static_cast<double>(count_anchor) / draws, 0.25, 0.01);
}

TEST(StateBuffer, OptionsAreValidated) {
  StateBufferOptions options;
  options.capacity_per_frame = 0;
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
  options = StateBufferOptions();
  options.temperature = 0.0;
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
  options = StateBufferOptions();
  options.anchor_share = 1.5;
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
  options.anchor_share = std::nan("");
  EXPECT_THROW(StateBuffer(1, options), ConfigError);
}

}  // namespace
}  // namespace m2d
