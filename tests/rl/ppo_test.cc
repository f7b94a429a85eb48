#include "rl/ppo.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "small_networks.h"
#include "test_paths.h"

namespace m2d {
namespace {

using testing::SmallLayout;
using testing::SmallModel;

TEST(Gae, MatchesAHandComputedExample) {
  // Two steps, one env; the episode ends after step 1.
  torch::Tensor rewards = torch::tensor({{1.0f}, {2.0f}});
  torch::Tensor values = torch::tensor({{0.5f}, {1.0f}});
  torch::Tensor dones = torch::tensor({{0.0f}, {1.0f}});
  torch::Tensor last = torch::tensor({7.0f});  // ignored: episode ended
  torch::Tensor advantages, returns;
  ComputeGae(rewards, values, dones, last, 0.9, 0.8, &advantages, &returns);
  // delta_1 = 2 - 1 = 1; A_1 = 1.
  // delta_0 = 1 + 0.9 * 1.0 - 0.5 = 1.4; A_0 = 1.4 + 0.9 * 0.8 * 1 = 2.12.
  EXPECT_NEAR(advantages[1][0].item<float>(), 1.0f, 1e-6);
  EXPECT_NEAR(advantages[0][0].item<float>(), 2.12f, 1e-6);
  EXPECT_NEAR(returns[0][0].item<float>(), 2.62f, 1e-6);
}

TEST(Gae, BootstrapsFromTheLastValueWhenNotDone) {
  torch::Tensor rewards = torch::tensor({{0.0f, 0.0f}});
  torch::Tensor values = torch::tensor({{0.0f, 0.0f}});
  torch::Tensor dones = torch::tensor({{0.0f, 1.0f}});
  torch::Tensor last = torch::tensor({10.0f, 10.0f});
  torch::Tensor advantages, returns;
  ComputeGae(rewards, values, dones, last, 0.5, 1.0, &advantages, &returns);
  EXPECT_NEAR(advantages[0][0].item<float>(), 5.0f, 1e-6);
  EXPECT_NEAR(advantages[0][1].item<float>(), 0.0f, 1e-6);
}

TEST(AdaptLearningRate, FollowsTheTargetKlWithinItsBounds) {
  PpoOptions options;
  options.target_kl = 0.01;
  options.learning_rate_min = 1e-6;
  options.learning_rate_max = 1e-3;
  // Far above 2x target: divided by 1.5; far below half: multiplied.
  EXPECT_DOUBLE_EQ(AdaptLearningRate(3e-4, 0.5, options), 2e-4);
  EXPECT_DOUBLE_EQ(AdaptLearningRate(2e-4, 0.001, options), 3e-4);
  // Inside [target / 2, 2 target], the edges included: unchanged.
  EXPECT_DOUBLE_EQ(AdaptLearningRate(2e-4, 0.005, options), 2e-4);
  EXPECT_DOUBLE_EQ(AdaptLearningRate(2e-4, 0.02, options), 2e-4);
  // Clamped to the bounds.
  EXPECT_DOUBLE_EQ(AdaptLearningRate(1.2e-6, 1.0, options), 1e-6);
  EXPECT_DOUBLE_EQ(AdaptLearningRate(9e-4, 0.0, options), 1e-3);
  // The KL seen after resuming at sigma 0.05 with a rate set for 0.1
  // (0.5) takes 2e-4 into [target / 2, 2 target] territory in 5 steps.
  double rate = 2e-4;
  for (int i = 0; i < 5; ++i) rate = AdaptLearningRate(rate, 0.5, options);
  EXPECT_NEAR(rate, 2e-4 / std::pow(1.5, 5), 1e-12);
}

TEST(Networks, AveragingIdenticalViewsEqualsOneView) {
  torch::manual_seed(0);
  ObservationLayout layout = SmallLayout();
  ActorCritic model(layout, SmallModel(), 4);
  torch::Tensor base = torch::randn({5, layout.view_offset()});
  torch::Tensor view = torch::randn({5, layout.view_size()});
  torch::Tensor one = torch::cat({base, view}, 1);
  torch::Tensor three = torch::cat({base, view, view, view}, 1);
  EXPECT_TRUE(torch::allclose(model->ActionMean(one, 1),
                              model->ActionMean(three, 3), 1e-5, 1e-6));
  EXPECT_TRUE(torch::allclose(model->Value(one, 1), model->Value(three, 3),
                              1e-5, 1e-6));
  // Views are order-free: swapping two views changes nothing.
  torch::Tensor other = torch::randn({5, layout.view_size()});
  torch::Tensor ab = torch::cat({base, view, other}, 1);
  torch::Tensor ba = torch::cat({base, other, view}, 1);
  EXPECT_TRUE(torch::allclose(model->ActionMean(ab, 2),
                              model->ActionMean(ba, 2), 1e-5, 1e-6));
}

// Asymmetric actor-critic: the block between the policy's base features and
// the views moves the value, never the action, with one view or several.
TEST(Networks, OnlyTheCriticReadsTheCriticOnlyBlock) {
  torch::manual_seed(1);
  ObservationLayout layout = SmallLayout();
  layout.critic_only_size = 5;
  ActorCritic model(layout, SmallModel(), 4);
  for (int views : {1, 2}) {
    SCOPED_TRACE(views);
    torch::Tensor policy_base = torch::randn({5, layout.actor_base_size()});
    torch::Tensor blocks = torch::randn({5, views * layout.view_size()});
    torch::Tensor a = torch::cat(
        {policy_base, torch::randn({5, layout.critic_only_size}), blocks}, 1);
    torch::Tensor b = torch::cat(
        {policy_base, torch::randn({5, layout.critic_only_size}), blocks}, 1);
    EXPECT_TRUE(
        torch::equal(model->ActionMean(a, views), model->ActionMean(b, views)));
    EXPECT_FALSE(torch::allclose(model->Value(a, views), model->Value(b, views),
                                 1e-3, 1e-4));
    // The views still start at view_offset(): changing them moves both.
    torch::Tensor c = a.clone();
    c.narrow(1, layout.view_offset(), 1).add_(3.0);
    EXPECT_FALSE(torch::allclose(model->ActionMean(a, views),
                                 model->ActionMean(c, views), 1e-3, 1e-4));
  }
}

// A source with 2 future frames widened to 4 acts and values as before, on
// any values of the frames it never read (their weights start at zero), and
// its normalizer carries over; the new frames' statistics start as its last
// frame's. Only a longer horizon is widened.
TEST(Networks, WideningTheFutureFramesKeepsTheSourcesActionsAndValues) {
  torch::manual_seed(2);
  const ObservationLayout short_layout = SmallLayout();
  ObservationLayout long_layout = short_layout;
  long_layout.num_future_frames = 4;
  ActorCritic source(short_layout, SmallModel(), 4);
  source->UpdateNormalizer(torch::randn({64, short_layout.size()}) * 3 + 1);
  ActorCritic widened(long_layout, SmallModel(), 4);
  WidenFutureFrames(*source, *widened);

  const int64_t frame_width =
      short_layout.num_points * ObservationLayout::kPointFeatures;
  for (int views : {1, 2}) {
    SCOPED_TRACE(views);
    torch::Tensor base = torch::randn({5, short_layout.view_offset()});
    std::vector<torch::Tensor> short_parts = {base}, long_parts = {base};
    for (int k = 0; k < views; ++k) {
      torch::Tensor block = torch::randn({5, short_layout.view_size()});
      short_parts.push_back(block);
      long_parts.push_back(block);
      long_parts.push_back(torch::randn({5, 2 * frame_width}) * 10);
    }
    const torch::Tensor short_obs =
        source->Normalize(torch::cat(short_parts, 1));
    const torch::Tensor long_obs =
        widened->Normalize(torch::cat(long_parts, 1));
    EXPECT_TRUE(torch::allclose(source->ActionMean(short_obs, views),
                                widened->ActionMean(long_obs, views), 1e-5,
                                1e-6));
    EXPECT_TRUE(torch::allclose(source->Value(short_obs, views),
                                widened->Value(long_obs, views), 1e-5, 1e-6));
  }
  // The new frames are read once training moves their weights.
  auto parameters = widened->named_parameters();
  EXPECT_TRUE(parameters["actor_encoder.0.weight"]
                  .narrow(1, short_layout.view_size(), 2 * frame_width)
                  .abs()
                  .sum()
                  .item<double>() == 0.0);
  auto buffers = widened->named_buffers();
  auto source_buffers = source->named_buffers();
  const torch::Tensor last_frame_mean =
      source_buffers["view_normalizer.mean"].narrow(
          0, short_layout.view_size() - frame_width, frame_width);
  for (int frame = 3; frame <= 4; ++frame) {
    EXPECT_TRUE(torch::equal(buffers["view_normalizer.mean"].narrow(
                                 0, frame * frame_width, frame_width),
                             last_frame_mean));
  }

  // Not a shorter horizon, nor other networks.
  EXPECT_THROW(WidenFutureFrames(*widened, *source), ConfigError);
  ModelOptions wider = SmallModel();
  wider.encoder_hidden = {24};
  ActorCritic other(long_layout, wider, 4);
  EXPECT_THROW(WidenFutureFrames(*source, *other), ConfigError);
}

TEST(Networks, ABf16ScopeRoundsOnlyWithinItAndStaysNearFloat32) {
  torch::manual_seed(4);
  ObservationLayout layout = SmallLayout();
  ModelOptions options;
  ActorCritic model(layout, options, 4);
  torch::NoGradGuard no_grad;
  torch::Tensor obs = torch::randn({64, layout.size()});
  torch::Tensor fp32 = model->Value(obs);
  torch::Tensor bf16;
  {
    PrecisionScope precision(TrainingPrecision::kBf16);
    bf16 = model->Value(obs);
  }
  EXPECT_EQ(bf16.scalar_type(), torch::kBFloat16);
  // bfloat16 keeps 8 significant bits: within a few percent, not equal.
  const double scale = fp32.abs().max().item<double>();
  const double error =
      (bf16.to(torch::kFloat) - fp32).abs().max().item<double>();
  EXPECT_GT(error, 0.0);
  EXPECT_LT(error, 0.05 * scale);
  // The scope ends: float32 again, and an fp32 scope changes nothing.
  EXPECT_EQ(model->Value(obs).scalar_type(), torch::kFloat);
  {
    PrecisionScope precision(TrainingPrecision::kFp32);
    EXPECT_TRUE(torch::equal(model->Value(obs), fp32));
  }
}

TEST(Networks, RunningNormalizerTracksMeanAndVariance) {
  RunningNormalizer normalizer(2, /*clip_std=*/5.0);
  torch::manual_seed(1);
  for (int i = 0; i < 20; ++i) {
    torch::Tensor batch = torch::randn({500, 2}) * torch::tensor({2.0f, 0.5f}) +
                          torch::tensor({3.0f, -1.0f});
    normalizer->Update(batch);
  }
  EXPECT_NEAR(normalizer->mean[0].item<float>(), 3.0f, 0.05f);
  EXPECT_NEAR(normalizer->mean[1].item<float>(), -1.0f, 0.02f);
  EXPECT_NEAR(normalizer->variance[0].item<float>(), 4.0f, 0.2f);
  EXPECT_NEAR(normalizer->variance[1].item<float>(), 0.25f, 0.02f);
}

TEST(Networks, NormalizedFeaturesAreClippedAtTheConfiguredDeviations) {
  // A feature 7 running standard deviations out (the zombie walk's raised
  // wrists under a walks-trained normalizer) reaches the networks as 5 under
  // the default clip, as itself under a clip of 10.
  ObservationLayout layout = SmallLayout();
  torch::manual_seed(3);
  torch::Tensor batch = torch::randn({2000, layout.size()});
  for (double clip : {5.0, 10.0}) {
    ModelOptions options;
    options.observation_clip_std = clip;
    ActorCritic model(layout, options, 2);
    model->UpdateNormalizer(batch);
    const torch::Tensor normalizer_mean = batch.mean(0);
    const torch::Tensor normalizer_std = batch.std(0, /*unbiased=*/false);
    torch::Tensor far = (normalizer_mean + 7.0 * normalizer_std).unsqueeze(0);
    torch::Tensor normalized = model->Normalize(far);
    EXPECT_NEAR(normalized.min().item<float>(), std::min(clip, 7.0), 1e-3)
        << "clip " << clip;
    EXPECT_NEAR(normalized.max().item<float>(), std::min(clip, 7.0), 1e-3)
        << "clip " << clip;
  }
  ModelOptions defaults;
  EXPECT_EQ(defaults.observation_clip_std, 5.0);
}

TEST(Networks, LogProbMatchesTheGaussianDensity) {
  ObservationLayout layout = SmallLayout();
  ModelOptions options;
  options.action_std = 0.5;
  ActorCritic model(layout, options, 2);
  torch::Tensor mean = torch::zeros({1, 2});
  torch::Tensor action = torch::tensor({{0.5f, -1.0f}});
  double expected = 0.0;
  for (double a : {0.5, -1.0})
    expected +=
        -0.5 * (a / 0.5) * (a / 0.5) - std::log(0.5) - 0.5 * std::log(2 * M_PI);
  EXPECT_NEAR(model->LogProb(mean, action).item<float>(), expected, 1e-5);
}

TEST(PpoUpdate, ReducesTheLossOnAFixedBatch) {
  // A batch where action +0.5 earned a positive advantage: after updates the
  // mean action moves toward it.
  torch::manual_seed(2);
  ObservationLayout layout = SmallLayout();
  ModelOptions options;
  options.policy_hidden = {32};
  options.critic_hidden = {32};
  ActorCritic model(layout, options, 1);
  RolloutStorage storage(8, 16, layout.size(), 1);
  storage.observations.normal_();
  {
    torch::NoGradGuard no_grad;
    torch::Tensor obs = storage.observations.reshape({128, -1});
    torch::Tensor mean = model->ActionMean(obs);
    torch::Tensor action = mean + 0.5;
    storage.actions.copy_(action.reshape({8, 16, 1}));
    storage.log_probs.copy_(model->LogProb(mean, action).reshape({8, 16}));
    storage.advantages.fill_(0.0);
    storage.advantages.index_put_(
        {torch::indexing::Slice(), torch::indexing::Slice(0, 8)}, 1.0);
    storage.advantages.index_put_(
        {torch::indexing::Slice(), torch::indexing::Slice(8, 16)}, -1.0);
    storage.returns.fill_(1.0);
  }
  PpoOptions ppo;
  ppo.num_envs = 16;
  ppo.steps_per_env = 8;
  ppo.minibatch_size = 32;
  ppo.epochs = 4;
  torch::optim::Adam optimizer(model->parameters(),
                               torch::optim::AdamOptions(1e-3));
  torch::Generator generator = at::detail::createCPUGenerator(3);
  torch::Tensor obs = storage.observations.reshape({128, -1});
  double before =
      torch::mean(torch::abs(model->Value(obs) - 1.0)).item<double>();
  PpoLosses losses = PpoUpdate(model, optimizer, storage, ppo, generator);
  double after =
      torch::mean(torch::abs(model->Value(obs) - 1.0)).item<double>();
  EXPECT_LT(after, before);
  EXPECT_TRUE(std::isfinite(losses.policy_loss));
  EXPECT_GT(losses.clip_fraction, 0.0);
}

}  // namespace
}  // namespace m2d
