#include "gen/vqvae.h"

#include <cmath>

namespace m2d {
namespace F = torch::nn::functional;

torch::Tensor AbsoluteFromCanonical(const torch::Tensor& features,
                                    int num_keypoints) {
  const int64_t batch = features.size(0), frames = features.size(1);
  const int64_t pose_size = 2 * num_keypoints;
  torch::Tensor local = features.narrow(2, 0, pose_size)
                            .reshape({batch, frames, num_keypoints, 2});
  torch::Tensor delta_root = features.narrow(2, pose_size, 2);
  torch::Tensor delta_log_scale = features.select(2, pose_size + 2);
  // s_t = s_{t-1} exp(δs_t), then root_t = root_{t-1} + s_t δroot_t.
  torch::Tensor scale = delta_log_scale.cumsum(1).exp();  // [B, T]
  torch::Tensor root =
      (delta_root * scale.unsqueeze(2)).cumsum(1);  // [B, T, 2]
  return root.unsqueeze(2) + scale.unsqueeze(2).unsqueeze(3) * local;
}

ResidualStackImpl::ResidualStackImpl(int width, int depth) {
  int dilation = 1;
  for (int i = 1; i < depth; ++i) dilation *= 3;
  for (int i = 0; i < depth; ++i, dilation /= 3) {
    dilated_.push_back(register_module(
        "dilated" + std::to_string(i),
        torch::nn::Conv1d(torch::nn::Conv1dOptions(width, width, 3)
                              .dilation(dilation)
                              .padding(dilation))));
    pointwise_.push_back(register_module(
        "pointwise" + std::to_string(i),
        torch::nn::Conv1d(torch::nn::Conv1dOptions(width, width, 1))));
  }
}

torch::Tensor ResidualStackImpl::forward(torch::Tensor x) {
  for (size_t i = 0; i < dilated_.size(); ++i)
    x = x + pointwise_[i]->forward(
                torch::relu(dilated_[i]->forward(torch::relu(x))));
  return x;
}

CodebookImpl::CodebookImpl(int num_codes, int code_size, double ema_decay)
    : num_codes_(num_codes), ema_decay_(ema_decay) {
  codes_ = register_buffer("codes", torch::zeros({num_codes, code_size}));
  ema_count_ = register_buffer("ema_count", torch::ones({num_codes}));
  ema_sum_ = register_buffer("ema_sum", torch::zeros({num_codes, code_size}));
  seeded_ = register_buffer("seeded", torch::zeros({1}));
}

torch::Tensor CodebookImpl::Nearest(const torch::Tensor& z) const {
  torch::NoGradGuard no_grad;
  // |z - c|^2 = |z|^2 - 2 z·c + |c|^2; |z|^2 does not change the argmin.
  torch::Tensor distances =
      codes_.pow(2).sum(1).unsqueeze(0) - 2.0 * z.matmul(codes_.t());
  return distances.argmin(1);
}

torch::Tensor CodebookImpl::Lookup(const torch::Tensor& indices) const {
  return torch::embedding(codes_, indices);
}

CodebookStats CodebookImpl::Update(const torch::Tensor& z,
                                   torch::Generator& generator) {
  torch::NoGradGuard no_grad;
  const int64_t rows = z.size(0);
  // A random vector of the batch per code: seeds and replacements.
  auto random_rows = [&] {
    return z.index_select(
        0, torch::randint(rows, {num_codes_}, generator, torch::kLong));
  };
  CodebookStats stats;
  if (seeded_.item<float>() == 0.0f) {
    codes_.copy_(random_rows());
    ema_sum_.copy_(codes_);
    ema_count_.fill_(1.0);
    seeded_.fill_(1.0);
  }
  torch::Tensor assigned = Nearest(z);
  torch::Tensor counts =
      torch::zeros({num_codes_}).index_add_(0, assigned, torch::ones({rows}));
  torch::Tensor sums = torch::zeros_like(ema_sum_).index_add_(0, assigned, z);
  ema_count_.mul_(ema_decay_).add_(counts, 1.0 - ema_decay_);
  ema_sum_.mul_(ema_decay_).add_(sums, 1.0 - ema_decay_);
  torch::Tensor alive = (ema_count_ >= 1.0).unsqueeze(1);
  torch::Tensor means = ema_sum_ / ema_count_.clamp_min(1e-5).unsqueeze(1);
  // A reset code restarts its averages at its new vector with a count of
  // 1 (Jukebox's reset): it stays while at least about one vector a step
  // chooses it. Keeping the faded averages (T2M-GPT) needs ~100 vectors in
  // one batch to revive a code (0.99 c + 0.01 n >= 1), so a dead code was
  // re-drawn every step: about 270 of 512 codes, batch after batch.
  torch::Tensor replacements = random_rows();
  codes_.copy_(torch::where(alive, means, replacements));
  ema_sum_.copy_(torch::where(alive, ema_sum_, replacements));
  ema_count_.copy_(
      torch::where(alive.squeeze(1), ema_count_, torch::ones_like(ema_count_)));

  torch::Tensor share = counts / static_cast<double>(rows);
  stats.perplexity =
      std::exp(-(share * (share + 1e-10).log()).sum().item<double>());
  stats.used_codes = (counts > 0).sum().item<int>();
  stats.reset_codes = num_codes_ - alive.sum().item<int>();
  return stats;
}

VqVaeImpl::VqVaeImpl(int frame_size, const VqVaeOptions& options)
    : frame_size_(frame_size), options_(options) {
  const int width = options.width;
  auto conv = [](int in, int out, int kernel, int stride, int padding) {
    return torch::nn::Conv1d(torch::nn::Conv1dOptions(in, out, kernel)
                                 .stride(stride)
                                 .padding(padding));
  };
  // Encoder: lift, then per level a strided convolution (halves time) and
  // residual blocks, then project to the code size.
  encoder_in_ = register_module("encoder_in", conv(frame_size, width, 3, 1, 1));
  for (int level = 0; level < options.down_levels; ++level) {
    const std::string name = std::to_string(level);
    encoder_down_.push_back(
        register_module("encoder_down" + name, conv(width, width, 4, 2, 1)));
    encoder_blocks_.push_back(register_module(
        "encoder_blocks" + name, ResidualStack(width, options.residual_depth)));
  }
  encoder_out_ =
      register_module("encoder_out", conv(width, options.code_size, 3, 1, 1));
  // Decoder: the mirror image, nearest-neighbour upsampling per level.
  decoder_in_ =
      register_module("decoder_in", conv(options.code_size, width, 3, 1, 1));
  for (int level = 0; level < options.down_levels; ++level) {
    const std::string name = std::to_string(level);
    decoder_blocks_.push_back(register_module(
        "decoder_blocks" + name, ResidualStack(width, options.residual_depth)));
    decoder_up_.push_back(
        register_module("decoder_up" + name, conv(width, width, 3, 1, 1)));
  }
  decoder_hidden_ =
      register_module("decoder_hidden", conv(width, width, 3, 1, 1));
  decoder_out_ =
      register_module("decoder_out", conv(width, frame_size, 3, 1, 1));
  codebook_ = register_module(
      "codebook",
      Codebook(options.num_codes, options.code_size, options.ema_decay));
}

torch::Tensor VqVaeImpl::EncodeLatents(const torch::Tensor& x) {
  torch::Tensor h = torch::relu(encoder_in_->forward(x.transpose(1, 2)));
  for (size_t level = 0; level < encoder_down_.size(); ++level)
    h = encoder_blocks_[level]->forward(encoder_down_[level]->forward(h));
  return encoder_out_->forward(h).transpose(1, 2);  // [B, N, D]
}

torch::Tensor VqVaeImpl::DecodeLatents(const torch::Tensor& q) {
  torch::Tensor h = torch::relu(decoder_in_->forward(q.transpose(1, 2)));
  for (size_t level = 0; level < decoder_blocks_.size(); ++level) {
    h = decoder_blocks_[level]->forward(h);
    h = F::interpolate(h, F::InterpolateFuncOptions()
                              .scale_factor(std::vector<double>{2.0})
                              .mode(torch::kNearest));
    h = decoder_up_[level]->forward(h);
  }
  h = torch::relu(decoder_hidden_->forward(h));
  return decoder_out_->forward(h).transpose(1, 2);  // [B, T, C]
}

VqVaeImpl::Output VqVaeImpl::Forward(const torch::Tensor& x,
                                     torch::Generator* training) {
  Output out;
  torch::Tensor z = EncodeLatents(x);  // [B, N, D]
  const int64_t batch = z.size(0), tokens = z.size(1);
  torch::Tensor flat = z.reshape({batch * tokens, -1});
  if (training != nullptr)
    out.stats = codebook_->Update(flat.detach(), *training);
  torch::Tensor indices = codebook_->Nearest(flat.detach());
  torch::Tensor q = codebook_->Lookup(indices).reshape(z.sizes());
  out.commit_loss = (z - q.detach()).pow(2).mean();
  // Straight-through: the decoder sees q, the encoder gets its gradient.
  out.reconstruction = DecodeLatents(z + (q - z).detach());
  out.tokens = indices.reshape({batch, tokens});
  return out;
}

torch::Tensor VqVaeImpl::Encode(const torch::Tensor& x) {
  torch::NoGradGuard no_grad;
  torch::Tensor z = EncodeLatents(x);
  return codebook_->Nearest(z.reshape({-1, z.size(2)}))
      .reshape({z.size(0), z.size(1)});
}

torch::Tensor VqVaeImpl::Decode(const torch::Tensor& tokens) {
  torch::NoGradGuard no_grad;
  return DecodeLatents(codebook_->Lookup(tokens));
}

VqVaeLosses ComputeVqVaeLosses(const torch::Tensor& reconstruction,
                               const torch::Tensor& target,
                               const torch::Tensor& commit_loss,
                               const torch::Tensor& mean,
                               const torch::Tensor& std, int num_keypoints,
                               const VqVaeOptions& options) {
  VqVaeLosses losses;
  losses.canonical = F::smooth_l1_loss(reconstruction, target);
  losses.absolute = F::smooth_l1_loss(
      AbsoluteFromCanonical(reconstruction * std + mean, num_keypoints),
      AbsoluteFromCanonical(target * std + mean, num_keypoints));
  const int64_t pose_size = 2 * num_keypoints;
  auto pose_velocity = [&](const torch::Tensor& x) {
    torch::Tensor pose = x.narrow(2, 0, pose_size);
    const int64_t frames = pose.size(1);
    return pose.narrow(1, 1, frames - 1) - pose.narrow(1, 0, frames - 1);
  };
  losses.velocity = reconstruction.size(1) > 1
                        ? F::smooth_l1_loss(pose_velocity(reconstruction),
                                            pose_velocity(target))
                        : torch::zeros({});
  losses.commit = commit_loss;
  losses.total = losses.canonical + options.absolute_weight * losses.absolute +
                 options.velocity_weight * losses.velocity +
                 options.commit_weight * losses.commit;
  return losses;
}

std::vector<std::vector<int64_t>> TokenizeDataset(VqVae& model,
                                                  const GenDataset& dataset,
                                                  const torch::Tensor& mean,
                                                  const torch::Tensor& std,
                                                  std::vector<int>* kept) {
  torch::NoGradGuard no_grad;
  const bool was_training = model->is_training();
  model->eval();
  std::vector<std::vector<int64_t>> sequences;
  kept->clear();
  const int per_token = model->frames_per_token();
  for (size_t i = 0; i < dataset.sequences.size(); ++i) {
    const GenSequence& sequence = dataset.sequences[i];
    const int frames = sequence.num_frames / per_token * per_token;
    if (frames == 0) continue;
    torch::Tensor x =
        torch::from_blob(const_cast<float*>(sequence.features.data()),
                         {1, frames, dataset.frame_size})
            .clone();
    torch::Tensor tokens = model->Encode((x - mean) / std).reshape({-1});
    sequences.emplace_back(tokens.data_ptr<int64_t>(),
                           tokens.data_ptr<int64_t>() + tokens.numel());
    kept->push_back(static_cast<int>(i));
  }
  model->train(was_training);
  return sequences;
}

}  // namespace m2d
