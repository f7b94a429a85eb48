// bench: the generator's speed (docs/generation.md, "Speed") at the sizes of
// configs/gen/clips.yaml with untrained weights (speed does not depend on
// them): the prior's next code, the decoder's window, and a stream's code
// (items = frames of 2D; real time = items per second / 30). One LibTorch
// thread, as the issue measures it.
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include "gen/gen_config.h"
#include "gen/motion_stream.h"
#include "test_paths.h"

namespace m2d {
namespace {

constexpr int kCocoFrameSize = 2 * 17 + 3;  // CanonicalFrameSize(coco17)

const GenConfig& Config() {
  static const GenConfig config =
      LoadGenConfig(testing::SourcePath("configs/gen/clips.yaml"));
  return config;
}

LoadedPrior UntrainedPrior() {
  torch::manual_seed(1);
  LoadedPrior prior{Config(),
                    Gpt(Config().tokenizer.num_codes, Config().prior)};
  prior.model->eval();
  return prior;
}

LoadedTokenizer UntrainedTokenizer() {
  torch::manual_seed(2);
  LoadedTokenizer tokenizer{Config(), VqVae(kCocoFrameSize, Config().tokenizer),
                            torch::zeros({kCocoFrameSize}),
                            torch::ones({kCocoFrameSize})};
  tokenizer.model->eval();
  return tokenizer;
}

// One code from the prior, the context full (the steady state of endless
// generation). Items = codes.
void BM_PriorNextCode(benchmark::State& state) {
  torch::set_num_threads(1);
  TokenSampler sampler(UntrainedPrior().model, SamplingOptions(), 1);
  for (int i = 0; i < 2 * Config().prior.context_tokens; ++i) sampler.Next();
  for (auto _ : state) benchmark::DoNotOptimize(sampler.Next());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PriorNextCode)->Unit(benchmark::kMicrosecond);

// The baseline: the same code from a pass over the whole context (no cache),
// as sampling ran before the cache.
void BM_PriorNextCodeUncached(benchmark::State& state) {
  torch::set_num_threads(1);
  c10::InferenceMode inference;
  Gpt gpt = UntrainedPrior().model;
  const int context = Config().prior.context_tokens;
  const torch::Tensor window = torch::randint(0, Config().tokenizer.num_codes,
                                              {1, context}, torch::kLong);
  for (auto _ : state) {
    torch::Tensor logits = gpt->forward(window).select(1, context - 1)[0];
    benchmark::DoNotOptimize(
        torch::multinomial(torch::softmax(logits, 0), 1).item<int64_t>());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PriorNextCodeUncached)->Unit(benchmark::kMicrosecond);

// The decoder on one stream window of codes. Items = windows.
void BM_DecodeWindow(benchmark::State& state) {
  torch::set_num_threads(1);
  torch::NoGradGuard no_grad;
  LoadedTokenizer tokenizer = UntrainedTokenizer();
  const torch::Tensor codes =
      torch::randint(0, Config().tokenizer.num_codes,
                     {1, StreamDecoding().context_codes}, torch::kLong);
  for (auto _ : state) benchmark::DoNotOptimize(tokenizer.model->Decode(codes));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DecodeWindow)->Unit(benchmark::kMicrosecond);

// The whole stream: frames of 2D motion per second, decoding once per
// range(0) codes (StreamDecoding::emit_codes; 1 is the baseline, a decoding
// per code). Items = frames.
void BM_MotionStream(benchmark::State& state) {
  torch::set_num_threads(1);
  GenerationOptions options;
  options.decoding.emit_codes = static_cast<int>(state.range(0));
  MotionStream stream(UntrainedTokenizer(), UntrainedPrior(), options);
  std::vector<float> rows;
  for (int i = 0; i < 2 * Config().prior.context_tokens; ++i) {
    stream.Next(&rows);
    rows.clear();
  }
  for (auto _ : state) {
    stream.Next(&rows);
    rows.clear();
  }
  state.SetItemsProcessed(state.iterations() * stream.frames_per_token());
  state.counters["x_real_time"] =
      benchmark::Counter(state.iterations() * stream.frames_per_token() / 30.0,
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MotionStream)
    ->Arg(1)
    ->Arg(4)
    ->Arg(8)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace m2d
