// detect: people's 2D keypoints from images and video — a TF.js graph-model
// interpreter on LibTorch, MoveNet on it, and a tracker that keeps one
// person across frames.
#ifndef MIMIC2D_DETECT_TFJS_GRAPH_H_
#define MIMIC2D_DETECT_TFJS_GRAPH_H_

#include <torch/torch.h>

#include <map>
#include <string>
#include <vector>

namespace m2d {

// A TF.js graph model (model.json + its weight shards, as tfjs-converter
// writes them) run on LibTorch tensors. Tensors keep TensorFlow's layout
// (NHWC) and semantics; convolutions run on channels-last views of them, so
// no layout copies are made. Supports the ops MoveNet's single- and
// multi-pose models use (SupportedOps()); loading a graph with any other op
// is an InputError naming the file and the op.
class TfjsGraphModel {
 public:
  // Reads `model_json_path` and the weight files its manifest names (next
  // to it). InputError naming the file on a missing or damaged file, a
  // weight shard of the wrong size, an unsupported op or dtype.
  static TfjsGraphModel Load(const std::string& model_json_path);

  // The single input's shape from the model's signature (-1: any) and
  // dtype; the single output's node name.
  const std::vector<int64_t>& input_shape() const { return input_shape_; }
  torch::ScalarType input_dtype() const { return input_dtype_; }

  // Runs the graph on `input` (the signature's dtype and shape) and returns
  // its output. Thread-compatible: const, no state changes.
  torch::Tensor Run(const torch::Tensor& input) const;

  static const std::vector<std::string>& SupportedOps();

 private:
  struct Node {
    std::string name;
    std::string op;
    // Inputs as (node index, output index); control inputs dropped.
    std::vector<std::pair<int, int>> inputs;
    // Attributes this interpreter reads, decoded at load.
    std::vector<int64_t> strides, dilations, squeeze_dims, ksize;
    std::string padding;                 // SAME / VALID
    std::vector<std::string> fused_ops;  // BiasAdd, Relu, Relu6
    int64_t axis = 0;                    // Unpack, Pack
    int64_t num = 0;                     // Unpack outputs, Split parts
    bool keep_dims = false;              // Max, Sum
    // StridedSlice's bit masks (ellipsis_mask must be 0).
    int64_t begin_mask = 0, end_mask = 0, new_axis_mask = 0,
            shrink_axis_mask = 0;
    torch::ScalarType cast_to = torch::kFloat;
    bool align_corners = false, half_pixel_centers = false;
  };

  std::vector<torch::Tensor> Execute(const Node& node,
                                     const std::vector<torch::Tensor>& inputs,
                                     const torch::Tensor& graph_input) const;

  std::string path_;
  std::vector<Node> nodes_;  // in an order where inputs come first
  std::map<std::string, torch::Tensor> constants_;
  int input_node_ = -1, output_node_ = -1;
  std::vector<int64_t> input_shape_;
  torch::ScalarType input_dtype_ = torch::kFloat;
};

}  // namespace m2d

#endif  // MIMIC2D_DETECT_TFJS_GRAPH_H_
