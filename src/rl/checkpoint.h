// rl: checkpoints — the model, optimizer, counters, ASI state buffers and
// the resolved config in one LibTorch archive, written atomically.
#ifndef MIMIC2D_RL_CHECKPOINT_H_
#define MIMIC2D_RL_CHECKPOINT_H_

#include <torch/torch.h>

#include <string>
#include <vector>

#include "env/reference.h"
#include "rl/networks.h"
#include "rl/train_config.h"

namespace m2d {

struct CheckpointCounters {
  int iteration = 0;
  int64_t samples = 0;
  double wall_time_s = 0.0;
  // Adam's rate when saved (0: not recorded; checkpoints before it was).
  // LibTorch 1.13's Optimizer::load drops the saved parameter-group options,
  // so LoadCheckpoint restores the rate itself.
  double learning_rate = 0.0;
};

// Writes to a temporary file next to `path` and renames it over `path`.
void SaveCheckpoint(const std::string& path, const TrainConfig& config,
                    ActorCritic& model, torch::optim::Optimizer& optimizer,
                    const CheckpointCounters& counters,
                    const InitialStates* initial_states,
                    const SimState& state_template);

// The config embedded in a checkpoint; InputError naming the file if it is
// not a mimic2d checkpoint.
TrainConfig ReadCheckpointConfig(const std::string& path);

// The observation layout and action size the checkpoint's networks take.
ObservationLayout ReadCheckpointLayout(const std::string& path,
                                       int* action_size);

// Loads what SaveCheckpoint wrote into objects built from the same config.
// `optimizer` and `initial_states` may be null (evaluation).
CheckpointCounters LoadCheckpoint(const std::string& path, ActorCritic& model,
                                  torch::optim::Optimizer* optimizer,
                                  InitialStates* initial_states,
                                  const SimState& state_template);

// Restores only the ASI buffers of `path` into `initial_states` (a task
// built with the checkpoint's sources on the same reference): episodes then
// start from the states training refined. InputError when the checkpoint
// has none or they belong to another task.
void LoadCheckpointStateBuffers(const std::string& path,
                                InitialStates* initial_states,
                                const SimState& state_template);

// What WriteSlimCheckpoint kept.
struct SlimCheckpointSummary {
  int64_t bytes_before = 0;
  int64_t bytes_after = 0;
  int64_t samples = 0;  // the run's counters, unchanged
};

// Writes `in` without its ASI state buffers to `out` (atomically; `out` may
// be `in`): the networks, optimizer, counters and config, which is all that
// evaluation, `generate --policy` and `run.init_from` read. A run resumed
// from it refills its buffers from the reference, as a fresh run does.
// Buffers grow with views x frames (133 MB for 24 views of 20 s), too big to
// commit or carry a policy with. InputError naming the file when `in` is
// not a mimic2d checkpoint.
SlimCheckpointSummary WriteSlimCheckpoint(const std::string& in,
                                          const std::string& out);

// What AverageCheckpoints made.
struct AveragedCheckpointSummary {
  int num_averaged = 0;
  int64_t first_samples = 0;  // the inputs' fewest and most samples
  int64_t last_samples = 0;
};

// Writes to `out` (atomically) the element-wise mean of the networks and
// observation normalizers of `inputs`, checkpoints of one line (the same
// config's networks and layout): a policy averaged over the line's recent
// checkpoints, whose figures swing from one checkpoint to the next
// (docs/training.md, "Averaging a line's checkpoints"). The optimizer,
// counters and config are the newest input's (most samples); no ASI buffers are
// kept (as `slim`). The inputs may come in any order. InputError naming the
// file when an input is not a checkpoint or its networks or layout differ from
// the newest's; ConfigError for fewer than 2 inputs.
AveragedCheckpointSummary AverageCheckpoints(
    const std::vector<std::string>& inputs, const std::string& out);

// What a checkpoint holds, read without building its task or networks
// (`mimic2d checkpoint info`).
struct CheckpointInfo {
  int64_t bytes = 0;
  CheckpointCounters counters;
  TrainConfig config;  // the embedded one
  ObservationLayout layout;
  int action_size = 0;
  int num_state_buffers = 0;        // ASI buffers saved; 0: slim or ASI off
  int64_t num_buffered_states = 0;  // states over all of them
};
// InputError naming the file when it is not a mimic2d checkpoint.
CheckpointInfo ReadCheckpointInfo(const std::string& path);

}  // namespace m2d

#endif  // MIMIC2D_RL_CHECKPOINT_H_
