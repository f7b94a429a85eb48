// env: per-reference-frame initial-state buffers (Adaptive State
// Initialization). Each frame of a reference motion keeps up to `capacity`
// simulator states with a score; an episode starting at that frame draws one
// with probability proportional to exp(score / temperature). Training
// rescores states with the critic and inserts high-scoring visited states,
// so infeasible initial states are gradually replaced by feasible ones.
#ifndef MIMIC2D_ENV_STATE_BUFFER_H_
#define MIMIC2D_ENV_STATE_BUFFER_H_

#include <random>
#include <vector>

#include "sim/simulation.h"

namespace m2d {

struct StateBufferOptions {
  int capacity_per_frame = 4;  // states kept per reference frame
  double temperature = 1.0;    // of exp(score / T); in units of the score

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

 private:
  StateBufferOptions options_;
  std::vector<std::vector<ScoredState>> entries_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_STATE_BUFFER_H_
