#include "rl/networks.h"

#include <ATen/autocast_mode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "common/error.h"

namespace m2d {

RunningNormalizerImpl::RunningNormalizerImpl(int size, double clip_std)
    : clip_std(clip_std) {
  mean = register_buffer("mean", torch::zeros({size}));
  variance = register_buffer("variance", torch::ones({size}));
  count = register_buffer("count", torch::full({1}, 1e-4));
}

void RunningNormalizerImpl::Update(const torch::Tensor& batch) {
  torch::NoGradGuard no_grad;
  torch::Tensor batch_mean = batch.mean(0);
  torch::Tensor batch_variance = batch.var(0, /*unbiased=*/false);
  double n = static_cast<double>(batch.size(0));
  torch::Tensor total = count + n;
  torch::Tensor delta = batch_mean - mean;
  torch::Tensor new_mean = mean + delta * (n / total);
  torch::Tensor m2 = variance * count + batch_variance * n +
                     delta.pow(2) * count * (n / total);
  mean.copy_(new_mean);
  variance.copy_(m2 / total);
  count.copy_(total);
}

torch::Tensor RunningNormalizerImpl::Normalize(const torch::Tensor& x) const {
  return ((x - mean) / torch::sqrt(variance + 1e-8)).clamp(-clip_std, clip_std);
}

torch::nn::Sequential MakeMlp(int input, const std::vector<int>& hidden,
                              int output, double last_layer_gain) {
  torch::nn::Sequential mlp;
  int width = input;
  for (int layer : hidden) {
    torch::nn::Linear linear(width, layer);
    torch::nn::init::orthogonal_(linear->weight, std::sqrt(2.0));
    torch::nn::init::zeros_(linear->bias);
    mlp->push_back(linear);
    mlp->push_back(torch::nn::ReLU());
    width = layer;
  }
  torch::nn::Linear last(width, output);
  torch::nn::init::orthogonal_(last->weight, last_layer_gain);
  torch::nn::init::zeros_(last->bias);
  mlp->push_back(last);
  return mlp;
}

ActorCriticImpl::ActorCriticImpl(const ObservationLayout& layout,
                                 const ModelOptions& options, int action_size)
    : layout_(layout),
      base_size_(layout.view_offset()),
      action_size_(action_size) {
  base_normalizer = register_module(
      "base_normalizer",
      RunningNormalizer(base_size_, options.observation_clip_std));
  view_normalizer = register_module(
      "view_normalizer",
      RunningNormalizer(layout.view_size(), options.observation_clip_std));
  // phi ends in a ReLU so that averaging over views mixes features of the
  // same kind (non-negative activations), as in the paper's aggregation.
  auto make_encoder = [&]() {
    torch::nn::Sequential encoder =
        MakeMlp(layout.view_size(), options.encoder_hidden,
                options.encoder_features, std::sqrt(2.0));
    encoder->push_back(torch::nn::ReLU());
    return encoder;
  };
  actor_encoder = register_module("actor_encoder", make_encoder());
  critic_encoder = register_module("critic_encoder", make_encoder());
  // The policy reads proprioception and object state; the critic also the
  // critic-only block when the layout has one (asymmetric actor-critic).
  actor = register_module(
      "actor", MakeMlp(layout.actor_base_size() + options.encoder_features,
                       options.policy_hidden, action_size, 0.01));
  critic =
      register_module("critic", MakeMlp(base_size_ + options.encoder_features,
                                        options.critic_hidden, 1, 1.0));
  log_std = register_parameter(
      "log_std", torch::full({action_size}, std::log(options.action_std)),
      /*requires_grad=*/options.learn_action_std);
}

torch::Tensor ActorCriticImpl::Normalize(const torch::Tensor& raw) const {
  const int64_t batch = raw.size(0);
  torch::Tensor base = base_normalizer->Normalize(raw.narrow(1, 0, base_size_));
  torch::Tensor views = raw.narrow(1, base_size_, raw.size(1) - base_size_)
                            .reshape({batch, -1, layout_.view_size()});
  views = view_normalizer->Normalize(views).reshape({batch, -1});
  return torch::cat({base, views}, 1);
}

void ActorCriticImpl::UpdateNormalizer(const torch::Tensor& raw) {
  base_normalizer->Update(raw.narrow(1, 0, base_size_));
  view_normalizer->Update(raw.narrow(1, base_size_, raw.size(1) - base_size_)
                              .reshape({-1, layout_.view_size()}));
}

torch::Tensor ActorCriticImpl::Features(torch::nn::Sequential& encoder,
                                        const torch::Tensor& obs, int num_views,
                                        int base_width) {
  const int64_t batch = obs.size(0);
  torch::Tensor views =
      obs.narrow(1, base_size_,
                 static_cast<int64_t>(num_views) * layout_.view_size())
          .reshape({batch * num_views, layout_.view_size()});
  torch::Tensor phi =
      encoder->forward(views).reshape({batch, num_views, -1}).mean(1);
  return torch::cat({obs.narrow(1, 0, base_width), phi}, 1);
}

torch::Tensor ActorCriticImpl::ActionMean(const torch::Tensor& obs,
                                          int num_views) {
  return actor->forward(
      Features(actor_encoder, obs, num_views, layout_.actor_base_size()));
}

torch::Tensor ActorCriticImpl::Value(const torch::Tensor& obs, int num_views) {
  return critic->forward(Features(critic_encoder, obs, num_views, base_size_))
      .squeeze(1);
}

torch::Tensor ActorCriticImpl::LogProb(const torch::Tensor& mean,
                                       const torch::Tensor& actions) const {
  torch::Tensor z = (actions - mean) * torch::exp(-log_std);
  return (-0.5 * z.pow(2) - log_std - 0.5 * std::log(2.0 * M_PI)).sum(1);
}

torch::Tensor ActorCriticImpl::Entropy() const {
  return (log_std + 0.5 * std::log(2.0 * M_PI * M_E)).sum();
}

void WidenFutureFrames(ActorCriticImpl& source, ActorCriticImpl& target) {
  const ObservationLayout& from = source.layout();
  const ObservationLayout& to = target.layout();
  if (from.num_bodies != to.num_bodies || from.num_objects != to.num_objects ||
      from.num_points != to.num_points ||
      from.critic_only_size != to.critic_only_size ||
      source.action_size() != target.action_size() ||
      from.num_future_frames >= to.num_future_frames) {
    throw ConfigError(
        "widening the future frames: the source's observation differs in "
        "more than a shorter horizon (" +
        std::to_string(from.num_future_frames) + " future frames against " +
        std::to_string(to.num_future_frames) + ")");
  }
  // Outline: the view block is frame-major (the current projection, then
  // future frames 1..L, each num_points x kPointFeatures wide), so the
  // source's columns are the first ones of the target's.
  const int64_t frame_width =
      from.num_points * ObservationLayout::kPointFeatures;
  const int64_t kept = from.view_size();
  torch::NoGradGuard no_grad;
  const auto source_tensor =
      [](const torch::OrderedDict<std::string, torch::Tensor>& tensors,
         const std::string& key) -> const torch::Tensor& {
    const torch::Tensor* found = tensors.find(key);
    if (found == nullptr) {
      throw ConfigError("widening the future frames: the source has no " + key);
    }
    return *found;
  };
  const auto source_parameters = source.named_parameters();
  for (auto& named : target.named_parameters()) {
    const torch::Tensor& from_tensor =
        source_tensor(source_parameters, named.key());
    torch::Tensor& to_tensor = named.value();
    if (from_tensor.sizes() == to_tensor.sizes()) {
      to_tensor.copy_(from_tensor);
    } else if ((named.key() == "actor_encoder.0.weight" ||
                named.key() == "critic_encoder.0.weight") &&
               from_tensor.size(0) == to_tensor.size(0) &&
               from_tensor.size(1) == kept) {
      // The encoders' first layers: the new frames' columns start at zero.
      to_tensor.zero_();
      to_tensor.narrow(1, 0, kept).copy_(from_tensor);
    } else {
      throw ConfigError("widening the future frames: " + named.key() +
                        " differs in shape (model.*_hidden or "
                        "encoder_features changed)");
    }
  }
  const auto source_buffers = source.named_buffers();
  for (auto& named : target.named_buffers()) {
    const torch::Tensor& from_tensor =
        source_tensor(source_buffers, named.key());
    torch::Tensor& to_tensor = named.value();
    if (from_tensor.sizes() == to_tensor.sizes()) {
      to_tensor.copy_(from_tensor);
      continue;
    }
    // The view normalizer's mean and variance: the source's, then its last
    // future frame's repeated over the new frames.
    if ((named.key() != "view_normalizer.mean" &&
         named.key() != "view_normalizer.variance") ||
        from_tensor.size(0) != kept) {
      throw ConfigError("widening the future frames: " + named.key() +
                        " differs in shape");
    }
    to_tensor.narrow(0, 0, kept).copy_(from_tensor);
    const torch::Tensor last_frame =
        from_tensor.narrow(0, kept - frame_width, frame_width);
    for (int64_t column = kept; column < to_tensor.size(0);
         column += frame_width) {
      to_tensor.narrow(0, column, frame_width).copy_(last_frame);
    }
  }
}

namespace {

// Seconds of the fastest of `repeats` forward + backward passes of an MLP
// with the default policy's hidden layers, 600 inputs (the order of the
// observation) and the humanoid's 28 actions, on a 1024-row minibatch, in
// `precision`. The tensors are filled without the random generator, so
// probing leaves a seeded run's draws untouched.
double TimeMlpStep(TrainingPrecision precision, int repeats) {
  std::vector<int64_t> sizes = {600};
  for (int width : ModelOptions().policy_hidden) sizes.push_back(width);
  sizes.push_back(28);
  std::vector<torch::Tensor> weights;
  for (size_t i = 0; i + 1 < sizes.size(); ++i) {
    weights.push_back(
        torch::full({sizes[i + 1], sizes[i]}, 0.01).requires_grad_(true));
  }
  const torch::Tensor input =
      torch::linspace(-1.0, 1.0, 1024 * sizes[0]).reshape({1024, sizes[0]});
  double best_s = INFINITY;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    {
      PrecisionScope scope(precision);
      torch::Tensor x = input;
      for (size_t i = 0; i < weights.size(); ++i) {
        x = torch::linear(x, weights[i]);
        if (i + 1 < weights.size()) x = torch::relu(x);
      }
      x.to(torch::kFloat).sum().backward();
    }
    best_s = std::min(best_s, std::chrono::duration<double>(
                                  std::chrono::steady_clock::now() - start)
                                  .count());
    for (torch::Tensor& w : weights) w.mutable_grad() = torch::Tensor();
  }
  return best_s;
}

}  // namespace

