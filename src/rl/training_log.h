// rl: the training log, train_log.csv — one row per iteration, appended and
// flushed as it happens; on resume, rows past the checkpoint are dropped and
// rows of an older log are widened to the current columns.
#ifndef MIMIC2D_RL_TRAINING_LOG_H_
#define MIMIC2D_RL_TRAINING_LOG_H_

#include <cstdint>
#include <fstream>
#include <string>

namespace m2d {

// One row of the training log.
struct TrainProgress {
  int iteration = 0;
  int64_t samples = 0;
  double wall_time_s = 0.0;    // across resumed runs
  double samples_per_s = 0.0;  // end to end, this iteration
  double mean_return = 0.0;    // finished episodes of this iteration
  double mean_episode_length = 0.0;
  double succ = 0.0;    // fraction not ended by early exit
  double e2d_px = 0.0;  // mean 2D error of those episodes
  double policy_loss = 0.0, value_loss = 0.0, entropy = 0.0;
  double approx_kl = 0.0;      // PPO update: mean KL(old || new) estimate
  double clip_fraction = 0.0;  // and the share of clipped ratios
  double learning_rate = 0.0;
  double collect_s = 0.0, update_s = 0.0, asi_s = 0.0;  // time split
  int torch_threads = 1;  // LibTorch threads this iteration ran with
  bool bf16 = false;      // and whether its networks ran in bfloat16 (the
                          // log's 0/1: every cell of the log is a number)
  // Not in the log: the time left to total_samples at the recent rate (an
  // average over about 20 iterations, without those the process spent
  // stopped: one iteration's rate swings the estimate by 10-20 %).
  double eta_s = 0.0;
};

// What a resumed run may need from the log's last kept row (-1: absent).
struct LastLogRow {
  double wall_time_s = -1.0;
  double learning_rate = -1.0;
};

class TrainingLog {
 public:
  // A new log holding only the header (written atomically).
  static void Start(const std::string& path);
  // Keeps the rows up to `iteration` (a resumed run rewrites what came after
  // its checkpoint; rows torn by a kill mid-write are dropped), written
  // atomically; returns the last kept row.
  static LastLogRow TrimTo(const std::string& path, int iteration);

  // Opens `path` for appending; InputError when it cannot.
  explicit TrainingLog(const std::string& path);
  // Appends and flushes one row; InputError when it cannot be written (a
  // full disk), so training stops with the last checkpoint intact rather
  // than train on with rows silently missing.
  void Append(const TrainProgress& progress);

 private:
  std::string path_;
  std::ofstream out_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAINING_LOG_H_
