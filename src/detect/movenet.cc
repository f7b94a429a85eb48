#include "detect/movenet.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "common/error.h"
#include "detect/tfjs_graph.h"

namespace m2d {
namespace {

namespace F = torch::nn::functional;

// An RGB image as a float [1, 3, H, W] tensor (a view is not possible: the
// bytes are uint8).
torch::Tensor ImageTensor(const RgbImage& image) {
  return torch::from_blob(const_cast<uint8_t*>(image.data()),
                          {1, image.height_px(), image.width_px(), 3},
                          torch::kUInt8)
      .permute({0, 3, 1, 2})
      .to(torch::kFloat);
}

// [1, 3, h, w] float -> the models' int32 [1, h, w, 3] (rounded).
torch::Tensor ModelInput(const torch::Tensor& nchw) {
  return torch::round(nchw)
      .clamp(0, 255)
      .permute({0, 2, 3, 1})
      .contiguous()
      .to(torch::kInt);
}

}  // namespace

double BoxIou(const Box& a, const Box& b) {
  Box overlap{std::max(a.x0_px, b.x0_px), std::max(a.y0_px, b.y0_px),
              std::min(a.x1_px, b.x1_px), std::min(a.y1_px, b.y1_px)};
  const double inter = overlap.area_px2();
  const double total = a.area_px2() + b.area_px2() - inter;
  return total > 0 ? inter / total : 0.0;
}

Box KeypointBox(const DetectedPerson& person, double min_score) {
  Box box{INFINITY, INFINITY, -INFINITY, -INFINITY};
  int count = 0;
  for (const Keypoint2D& k : person.keypoints) {
    if (!(k.confidence >= min_score)) continue;
    box.x0_px = std::min(box.x0_px, k.x_px);
    box.y0_px = std::min(box.y0_px, k.y_px);
    box.x1_px = std::max(box.x1_px, k.x_px);
    box.y1_px = std::max(box.y1_px, k.y_px);
    ++count;
  }
  return count >= 2 ? box : Box();
}

void SetDetectionThreads(int threads) { torch::set_num_threads(threads); }

std::string DefaultMoveNetFolder() {
  const char* override_folder = std::getenv("MIMIC2D_MODELS");
  if (override_folder != nullptr && *override_folder != '\0')
    return override_folder;
  return std::string(MIMIC2D_SOURCE_DIR) + "/assets/models/movenet";
}

struct MoveNet::Impl {
  TfjsGraphModel single;
  TfjsGraphModel multi;
  int input_side_px = 192;
};

MoveNet::MoveNet(const std::string& folder, MoveNetModel model)
    : impl_(new Impl{
          TfjsGraphModel::Load(folder + (model == MoveNetModel::kLightning
                                             ? "/movenet-lightning.json"
                                             : "/movenet-thunder.json")),
          TfjsGraphModel::Load(folder + "/movenet-multipose.json")}) {
  impl_->input_side_px = static_cast<int>(impl_->single.input_shape().at(1));
}

MoveNet::~MoveNet() = default;
MoveNet::MoveNet(MoveNet&&) noexcept = default;

DetectedPerson MoveNet::DetectInRegion(const RgbImage& image,
                                       double centre_x_px, double centre_y_px,
                                       double side_px) const {
  // Outline: cut the square region (black outside the image), resize it to
  // the model's input, run, map the normalized keypoints back.
  c10::InferenceMode inference;
  const int n = impl_->input_side_px;
  const double x0 = centre_x_px - 0.5 * side_px;
  const double y0 = centre_y_px - 0.5 * side_px;
  // Pixel bounds of the region, padded where it leaves the image.
  const int64_t left = static_cast<int64_t>(std::floor(x0));
  const int64_t top = static_cast<int64_t>(std::floor(y0));
  const int64_t side = std::max<int64_t>(1, std::llround(side_px));
  // Only the part inside the image is converted to float; the rest is
  // black padding (not the whole frame per call: this runs every frame).
  const int64_t width = image.width_px(), height = image.height_px();
  const int64_t inside_x0 = std::clamp<int64_t>(left, 0, width);
  const int64_t inside_x1 = std::clamp<int64_t>(left + side, 0, width);
  const int64_t inside_y0 = std::clamp<int64_t>(top, 0, height);
  const int64_t inside_y1 = std::clamp<int64_t>(top + side, 0, height);
  torch::Tensor region;
  if (inside_x1 <= inside_x0 || inside_y1 <= inside_y0) {
    region = torch::zeros({1, 3, side, side});
  } else {
    torch::Tensor inside =
        torch::from_blob(const_cast<uint8_t*>(image.data()),
                         {1, height, width, 3}, torch::kUInt8)
            .slice(1, inside_y0, inside_y1)
            .slice(2, inside_x0, inside_x1)
            .permute({0, 3, 1, 2})
            .to(torch::kFloat);
    region = F::pad(
        inside, F::PadFuncOptions({inside_x0 - left, left + side - inside_x1,
                                   inside_y0 - top, top + side - inside_y1}));
  }
  torch::Tensor input =
      ModelInput(F::interpolate(region, F::InterpolateFuncOptions()
                                            .size(std::vector<int64_t>{n, n})
                                            .mode(torch::kBilinear)
                                            .align_corners(false)
                                            .antialias(side > n)));
  torch::Tensor output = impl_->single.Run(input).reshape({17, 3});
  const float* values = output.data_ptr<float>();
  DetectedPerson person;
  double score_sum = 0;
  for (int j = 0; j < 17; ++j) {
    const double y = values[3 * j], x = values[3 * j + 1];
    person.keypoints[j] = {left + x * side, top + y * side, values[3 * j + 2]};
    score_sum += values[3 * j + 2];
  }
  person.score = score_sum / 17;
  person.box = KeypointBox(person, 0.2);
  return person;
}

std::vector<DetectedPerson> MoveNet::DetectPeople(const RgbImage& image,
                                                  int long_side_px,
                                                  double min_score) const {
  c10::InferenceMode inference;
  const double scale = static_cast<double>(long_side_px) /
                       std::max(image.width_px(), image.height_px());
  auto to32 = [](double v) {
    return std::max<int64_t>(32, 32 * std::llround(v / 32.0));
  };
  const int64_t w = to32(image.width_px() * scale);
  const int64_t h = to32(image.height_px() * scale);
  torch::Tensor input = ModelInput(
      F::interpolate(ImageTensor(image), F::InterpolateFuncOptions()
                                             .size(std::vector<int64_t>{h, w})
                                             .mode(torch::kBilinear)
                                             .align_corners(false)
                                             .antialias(true)));
  torch::Tensor output = impl_->multi.Run(input).reshape({-1, 56});
  const float* values = output.data_ptr<float>();
  std::vector<DetectedPerson> people;
  for (int64_t p = 0; p < output.size(0); ++p) {
    const float* row = values + 56 * p;
    if (!(row[55] >= min_score)) continue;
    DetectedPerson person;
    for (int j = 0; j < 17; ++j) {
      person.keypoints[j] = {row[3 * j + 1] * image.width_px(),
                             row[3 * j] * image.height_px(), row[3 * j + 2]};
    }
    person.box = {row[52] * image.width_px(), row[51] * image.height_px(),
                  row[54] * image.width_px(), row[53] * image.height_px()};
    person.score = row[55];
    people.push_back(person);
  }
  std::sort(people.begin(), people.end(),
            [](const DetectedPerson& a, const DetectedPerson& b) {
              return a.score > b.score;
            });
  return people;
}

}  // namespace m2d
