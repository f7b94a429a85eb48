// rl: a trained policy loaded from a checkpoint, behind the torch-free
// Policy interface (deterministic: the Gaussian's mean). Accepts K >= 1
// view blocks per observation (zero-shot multi-view aggregation of phi).
#ifndef MIMIC2D_RL_TORCH_POLICY_H_
#define MIMIC2D_RL_TORCH_POLICY_H_

#include <memory>
#include <string>

#include "env/policy.h"
#include "rl/train_config.h"

namespace m2d {

class TorchPolicy : public Policy {
 public:
  // Loads the checkpoint at `path` (its embedded config rebuilds the
  // networks). `num_views`: view blocks per observation.
  explicit TorchPolicy(const std::string& path, int num_views = 1);
  ~TorchPolicy() override;

  void Act(const float* observations, int batch, float* actions) override;
  int observation_size() const override;
  int action_size() const override;
  const TrainConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_TORCH_POLICY_H_
