#include "env/state_buffer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/error.h"

namespace m2d {

void StateBufferOptions::Validate() const { CheckRanges(*this, "asi"); }

StateBuffer::StateBuffer(int num_frames, const StateBufferOptions& options)
    : options_(options),
      entries_(num_frames),
      anchors_(num_frames),
      has_anchor_(num_frames, false) {
  options_.Validate();
}

bool StateBuffer::Insert(int frame, const SimState& state, double score) {
  std::vector<ScoredState>& slot = entries_[frame];
  if (static_cast<int>(slot.size()) < options_.capacity_per_frame) {
    slot.push_back({state, score});
    return true;
  }
  auto lowest = std::min_element(
      slot.begin(), slot.end(), [](const ScoredState& a, const ScoredState& b) {
        return a.score < b.score;
      });
  if (score <= lowest->score) return false;
  *lowest = {state, score};
  return true;
}

void StateBuffer::Rescore(int frame, int index, double score) {
  entries_[frame][index].score = score;
}

int StateBuffer::Best(int frame) const {
  const std::vector<ScoredState>& slot = entries_[frame];
  int best = slot.empty() ? -1 : 0;
  for (int i = 1; i < static_cast<int>(slot.size()); ++i) {
    if (slot[i].score > slot[best].score) best = i;
  }
  return best;
}

int StateBuffer::Sample(int frame, std::mt19937_64& rng) const {
  const std::vector<ScoredState>& slot = entries_[frame];
  if (slot.empty()) return -1;
  if (slot.size() == 1) return 0;
  // Softmax over scores, shifted by the maximum for numerical safety.
  double best = slot[0].score;
  for (const ScoredState& entry : slot) best = std::max(best, entry.score);
  double weights[64];
  std::vector<double> heap_weights;
  double* w = weights;
  if (slot.size() > 64) {
    heap_weights.resize(slot.size());
    w = heap_weights.data();
  }
  double total = 0.0;
  for (size_t i = 0; i < slot.size(); ++i) {
    w[i] = std::exp((slot[i].score - best) / options_.temperature);
    total += w[i];
  }
  double draw = std::uniform_real_distribution<double>(0.0, total)(rng);
  for (size_t i = 0; i < slot.size(); ++i) {
    draw -= w[i];
    if (draw <= 0.0) return static_cast<int>(i);
  }
  return static_cast<int>(slot.size()) - 1;
}

void StateBuffer::SetAnchor(int frame, const SimState& state) {
  anchors_[frame] = state;
  has_anchor_[frame] = true;
}

const SimState& StateBuffer::Draw(int frame, std::mt19937_64& rng) const {
  const bool use_anchor =
      has_anchor_[frame] &&
      (entries_[frame].empty() || (options_.anchor_share > 0 &&
                                   std::uniform_real_distribution<double>(
                                       0.0, 1.0)(rng) < options_.anchor_share));
  if (use_anchor) return anchors_[frame];
  int index = Sample(frame, rng);
  if (index < 0) {
    throw std::logic_error("state buffer: frame " + std::to_string(frame) +
                           " has no initial state");
  }
  return entries_[frame][index].state;
}

}  // namespace m2d
