#include "rl/torch_policy.h"

#include <cstring>

#include "rl/checkpoint.h"
#include "rl/networks.h"

namespace m2d {

struct TorchPolicy::Impl {
  TrainConfig config;
  ActorCritic model{nullptr};
  int num_views = 1;
  int observation_size = 0;
  int action_size = 0;
};

TorchPolicy::TorchPolicy(const std::string& path, int num_views)
    : impl_(new Impl) {
  impl_->config = ReadCheckpointConfig(path);
  impl_->num_views = num_views;
  const TrainConfig& config = impl_->config;
  ObservationLayout layout = ReadCheckpointLayout(path, &impl_->action_size);
  impl_->model = ActorCritic(layout, config.model, impl_->action_size);
  // The state template only sizes ASI entries, which a policy does not load.
  LoadCheckpoint(path, impl_->model, nullptr, nullptr, SimState());
  impl_->model->eval();
  impl_->observation_size =
      layout.view_offset() + num_views * layout.view_size();
}

TorchPolicy::~TorchPolicy() = default;

void TorchPolicy::Act(const float* observations, int batch, float* actions) {
  torch::NoGradGuard no_grad;
  torch::Tensor raw = torch::from_blob(const_cast<float*>(observations),
                                       {batch, impl_->observation_size});
  torch::Tensor obs = impl_->config.ppo.normalize_observations
                          ? impl_->model->Normalize(raw)
                          : raw;
  torch::Tensor mean =
      impl_->model->ActionMean(obs, impl_->num_views).contiguous();
  std::memcpy(actions, mean.data_ptr<float>(),
              sizeof(float) * batch * impl_->action_size);
}

int TorchPolicy::observation_size() const { return impl_->observation_size; }
int TorchPolicy::action_size() const { return impl_->action_size; }
const TrainConfig& TorchPolicy::config() const { return impl_->config; }

}  // namespace m2d
