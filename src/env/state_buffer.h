// env: per-reference-frame initial-state buffers (Adaptive State
// Initialization). Each frame of a reference motion keeps up to `capacity`
// simulator states with a score; an episode starting at that frame draws one
// with probability proportional to exp(score / temperature). Training
// rescores states with the critic and inserts high-scoring visited states,
// so infeasible initial states are gradually replaced by feasible ones.
// A frame may also keep an anchor: the state it was first filled with (e.g.
// the fit's estimate), never replaced, drawn with a fixed probability so
// that training keeps practising the starts a user's rollout begins from.
#ifndef MIMIC2D_ENV_STATE_BUFFER_H_
#define MIMIC2D_ENV_STATE_BUFFER_H_

#include <random>
#include <vector>

#include "common/settings.h"
#include "sim/simulation.h"

namespace m2d {

struct StateBufferOptions {
  int capacity_per_frame = 4;  // states kept per reference frame
  double temperature = 1.0;    // of exp(score / T); in units of the score
  double anchor_share = 0.0;   // probability a draw returns the frame's anchor

  // Every setting (common/settings.h); spliced into a training config's
  // `asi` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("capacity_per_frame", self.capacity_per_frame, Range::Closed(1, 1024),
      "states kept per reference frame");
    v("temperature", self.temperature, Range::Above(0),
      "T of sampling proportional to exp(V / T), V in return units");
    v("anchor_share", self.anchor_share, Range::Closed(0, 1),
      "share of episodes started from the frame's first-filled state "
      "(never replaced by ASI)");
  }
  void Validate() const;  // throws ConfigError
};

struct ScoredState {
  SimState state;
  double score = 0.0;
};

// Not synchronized: concurrent Sample() calls are safe, but Insert/Rescore
// must not run while other threads sample (the trainer updates the buffer
// between rollouts).
class StateBuffer {
 public:
  StateBuffer(int num_frames, const StateBufferOptions& options);

  int num_frames() const { return static_cast<int>(entries_.size()); }
  const StateBufferOptions& options() const { return options_; }
  int size(int frame) const { return static_cast<int>(entries_[frame].size()); }
  const ScoredState& entry(int frame, int index) const {
    return entries_[frame][index];
  }

  // Adds a state; when the frame is full it replaces the lowest-scoring
  // entry, if `score` is higher. Returns whether the state was kept.
  bool Insert(int frame, const SimState& state, double score);
  void Rescore(int frame, int index, double score);

  // The index of `frame`'s highest-scoring entry; -1 when empty.
  int Best(int frame) const;

  // An entry index of `frame`, drawn with probability ∝ exp(score / T);
  // -1 when the frame is empty.
  int Sample(int frame, std::mt19937_64& rng) const;

  // The frame's anchor state, kept apart from the scored entries; nullptr
  // when the frame has none.
  void SetAnchor(int frame, const SimState& state);
  const SimState* anchor(int frame) const {
    return has_anchor_[frame] ? &anchors_[frame] : nullptr;
  }

  // An episode's initial state for `frame`: its anchor with probability
  // anchor_share (when it has one), otherwise a Sample()d entry. The frame
  // must have an anchor or an entry.
  const SimState& Draw(int frame, std::mt19937_64& rng) const;

 private:
  StateBufferOptions options_;
  std::vector<std::vector<ScoredState>> entries_;
  std::vector<SimState> anchors_;
  std::vector<bool> has_anchor_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_STATE_BUFFER_H_
