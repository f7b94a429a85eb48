#include "rl/hard_views.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/error.h"

namespace m2d {

double FailureHazard(const ViewFailureRecord& record) {
  if (record.steps <= 0.0) return -1.0;
  return record.failures / record.steps;
}

double FullRolloutFailure(const ViewFailureRecord& record, int num_frames) {
  const double hazard_per_step = FailureHazard(record);
  if (hazard_per_step < 0.0) return -1.0;
  return 1.0 - std::exp(-hazard_per_step * std::max(num_frames - 1, 1));
}

double HazardPerEpisodeStep(const ViewFailureRecord& record) {
  if (record.steps <= 0.0 || record.episodes <= 0.0) return -1.0;
  return FailureHazard(record) * record.episodes / record.steps;
}

namespace {

// A view's value of `measure`; negative when unknown (no episodes yet).
double StartMeasure(const ViewFailureRecord& record, int num_frames,
                    HardViewMeasure measure) {
  switch (measure) {
    case HardViewMeasure::kFullRollout:
      return FullRolloutFailure(record, num_frames);
    case HardViewMeasure::kHazard:
      return FailureHazard(record);
    case HardViewMeasure::kHazardSamples:
      return HazardPerEpisodeStep(record);
  }
  return -1.0;
}

// Each view's `measure` (negative: no episodes yet), and how many
// views have episodes, with the mean of their chances.
struct FailureChances {
  std::vector<double> per_view;
  int known = 0;
  double known_mean = 0.0;
};

FailureChances ChancesOf(const std::vector<ViewFailureRecord>& records,
                         const std::vector<int>& num_frames,
                         HardViewMeasure measure) {
  FailureChances chances;
  double known_sum = 0.0;
  for (size_t v = 0; v < records.size(); ++v) {
    chances.per_view.push_back(
        StartMeasure(records[v], num_frames[v], measure));
    if (chances.per_view.back() < 0.0) continue;
    known_sum += chances.per_view.back();
    ++chances.known;
  }
  if (chances.known > 0) chances.known_mean = known_sum / chances.known;
  return chances;
}

}  // namespace

std::vector<double> HardViewWeights(
    const std::vector<ViewFailureRecord>& records,
    const std::vector<int>& num_frames, double share, HardViewMeasure measure) {
  // Outline: each view's measure (unknown ones at the known mean), then the
  // uniform part plus the share in proportion to them.
  const size_t num_views = records.size();
  std::vector<double> weights(num_views, 1.0 / num_views);
  FailureChances chances = ChancesOf(records, num_frames, measure);
  if (chances.known == 0 || chances.known_mean <= 0.0) return weights;
  for (double& f : chances.per_view) {
    if (f < 0.0) f = chances.known_mean;
  }
  const double total =
      std::accumulate(chances.per_view.begin(), chances.per_view.end(), 0.0);
  for (size_t v = 0; v < num_views; ++v) {
    weights[v] =
        (1.0 - share) / num_views + share * chances.per_view[v] / total;
  }
  return weights;
}

HardViewSampler::HardViewSampler(const TrackingReference& reference,
                                 double share, double half_life_samples,
                                 HardViewMeasure measure)
    : share_(share), half_life_samples_(half_life_samples), measure_(measure) {
  if (!(share >= 0.0 && share <= 1.0) || !(half_life_samples > 0.0)) {
    throw ConfigError(fmt::format(
        "hard views: share {} (0..1) and half life {} samples (> 0)", share,
        half_life_samples));
  }
  for (const TrackedView& view : reference.views()) {
    const std::string& bundle = reference.bundles()[view.bundle].name;
    view_names_.push_back(fmt::format("{} view {}", bundle, view.view));
    num_frames_.push_back(view.num_frames);
  }
  records_.resize(view_names_.size());
}

void HardViewSampler::Record(const std::vector<FinishedEpisode>& finished,
                             int64_t batch_samples) {
  const double keep = std::exp2(-batch_samples / half_life_samples_);
  for (ViewFailureRecord& record : records_) {
    record.steps *= keep;
    record.failures *= keep;
    record.episodes *= keep;
  }
  for (const FinishedEpisode& episode : finished) {
    ViewFailureRecord& record = records_.at(episode.stats.view_index);
    record.steps += episode.stats.steps;
    record.failures += episode.stats.failed ? 1.0 : 0.0;
    record.episodes += 1.0;
  }
}

std::vector<double> HardViewSampler::Weights() const {
  return HardViewWeights(records_, num_frames_, share_, measure_);
}

std::string HardViewSampler::Report(int count) const {
  const FailureChances chances =
      ChancesOf(records_, num_frames_, HardViewMeasure::kFullRollout);
  if (chances.known == 0) return "no episodes yet";
  const std::vector<double>& failure = chances.per_view;
  const std::vector<double> weights = Weights();
  std::vector<int> order(records_.size());
  std::iota(order.begin(), order.end(), 0);
  // Hardest first by start weight (the configured measure's order; under
  // kHazard the chances of long views all round to 1), then by chance.
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return failure[a] > failure[b]; });
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return weights[a] > weights[b]; });
  std::string report =
      fmt::format("mean failure chance {:.2f} over {} of {} views; hardest:",
                  chances.known_mean, chances.known, failure.size());
  int listed = 0;
  for (int v : order) {
    if (listed == count) break;
    if (failure[v] < 0.0) continue;  // no episodes yet
    const ViewFailureRecord& record = records_[v];
    const double steps_per_episode =
        record.episodes > 0.0 ? record.steps / record.episodes : 0.0;
    report += fmt::format("{} {} {:.2f} ({:.0f} steps, w {:.3f})",
                          listed == 0 ? "" : ",", view_names_[v], failure[v],
                          steps_per_episode, weights[v]);
    ++listed;
  }
  return report;
}

}  // namespace m2d
