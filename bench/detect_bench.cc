// bench: the cost of finding keypoints in video (docs/video.md) — one
// MoveNet run per model on LibTorch, a single-pose region cut from a
// vtest.avi frame, MultiPose on a whole frame, and decoding. Items = frames.
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <filesystem>
#include <string>

#include "detect/movenet.h"
#include "detect/tfjs_graph.h"
#include "media/video_reader.h"

namespace m2d {
namespace {

const std::string kVideo = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";

const RgbImage& VtestFrame() {
  static const RgbImage frame = ReadImageFile(kVideo);
  return frame;
}

void BM_GraphRun(benchmark::State& state, const char* name, int width,
                 int height) {
  torch::set_num_threads(static_cast<int>(state.range(0)));
  TfjsGraphModel model =
      TfjsGraphModel::Load(DefaultMoveNetFolder() + "/" + name + ".json");
  torch::Tensor input =
      torch::randint(0, 255, {1, height, width, 3}, torch::kInt);
  for (auto _ : state) benchmark::DoNotOptimize(model.Run(input));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_GraphRun, lightning, "movenet-lightning", 192, 192)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GraphRun, thunder, "movenet-thunder", 256, 256)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GraphRun, multipose_512x384, "movenet-multipose", 512, 384)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond);

// Single pose around a person in vtest.avi (the region the tracker cuts).
void BM_DetectInRegion(benchmark::State& state) {
  torch::set_num_threads(static_cast<int>(state.range(0)));
  MoveNet movenet(DefaultMoveNetFolder(), MoveNetModel::kLightning);
  for (auto _ : state)
    benchmark::DoNotOptimize(
        movenet.DetectInRegion(VtestFrame(), 600, 300, 120));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DetectInRegion)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_DecodeVtest(benchmark::State& state) {
  int64_t frames = 0;
  for (auto _ : state) {
    VideoReader reader(kVideo);
    RgbImage frame;
    while (reader.Read(&frame)) ++frames;
  }
  state.SetItemsProcessed(frames);
}
BENCHMARK(BM_DecodeVtest)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace m2d