const Bf16Support& ProbeBf16() {
  // Once per process, on the LibTorch threads of the first caller (the
  // trainer resolves before it collects).
  static const Bf16Support support = MeasureBf16Support(TimeMlpStep);
  return support;
}

PrecisionScope::PrecisionScope(TrainingPrecision precision)
    : bf16_(ResolvePrecision(precision) == TrainingPrecision::kBf16 &&
            !at::autocast::is_cpu_enabled()) {
  if (!bf16_) return;
  at::autocast::set_autocast_cpu_dtype(at::kBFloat16);
  at::autocast::set_cpu_enabled(true);
}

PrecisionScope::~PrecisionScope() {
  if (!bf16_) return;
  at::autocast::set_cpu_enabled(false);
  at::autocast::clear_cache();
}

void ForwardInPrecision(ActorCritic& model, const torch::Tensor& obs,
                        TrainingPrecision precision, torch::Tensor* mean,
                        torch::Tensor* value) {
  // Under bf16 the mean is the rounded network's: exact for the first
  // minibatch's ratios, noisy after (a weight step of Adam's size moves a
  // weight's bfloat16 copy by a whole rounding step or not at all; about
  // KL 0.004 of noise at sigma 0.05). A float32 mean with a bfloat16
  // gradient removed it and cost 15 % of the samples/s, with no gain in
  // samples to learn the walk in one timed run (docs/training.md,
  // "Throughput", item 5).
  PrecisionScope scope(precision);
  *mean = model->ActionMean(obs).to(torch::kFloat);
  *value = model->Value(obs).to(torch::kFloat);
}

}  // namespace m2d
