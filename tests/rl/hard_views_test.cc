// Hard-view sampling: a view's chance of failing a whole rollout from its
// training episodes' early exits, and start weights that favour the views
// that fail, forgetting old episodes with the configured half life.
#include "rl/hard_views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "common/error.h"
#include "env/env_fixture.h"
#include "env/task.h"

namespace m2d {
namespace {

TEST(HardViews, AConstantHazardGivesTheWholeRolloutsFailure) {
  EXPECT_LT(FullRolloutFailure({}, 100), 0.0);  // no steps: unknown
  EXPECT_DOUBLE_EQ(FullRolloutFailure({500.0, 0.0}, 100), 0.0);
  // One early exit per 100 steps over a 101-frame view: 1 - e^-1.
  EXPECT_NEAR(FullRolloutFailure({1000.0, 10.0}, 101), 1.0 - std::exp(-1.0),
              1e-12);
  // The longer the view, the likelier a rollout fails at the same rate.
  EXPECT_GT(FullRolloutFailure({1000.0, 10.0}, 300),
            FullRolloutFailure({1000.0, 10.0}, 30));
}

TEST(HardViews, WeightsAreUniformPlusAShareInProportionToFailure) {
  const std::vector<int> frames = {101, 101, 101};
  // Nothing known, or nothing fails: uniform.
  for (const auto& records :
       {std::vector<ViewFailureRecord>(3),
        std::vector<ViewFailureRecord>{{100, 0}, {100, 0}, {0, 0}}}) {
    for (double w : HardViewWeights(records, frames, 0.5)) {
      EXPECT_DOUBLE_EQ(w, 1.0 / 3.0);
    }
  }
  // View 0 never fails, view 1 does (p = 1 - e^-1), view 2 is unknown and
  // counts as the known mean (p / 2).
  const std::vector<ViewFailureRecord> records = {
      {1000, 0}, {1000, 10}, {0, 0}};
  const std::vector<double> weights = HardViewWeights(records, frames, 0.6);
  EXPECT_NEAR(std::accumulate(weights.begin(), weights.end(), 0.0), 1.0, 1e-12);
  EXPECT_NEAR(weights[0], 0.4 / 3.0, 1e-12);
  EXPECT_NEAR(weights[1], 0.4 / 3.0 + 0.6 * (2.0 / 3.0), 1e-12);
  EXPECT_NEAR(weights[2], 0.4 / 3.0 + 0.6 * (1.0 / 3.0), 1e-12);
  // Share 0: uniform whatever fails.
  for (double w : HardViewWeights(records, frames, 0.0)) {
    EXPECT_DOUBLE_EQ(w, 1.0 / 3.0);
  }
}

TEST(HardViews, HazardWeightsGiveFailingViewsEqualSamples) {
  EXPECT_LT(FailureHazard({}), 0.0);  // no steps: unknown
  EXPECT_DOUBLE_EQ(FailureHazard({1000.0, 10.0}), 0.01);
  // Views lost after 10 and after 200 steps, one never lost, one unknown
  // (at the known mean): over long views both failing ones are near 1 as
  // full-rollout chances, while by hazard the quick failure gets 20x the
  // starts, so both get the same samples (starts x steps per episode).
  const std::vector<int> frames = {2000, 2000, 2000, 2000};
  const std::vector<ViewFailureRecord> records = {
      {1000, 100}, {1000, 5}, {1000, 0}, {0, 0}};
  const std::vector<double> chance =
      HardViewWeights(records, frames, 1.0, HardViewMeasure::kFullRollout);
  EXPECT_NEAR(chance[0] / chance[1], 1.0, 1e-3);
  const std::vector<double> hazard =
      HardViewWeights(records, frames, 1.0, HardViewMeasure::kHazard);
  EXPECT_NEAR(std::accumulate(hazard.begin(), hazard.end(), 0.0), 1.0, 1e-12);
  EXPECT_NEAR(hazard[0] * 10.0, hazard[1] * 200.0, 1e-12);
  EXPECT_DOUBLE_EQ(hazard[2], 0.0);
  const double known_mean = (0.1 + 0.005 + 0.0) / 3.0;
  EXPECT_NEAR(hazard[3] / hazard[0], known_mean / 0.1, 1e-12);
}

TEST(HardViews, HazardSampleWeightsGiveFailingViewsSamplesInProportion) {
  EXPECT_LT(HazardPerEpisodeStep({}), 0.0);  // no episodes: unknown
  // Views lost after 10 and after 200 steps, one held (2 episodes to the
  // end, never lost): by hazard both failing views get the same samples;
  // by hazard over episode length the quick failure gets 20x the samples
  // (its hazard is 20x), so 400x the starts.
  const std::vector<int> frames = {2000, 2000, 2000};
  const std::vector<ViewFailureRecord> records = {
      {1000, 100, 100}, {1000, 5, 5}, {1000, 0, 2}};
  const std::vector<double> weights =
      HardViewWeights(records, frames, 1.0, HardViewMeasure::kHazardSamples);
  EXPECT_NEAR(std::accumulate(weights.begin(), weights.end(), 0.0), 1.0, 1e-12);
  const double samples_quick = weights[0] * 10.0;
  const double samples_slow = weights[1] * 200.0;
  EXPECT_NEAR(samples_quick / samples_slow, 0.1 / 0.005, 1e-9);
  EXPECT_DOUBLE_EQ(weights[2], 0.0);
  // A uniform part stays whatever the measure.
  const std::vector<double> shared =
      HardViewWeights(records, frames, 0.8, HardViewMeasure::kHazardSamples);
  EXPECT_NEAR(shared[2], 0.2 / 3.0, 1e-12);
}

TEST(HardViews, TheHazardSamplerListsViewsByStartWeight) {
  TrackingTask task = testing::MakeGlidingTask(/*num_views=*/2);
  HardViewSampler sampler(*task.reference, /*share=*/1.0,
                          /*half_life_samples=*/1000.0,
                          HardViewMeasure::kHazard);
  // Both views fail every episode, view 1 after 5 steps and view 0 after
  // 50: view 1 gets 10x view 0's starts and is listed first.
  auto failed_episode = [](int view, int steps) {
    FinishedEpisode finished;
    finished.stats.view_index = view;
    finished.stats.steps = steps;
    finished.stats.failed = true;
    return finished;
  };
  sampler.Record({failed_episode(1, 5), failed_episode(0, 50)}, 1000);
  const std::vector<double> weights = sampler.Weights();
  EXPECT_NEAR(weights[1], 10.0 / 11.0, 1e-12);
  EXPECT_NEAR(weights[0], 1.0 / 11.0, 1e-12);
  const std::string report = sampler.Report(2);
  EXPECT_NE(report.find("hardest: gliding view 1 1.00 (5 steps, w 0.909), "
                        "gliding view 0 0.45 (50 steps, w 0.091)"),
            std::string::npos)
      << report;
}

TEST(HardViews, TheSamplerFavoursFailingViewsAndForgets) {
  TrackingTask task = testing::MakeGlidingTask(/*num_views=*/2);
  HardViewSampler sampler(*task.reference, /*share=*/1.0,
                          /*half_life_samples=*/1000.0);
  EXPECT_EQ(sampler.Report(3), "no episodes yet");

  // View 0 fails every episode after 5 steps; view 1 tracks 29 steps.
  auto episode = [](int view, int steps, bool failed) {
    FinishedEpisode finished;
    finished.stats.view_index = view;
    finished.stats.steps = steps;
    finished.stats.failed = failed;
    return finished;
  };
  sampler.Record({episode(0, 5, true), episode(1, 29, false)}, 1000);
  std::vector<double> weights = sampler.Weights();
  EXPECT_DOUBLE_EQ(weights[0], 1.0);  // share 1: only the failing view
  EXPECT_DOUBLE_EQ(weights[1], 0.0);
  const std::string report = sampler.Report(1);
  EXPECT_NE(report.find("mean failure chance 0.50 over 2 of 2 views"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("hardest: gliding view 0 1.00 (5 steps, w 1.000)"),
            std::string::npos)
      << report;
  // Later the views swap; after many half lives the old records are gone.
  for (int i = 0; i < 40; ++i) {
    sampler.Record({episode(0, 29, false), episode(1, 5, true)}, 1000);
  }
  weights = sampler.Weights();
  EXPECT_LT(weights[0], 1e-6);
  EXPECT_GT(weights[1], 1.0 - 1e-6);
  // An episode of a view the reference has not: refused.
  EXPECT_THROW(sampler.Record({episode(2, 5, true)}, 1000), std::out_of_range);
  EXPECT_THROW(HardViewSampler(*task.reference, 1.5, 1000.0), ConfigError);
  EXPECT_THROW(HardViewSampler(*task.reference, 0.5, 0.0), ConfigError);
}

}  // namespace
}  // namespace m2d
