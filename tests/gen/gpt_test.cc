#include "gen/gpt.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include "common/error.h"

namespace m2d {
namespace {

GptOptions SmallGpt() {
  GptOptions options;
  options.num_layers = 2;
  options.num_heads = 2;
  options.embedding = 32;
  options.context_tokens = 12;
  options.dropout = 0.0;
  return options;
}

TEST(Gpt, IsCausal) {
  // Changing a later token never changes an earlier position's logits.
  torch::manual_seed(1);
  Gpt gpt(16, SmallGpt());
  gpt->eval();
  torch::Tensor tokens =
      torch::tensor({16, 3, 5, 7, 9, 11}, torch::kLong).unsqueeze(0);
  torch::Tensor changed = tokens.clone();
  changed[0][4] = 2;
  torch::Tensor a = gpt->forward(tokens), b = gpt->forward(changed);
  EXPECT_TRUE(torch::allclose(a.narrow(1, 0, 4), b.narrow(1, 0, 4)));
  EXPECT_FALSE(torch::allclose(a.narrow(1, 4, 2), b.narrow(1, 4, 2)));
}

TEST(Gpt, CachedInferenceMatchesTheFullForward) {
  // A prefix at once, then token by token: every step's logits equal the
  // full forward's at that position.
  torch::manual_seed(3);
  Gpt gpt(16, SmallGpt());
  gpt->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor tokens =
      torch::tensor({16, 3, 5, 7, 9, 11, 2, 2, 14, 0, 1, 6}, torch::kLong);
  const torch::Tensor full = gpt->forward(tokens.unsqueeze(0))[0];  // [S, K]
  GptCache cache;
  torch::Tensor logits = gpt->ForwardCached(tokens.narrow(0, 0, 4), &cache);
  EXPECT_TRUE(torch::allclose(logits, full[3], 1e-5, 1e-5));
  for (int64_t s = 4; s < tokens.size(0); ++s) {
    logits = gpt->ForwardCached(tokens.narrow(0, s, 1), &cache);
    EXPECT_TRUE(torch::allclose(logits, full[s], 1e-5, 1e-5)) << "at " << s;
  }
  EXPECT_EQ(cache.length, 12);
  // The context is full: one more token is refused.
  EXPECT_THROW(gpt->ForwardCached(tokens.narrow(0, 0, 1), &cache), c10::Error);
}

TEST(Gpt, SamplingIsDeterministicForASeed) {
  torch::manual_seed(1);
  Gpt gpt(16, SmallGpt());
  auto draw = [&](uint64_t seed) {
    TokenSampler sampler(gpt, SamplingOptions{1.0, 0}, seed);
    for (int i = 0; i < 40; ++i) sampler.Next();  // past the context of 12
    return sampler.codes();
  };
  EXPECT_EQ(draw(7), draw(7));
  EXPECT_NE(draw(7), draw(8));
}

TEST(Gpt, TopKOneIsGreedy) {
  torch::manual_seed(1);
  Gpt gpt(16, SmallGpt());
  TokenSampler a(gpt, SamplingOptions{1.0, 1}, 1),
      b(gpt, SamplingOptions{1.0, 1}, 2);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(a.Next(), b.Next());
}

TEST(Gpt, BatchesReadSequencesFromTheirStart) {
  auto generator = at::make_generator<at::CPUGeneratorImpl>(1);
  // One sequence shorter than the context: every window is it, padded.
  TokenBatch batch = SampleTokenBatch({{4, 5, 6}}, 8, 6, 2, 1.0, generator);
  std::vector<int64_t> inputs(batch.inputs[0].data_ptr<int64_t>(),
                              batch.inputs[0].data_ptr<int64_t>() + 6);
  std::vector<int64_t> targets(batch.targets[0].data_ptr<int64_t>(),
                               batch.targets[0].data_ptr<int64_t>() + 6);
  EXPECT_EQ(inputs, (std::vector<int64_t>{8, 4, 5, 0, 0, 0}));
  EXPECT_EQ(targets, (std::vector<int64_t>{4, 5, 6, kIgnoreTarget,
                                           kIgnoreTarget, kIgnoreTarget}));
}

TEST(Gpt, ConditionedWindowsOpenWithTheirView) {
  auto generator = at::make_generator<at::CPUGeneratorImpl>(1);
  // Slot 0 holds the view token (20); the read sequence follows, so the
  // first window of {4, 5, 6} is [20, start, 4, 5, pad, pad]; slot 0
  // predicts nothing there (the start token is not a code).
  TokenBatch batch =
      SampleTokenBatch({{4, 5, 6}}, 8, 6, 2, 1.0, generator, {20});
  std::vector<int64_t> inputs(batch.inputs[0].data_ptr<int64_t>(),
                              batch.inputs[0].data_ptr<int64_t>() + 6);
  std::vector<int64_t> targets(batch.targets[0].data_ptr<int64_t>(),
                               batch.targets[0].data_ptr<int64_t>() + 6);
  EXPECT_EQ(inputs, (std::vector<int64_t>{20, 8, 4, 5, 0, 0}));
  EXPECT_EQ(targets, (std::vector<int64_t>{kIgnoreTarget, 4, 5, 6,
                                           kIgnoreTarget, kIgnoreTarget}));
  // Mid-sequence windows: slot 0 predicts the window's first code. Each
  // sequence gets its own view; corruption never touches the view or the
  // start token.
  std::vector<std::vector<int64_t>> sequences = {{}, {}};
  for (int64_t i = 0; i < 40; ++i) {
    sequences[0].push_back(i % 4);
    sequences[1].push_back(4 + i % 4);
  }
  batch = SampleTokenBatch(sequences, 8, 6, 64, 1.0, generator, {9, 10});
  int mid_windows = 0;
  for (int b = 0; b < 64; ++b) {
    const int64_t view = batch.inputs[b][0].item<int64_t>();
    ASSERT_TRUE(view == 9 || view == 10);
    const int64_t first = batch.inputs[b][1].item<int64_t>();
    if (first == 8) continue;  // the start: slot 0 predicts nothing
    ++mid_windows;
    EXPECT_EQ(batch.targets[b][0].item<int64_t>(), first);
    EXPECT_EQ(first / 4, view - 9);  // the view's own sequence
  }
  EXPECT_GT(mid_windows, 40);
  torch::Tensor corrupted =
      SampleTokenBatch(sequences, 8, 6, 64, 0.0, generator, {9, 10}).inputs;
  EXPECT_TRUE(corrupted.select(1, 0).ge(9).all().item<bool>());
  // Sequences and conditions must pair up.
  EXPECT_THROW(SampleTokenBatch(sequences, 8, 6, 1, 1.0, generator, {9}),
               c10::Error);
}

TEST(Gpt, AConditionedPriorGeneratesTheViewItIsAskedFor) {
  // View 0 cycles through codes 0..3, view 1 through 4..7, from every
  // phase. Asked for a view, the prior draws its codes from the first one
  // on (an unconditioned prior's first code would be either view's) and
  // keeps to them past the context.
  torch::manual_seed(4);
  torch::set_num_threads(1);
  GptOptions options = SmallGpt();
  options.condition_on_view = true;
  Gpt gpt(8, options, /*num_views=*/2);
  torch::optim::AdamW optimizer(gpt->parameters(),
                                torch::optim::AdamWOptions(3e-3));
  std::vector<std::vector<int64_t>> sequences;
  std::vector<int64_t> conditions;
  for (int view = 0; view < 2; ++view) {
    for (int phase = 0; phase < 4; ++phase) {
      std::vector<int64_t> codes;
      for (int i = 0; i < 40; ++i) codes.push_back(4 * view + (i + phase) % 4);
      sequences.push_back(codes);
      conditions.push_back(gpt->view_token(view));
    }
  }
  auto generator = at::make_generator<at::CPUGeneratorImpl>(5);
  for (int step = 0; step < 300; ++step) {
    TokenBatch batch =
        SampleTokenBatch(sequences, 8, options.context_tokens, 16,
                         options.keep_probability, generator, conditions);
    torch::Tensor l = NextTokenLoss(gpt->forward(batch.inputs), batch.targets);
    optimizer.zero_grad();
    l.backward();
    optimizer.step();
  }
  torch::NoGradGuard no_grad;
  gpt->eval();
  for (int view = 0; view < 2; ++view) {
    // The first code: the 4 likeliest are the view's 4.
    GptCache cache;
    const torch::Tensor first = gpt->ForwardCached(
        torch::tensor({gpt->view_token(view), gpt->start_token()}), &cache);
    const torch::Tensor likeliest =
        std::get<0>(std::get<1>(first.topk(4)).sort());
    EXPECT_TRUE(likeliest.equal(torch::arange(4 * view, 4 * view + 4)))
        << "view " << view;
    // Then the view's cycle, past the context of 12.
    TokenSampler sampler(gpt, SamplingOptions{1.0, 1}, 1, view);
    int64_t previous = sampler.Next();
    for (int i = 1; i < 40; ++i) {
      const int64_t code = sampler.Next();
      ASSERT_EQ(code, 4 * view + (previous + 1) % 4) << "code " << i;
      previous = code;
    }
  }
  // A view it does not know, or none, is refused; so is a view asked of an
  // unconditioned prior.
  EXPECT_THROW(TokenSampler(gpt, SamplingOptions(), 1, 2), ConfigError);
  EXPECT_THROW(TokenSampler(gpt, SamplingOptions(), 1), ConfigError);
  EXPECT_THROW(TokenSampler(Gpt(8, SmallGpt()), SamplingOptions(), 1, 0),
               ConfigError);
}

TEST(Gpt, LearnsACycleAndContinuesItEndlessly) {
  // Codes 0..5 repeating: after training, greedy sampling must continue the
  // cycle far past the context (the sliding window starts mid-cycle).
  torch::manual_seed(2);
  torch::set_num_threads(1);
  GptOptions options = SmallGpt();
  options.keep_probability = 0.9;
  Gpt gpt(8, options);
  torch::optim::AdamW optimizer(gpt->parameters(),
                                torch::optim::AdamWOptions(3e-3));
  std::vector<std::vector<int64_t>> sequences;
  for (int offset = 0; offset < 6; ++offset) {
    std::vector<int64_t> codes;
    for (int i = 0; i < 60; ++i) codes.push_back((i + offset) % 6);
    sequences.push_back(codes);
  }
  auto generator = at::make_generator<at::CPUGeneratorImpl>(3);
  double loss = 0;
  for (int step = 0; step < 300; ++step) {
    TokenBatch batch =
        SampleTokenBatch(sequences, 8, options.context_tokens, 16,
                         options.keep_probability, generator);
    torch::Tensor l = NextTokenLoss(gpt->forward(batch.inputs), batch.targets);
    optimizer.zero_grad();
    l.backward();
    optimizer.step();
    loss = l.item<double>();
  }
  EXPECT_LT(loss, 0.5);  // corrupted inputs keep it above 0
  // However much of the past each slide keeps (0: half the context of 12).
  for (int kept : {0, 1, 11}) {
    TokenSampler sampler(gpt, SamplingOptions{1.0, 1, kept}, 1);
    for (int i = 0; i < 50; ++i) sampler.Next();
    const std::vector<int64_t>& codes = sampler.codes();
    for (size_t i = 1; i < codes.size(); ++i)
      EXPECT_EQ(codes[i], (codes[i - 1] + 1) % 6)
          << "at " << i << ", kept " << kept;
  }
  // A slide that would keep the whole context is refused.
  EXPECT_THROW(TokenSampler(gpt, SamplingOptions{1.0, 1, 12}, 1), ConfigError);
}

TEST(Gpt, HeldOutCodesAreNeverTrainedOn) {
  const int context = 4;
  std::vector<std::vector<int64_t>> sequences = {
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11},  // 12 >= 2 * 4 + 1: split
      {20, 21, 22}};                           // too short: kept whole
  const TokenSplit split = SplitTokensForValidation(sequences, context);
  ASSERT_EQ(split.training.size(), 2u);
  EXPECT_EQ(split.training[0], (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(split.training[1], sequences[1]);
  ASSERT_TRUE(split.validation.inputs.defined());
  ASSERT_EQ(split.validation.inputs.sizes(), (std::vector<int64_t>{1, 4}));
  // Targets are the last 4 codes; inputs the code before them onward.
  EXPECT_TRUE(split.validation.targets[0].equal(
      torch::tensor({8, 9, 10, 11}, torch::kLong)));
  EXPECT_TRUE(split.validation.inputs[0].equal(
      torch::tensor({7, 8, 9, 10}, torch::kLong)));
  // Conditioned: the view token takes the place of the code before them.
  const TokenSplit conditioned =
      SplitTokensForValidation(sequences, context, {30, 31});
  EXPECT_EQ(conditioned.training, split.training);
  EXPECT_TRUE(conditioned.validation.targets[0].equal(
      torch::tensor({8, 9, 10, 11}, torch::kLong)));
  EXPECT_TRUE(conditioned.validation.inputs[0].equal(
      torch::tensor({30, 8, 9, 10}, torch::kLong)));
  // Nothing long enough: no validation batch.
  EXPECT_FALSE(SplitTokensForValidation({{1, 2, 3}}, context)
                   .validation.inputs.defined());
}

}  // namespace
}  // namespace m2d
