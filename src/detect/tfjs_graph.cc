#include "detect/tfjs_graph.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "common/error.h"
#include "common/file_io.h"

namespace m2d {
namespace {

namespace F = torch::nn::functional;

// TF.js stores string attributes base64-encoded (e.g. "U0FNRQ==" = SAME).
// Hand-written: a dozen lines, and none of our libraries exports one.
std::string DecodeBase64(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  int bits = 0, buffer = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;  // '=' padding
    buffer = (buffer << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((buffer >> bits) & 0xff));
    }
  }
  return out;
}

torch::ScalarType DtypeOf(const std::string& tf_type, const std::string& file) {
  if (tf_type == "DT_FLOAT" || tf_type == "float32") return torch::kFloat;
  if (tf_type == "DT_INT32" || tf_type == "int32") return torch::kInt;
  if (tf_type == "DT_BOOL" || tf_type == "bool") return torch::kBool;
  throw InputError(file, "unsupported tensor dtype '" + tf_type + "'");
}

std::vector<int64_t> IntList(const nlohmann::json& attr, const char* key) {
  std::vector<int64_t> values;
  if (!attr.contains(key)) return values;
  const nlohmann::json& list = attr[key]["list"];
  if (!list.contains("i")) return values;
  for (const nlohmann::json& v : list["i"])
    values.push_back(std::stoll(v.get<std::string>()));
  return values;
}

int64_t IntAttr(const nlohmann::json& attr, const char* key) {
  if (!attr.contains(key)) return 0;
  const nlohmann::json& i = attr[key]["i"];
  return i.is_string() ? std::stoll(i.get<std::string>()) : i.get<int64_t>();
}

bool BoolAttr(const nlohmann::json& attr, const char* key) {
  return attr.contains(key) && attr[key].value("b", false);
}

// TensorFlow's SAME padding: output ceil(in / stride); the total padding
// split with the extra row or column at the end.
std::pair<int64_t, int64_t> SamePadding(int64_t in, int64_t kernel,
                                        int64_t stride, int64_t dilation) {
  const int64_t out = (in + stride - 1) / stride;
  const int64_t effective = (kernel - 1) * dilation + 1;
  const int64_t total =
      std::max<int64_t>((out - 1) * stride + effective - in, 0);
  return {total / 2, total - total / 2};
}

// A convolution of an NHWC tensor: x [N,H,W,C]; weight in torch's
// [O, I/groups, kh, kw]; returns NHWC. The NCHW view of x is channels-last
// in memory, which oneDNN convolves without copying.
torch::Tensor ConvNhwc(const torch::Tensor& x, const torch::Tensor& weight,
                       const torch::Tensor& bias,
                       const std::vector<int64_t>& strides,
                       const std::vector<int64_t>& dilations,
                       const std::string& padding, int64_t groups) {
  torch::Tensor nchw = x.permute({0, 3, 1, 2});
  const int64_t stride_h = strides.size() == 4 ? strides[1] : 1;
  const int64_t stride_w = strides.size() == 4 ? strides[2] : 1;
  const int64_t dilation_h = dilations.size() == 4 ? dilations[1] : 1;
  const int64_t dilation_w = dilations.size() == 4 ? dilations[2] : 1;
  if (padding == "SAME") {
    const auto [top, bottom] =
        SamePadding(nchw.size(2), weight.size(2), stride_h, dilation_h);
    const auto [left, right] =
        SamePadding(nchw.size(3), weight.size(3), stride_w, dilation_w);
    if (top != bottom || left != right) {
      nchw = F::pad(nchw, F::PadFuncOptions({left, right, top, bottom}))
                 .contiguous(torch::MemoryFormat::ChannelsLast);
    } else if (top > 0 || left > 0) {
      const std::vector<int64_t> symmetric = {top, left};
      torch::Tensor out =
          torch::conv2d(nchw, weight, bias, {stride_h, stride_w}, symmetric,
                        {dilation_h, dilation_w}, groups);
      return out.permute({0, 2, 3, 1});
    }
  }
  const std::vector<int64_t> no_padding = {0, 0};
  torch::Tensor out =
      torch::conv2d(nchw, weight, bias, {stride_h, stride_w}, no_padding,
                    {dilation_h, dilation_w}, groups);
  return out.permute({0, 2, 3, 1});
}

torch::Tensor ApplyFusedActivations(torch::Tensor x,
                                    const std::vector<std::string>& fused) {
  for (const std::string& op : fused) {
    if (op == "Relu") x = torch::relu(x);
    if (op == "Relu6") x = torch::clamp(x, 0.0, 6.0);
  }
  return x;
}

// TensorFlow's ExpandDims / axis arguments may be negative.
int64_t NormalizeAxis(int64_t axis, int64_t rank) {
  return axis < 0 ? axis + rank : axis;
}

// Elementwise ops follow TF's dtype: int32 stays int32.
torch::Tensor FloorDivide(const torch::Tensor& a, const torch::Tensor& b) {
  if (a.is_floating_point() || b.is_floating_point())
    return torch::floor(a / b);
  return torch::div(a, b, "floor").to(a.scalar_type());
}

// GatherNd: indices [..., K] pick slices params[i0, ..., iK-1].
torch::Tensor GatherNd(const torch::Tensor& params,
                       const torch::Tensor& indices) {
  const int64_t k = indices.size(-1);
  std::vector<int64_t> slice_shape(params.sizes().begin() + k,
                                   params.sizes().end());
  torch::Tensor flat_params = params.reshape([&] {
    std::vector<int64_t> shape = {-1};
    shape.insert(shape.end(), slice_shape.begin(), slice_shape.end());
    return shape;
  }());
  torch::Tensor idx = indices.to(torch::kLong).reshape({-1, k});
  torch::Tensor linear = torch::zeros({idx.size(0)}, torch::kLong);
  for (int64_t d = 0; d < k; ++d)
    linear = linear * params.size(d) + idx.select(1, d);
  torch::Tensor gathered = flat_params.index_select(0, linear);
  std::vector<int64_t> out_shape(indices.sizes().begin(),
                                 indices.sizes().end() - 1);
  out_shape.insert(out_shape.end(), slice_shape.begin(), slice_shape.end());
  return gathered.reshape(out_shape);
}

// TensorFlow's StridedSlice for positive strides, without ellipsis: per
// entry of `begin`, a new axis, a single index (shrink) or a range.
torch::Tensor StridedSlice(const torch::Tensor& x, const torch::Tensor& begin,
                           const torch::Tensor& end,
                           const torch::Tensor& strides, int64_t begin_mask,
                           int64_t end_mask, int64_t new_axis_mask,
                           int64_t shrink_axis_mask, const std::string& where) {
  torch::Tensor b = begin.to(torch::kLong).contiguous();
  torch::Tensor e = end.to(torch::kLong).contiguous();
  torch::Tensor s = strides.to(torch::kLong).contiguous();
  torch::Tensor y = x;
  int64_t dim = 0;  // the next dimension of y to slice
  for (int64_t i = 0; i < b.numel(); ++i) {
    const int64_t bit = int64_t{1} << i;
    if (new_axis_mask & bit) {
      y = y.unsqueeze(dim++);
      continue;
    }
    if (dim >= y.dim())
      throw InputError(where, "StridedSlice indexes past the tensor's rank");
    const int64_t size = y.size(dim);
    const int64_t stride = s.data_ptr<int64_t>()[i];
    if (stride <= 0)
      throw InputError(where, "StridedSlice with a non-positive stride");
    auto clamp = [&](int64_t v) {
      if (v < 0) v += size;
      return std::clamp<int64_t>(v, 0, size);
    };
    if (shrink_axis_mask & bit) {
      int64_t index = b.data_ptr<int64_t>()[i];
      if (index < 0) index += size;
      y = y.select(dim, index);
      continue;
    }
    const int64_t start =
        (begin_mask & bit) ? 0 : clamp(b.data_ptr<int64_t>()[i]);
    const int64_t stop =
        (end_mask & bit) ? size : clamp(e.data_ptr<int64_t>()[i]);
    y = y.slice(dim, start, std::max(start, stop), stride);
    ++dim;
  }
  return y;
}

// The axes of a reduction (a scalar or a vector tensor), normalized.
std::vector<int64_t> ReductionAxes(const torch::Tensor& axes, int64_t rank) {
  torch::Tensor a = axes.to(torch::kLong).contiguous().reshape({-1});
  std::vector<int64_t> dims;
  for (int64_t i = 0; i < a.numel(); ++i)
    dims.push_back(NormalizeAxis(a.data_ptr<int64_t>()[i], rank));
  return dims;
}

std::vector<int64_t> ToSizes(const torch::Tensor& t) {
  torch::Tensor a = t.to(torch::kLong).contiguous().reshape({-1});
  return std::vector<int64_t>(a.data_ptr<int64_t>(),
                              a.data_ptr<int64_t>() + a.numel());
}

}  // namespace

const std::vector<std::string>& TfjsGraphModel::SupportedOps() {
  // clang-format off
  static const std::vector<std::string> ops = {
      // MoveNet single pose.
      "Const", "Placeholder", "Identity", "Cast", "Unpack", "ExpandDims",
      "Squeeze", "Reshape", "Sub", "Mul", "AddV2", "RealDiv", "FloorDiv",
      "SquaredDifference", "Sqrt", "Sigmoid", "_FusedConv2D",
      "FusedDepthwiseConv2dNative", "DepthwiseConv2dNative", "ResizeBilinear",
      "ArgMax", "Pack", "ConcatV2", "GatherNd",
      // MoveNet MultiPose adds these.
      "Shape", "Size", "StridedSlice", "MaxPool", "Abs", "Exp", "Reciprocal",
      "Minimum", "Maximum", "Less", "Greater", "GreaterEqual", "Equal",
      "LogicalAnd", "Range", "Tile", "Fill", "TopKV2", "AddN", "Split", "Max",
      "Sum", "Select"};
  // clang-format on
  return ops;
}

TfjsGraphModel TfjsGraphModel::Load(const std::string& model_json_path) {
  // Outline: parse the JSON, read the weight shards into constants, decode
  // each node's inputs and attributes, order the nodes the output needs.
  TfjsGraphModel model;
  model.path_ = model_json_path;
  const std::string& file = model_json_path;
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(ReadFileText(file));
  } catch (const nlohmann::json::exception& error) {
    throw InputError(file,
                     std::string("not a TF.js model.json: ") + error.what());
  }
  if (!json.contains("modelTopology") || !json.contains("weightsManifest") ||
      !json["modelTopology"].contains("node")) {
    throw InputError(file,
                     "not a TF.js graph model (no modelTopology.node or "
                     "weightsManifest)");
  }

  // Weights: the manifest's groups, each a list of shard files holding its
  // tensors back to back (float32 quantized to float16, or int32).
  std::unordered_map<std::string, torch::Tensor> weights;
  const std::filesystem::path folder =
      std::filesystem::path(file).parent_path();
  for (const nlohmann::json& group : json["weightsManifest"]) {
    std::string bytes;
    for (const nlohmann::json& shard : group["paths"]) {
      const std::string shard_path =
          (folder / shard.get<std::string>()).string();
      if (!std::filesystem::exists(shard_path))
        throw InputError(file, "weight file " + shard_path + " is missing");
      bytes += ReadFileText(shard_path);
    }
    size_t offset = 0;
    for (const nlohmann::json& spec : group["weights"]) {
      const std::string name = spec["name"];
      std::vector<int64_t> shape = spec["shape"].get<std::vector<int64_t>>();
      int64_t count = 1;
      for (int64_t d : shape) count *= d;
      const torch::ScalarType dtype = DtypeOf(spec["dtype"], file);
      torch::ScalarType stored = dtype;
      if (spec.contains("quantization")) {
        const std::string quantized = spec["quantization"]["dtype"];
        if (quantized != "float16") {
          throw InputError(file, "weight " + name + ": quantization '" +
                                     quantized + "' is not supported");
        }
        stored = torch::kHalf;
      }
      const size_t size = count * torch::elementSize(stored);
      if (offset + size > bytes.size()) {
        throw InputError(file, "the weight files end before weight " + name +
                                   " (" + std::to_string(bytes.size()) +
                                   " bytes): damaged or truncated");
      }
      torch::Tensor tensor =
          torch::from_blob(bytes.data() + offset, shape, stored)
              .to(dtype)
              .clone();
      weights[name] = tensor;
      offset += size;
    }
    if (offset != bytes.size()) {
      throw InputError(
          file, "the weight files hold " + std::to_string(bytes.size()) +
                    " bytes; the manifest describes " + std::to_string(offset));
    }
  }

  // Nodes.
  const nlohmann::json& nodes = json["modelTopology"]["node"];
  std::unordered_map<std::string, int> index;
  for (const nlohmann::json& n : nodes) {
    Node node;
    node.name = n.at("name");
    node.op = n.at("op");
    index[node.name] = static_cast<int>(model.nodes_.size());
    model.nodes_.push_back(node);
  }
  const std::vector<std::string>& supported = SupportedOps();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const nlohmann::json& n = nodes[i];
    Node& node = model.nodes_[i];
    if (std::find(supported.begin(), supported.end(), node.op) ==
        supported.end()) {
      throw InputError(file, "node " + node.name + ": op '" + node.op +
                                 "' is not supported by this interpreter");
    }
    for (const nlohmann::json& input :
         n.value("input", nlohmann::json::array())) {
      std::string ref = input;
      if (!ref.empty() && ref[0] == '^') continue;  // control dependency
      int output = 0;
      const size_t colon = ref.rfind(':');
      if (colon != std::string::npos) {
        output = std::stoi(ref.substr(colon + 1));
        ref = ref.substr(0, colon);
      }
      auto found = index.find(ref);
      if (found == index.end())
        throw InputError(file, "node " + node.name + " reads unknown " + ref);
      node.inputs.push_back({found->second, output});
    }
    const nlohmann::json attr = n.value("attr", nlohmann::json::object());
    node.strides = IntList(attr, "strides");
    node.dilations = IntList(attr, "dilations");
    node.squeeze_dims = IntList(attr, "squeeze_dims");
    node.ksize = IntList(attr, "ksize");
    node.keep_dims = BoolAttr(attr, "keep_dims");
    node.begin_mask = IntAttr(attr, "begin_mask");
    node.end_mask = IntAttr(attr, "end_mask");
    node.new_axis_mask = IntAttr(attr, "new_axis_mask");
    node.shrink_axis_mask = IntAttr(attr, "shrink_axis_mask");
    if (IntAttr(attr, "ellipsis_mask") != 0)
      throw InputError(file, "node " + node.name + ": ellipsis_mask");
    if (node.op == "Split") node.num = IntAttr(attr, "num_split");
    if (attr.contains("padding"))
      node.padding = DecodeBase64(attr["padding"].value("s", ""));
    if (attr.contains("fused_ops")) {
      for (const nlohmann::json& s :
           attr["fused_ops"]["list"].value("s", nlohmann::json::array()))
        node.fused_ops.push_back(DecodeBase64(s));
    }
    if (attr.contains("data_format")) {
      const std::string format =
          DecodeBase64(attr["data_format"].value("s", ""));
      if (format != "NHWC")
        throw InputError(file, "node " + node.name + ": data format " + format);
    }
    if (!node.padding.empty() && node.padding != "SAME" &&
        node.padding != "VALID") {
      throw InputError(file, "node " + node.name + ": padding " + node.padding);
    }
    node.axis = IntAttr(attr, "axis");
    if (node.op == "Unpack") node.num = IntAttr(attr, "num");
    if (node.op == "Cast")
      node.cast_to = DtypeOf(attr["DstT"]["type"].get<std::string>(), file);
    node.align_corners = BoolAttr(attr, "align_corners");
    node.half_pixel_centers = BoolAttr(attr, "half_pixel_centers");
    if (node.op == "Const") {
      auto weight = weights.find(node.name);
      if (weight == weights.end())
        throw InputError(file, "constant " + node.name + " has no weight");
      model.constants_[node.name] = weight->second;
    }
    if (node.op == "Placeholder") {
      if (model.input_node_ >= 0)
        throw InputError(file, "more than one input (Placeholder)");
      model.input_node_ = static_cast<int>(i);
      model.input_dtype_ =
          DtypeOf(attr["dtype"]["type"].get<std::string>(), file);
      for (const nlohmann::json& dim : attr["shape"]["shape"]["dim"])
        model.input_shape_.push_back(std::stoll(dim.value("size", "-1")));
    }
  }
  if (model.input_node_ < 0) throw InputError(file, "the graph has no input");

  // The output: the signature's, else the node named Identity.
  std::string output_name = "Identity";
  if (json.contains("signature") && json["signature"].contains("outputs")) {
    const nlohmann::json& outputs = json["signature"]["outputs"];
    if (outputs.size() != 1)
      throw InputError(file, "the model has " + std::to_string(outputs.size()) +
                                 " outputs; one is supported");
    output_name = outputs.begin().value().value("name", "Identity:0");
    output_name = output_name.substr(0, output_name.rfind(':'));
  }
  auto output = index.find(output_name);
  if (output == index.end())
    throw InputError(file, "the output node " + output_name + " is missing");

  // Order: depth-first from the output, inputs before their readers.
  std::vector<int> order, state(model.nodes_.size(), 0);
  std::function<void(int)> visit = [&](int i) {
    if (state[i] == 2) return;
    if (state[i] == 1) throw InputError(file, "the graph has a cycle");
    state[i] = 1;
    for (const auto& [input, _] : model.nodes_[i].inputs) visit(input);
    state[i] = 2;
    order.push_back(i);
  };
  visit(output->second);
  std::vector<Node> ordered;
  std::vector<int> new_index(model.nodes_.size(), -1);
  for (int i : order) {
    new_index[i] = static_cast<int>(ordered.size());
    ordered.push_back(model.nodes_[i]);
  }
  for (Node& node : ordered)
    for (auto& input : node.inputs) input.first = new_index[input.first];
  model.input_node_ = new_index[model.input_node_];
  model.output_node_ = static_cast<int>(ordered.size()) - 1;
  model.nodes_ = std::move(ordered);
  return model;
}

torch::Tensor TfjsGraphModel::Run(const torch::Tensor& input) const {
  c10::InferenceMode inference;
  if (input.scalar_type() != input_dtype_ ||
      input.dim() != static_cast<int64_t>(input_shape_.size())) {
    throw InputError(path_, "the input must be a " +
                                std::to_string(input_shape_.size()) +
                                "-d tensor of the model's dtype");
  }
  for (size_t d = 0; d < input_shape_.size(); ++d) {
    if (input_shape_[d] >= 0 && input.size(d) != input_shape_[d]) {
      throw InputError(path_, "input dimension " + std::to_string(d) + " is " +
                                  std::to_string(input.size(d)) +
                                  "; the model takes " +
                                  std::to_string(input_shape_[d]));
    }
  }
  std::vector<std::vector<torch::Tensor>> values(nodes_.size());
  std::vector<torch::Tensor> inputs;
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const Node& node = nodes_[i];
    inputs.clear();
    for (const auto& [from, output] : node.inputs) {
      if (output >= static_cast<int>(values[from].size())) {
        throw InputError(path_, "node " + node.name + " reads output " +
                                    std::to_string(output) + " of " +
                                    nodes_[from].name + ", which has " +
                                    std::to_string(values[from].size()));
      }
      inputs.push_back(values[from][output]);
    }
    values[i] = Execute(node, inputs, input);
  }
  return values[output_node_].at(0).contiguous();
}

std::vector<torch::Tensor> TfjsGraphModel::Execute(
    const Node& node, const std::vector<torch::Tensor>& in,
    const torch::Tensor& graph_input) const {
  const std::string& op = node.op;
  auto arity = [&](size_t n) {
    if (in.size() < n)
      throw InputError(path_, "node " + node.name + " (" + op + ") has " +
                                  std::to_string(in.size()) + " inputs");
  };
  if (op == "Const") return {constants_.at(node.name)};
  if (op == "Placeholder") return {graph_input};
  if (op == "Identity") return {in.at(0)};
  if (op == "Cast") return {in.at(0).to(node.cast_to)};
  if (op == "Unpack") {
    std::vector<torch::Tensor> parts =
        torch::unbind(in.at(0), NormalizeAxis(node.axis, in[0].dim()));
    return parts;
  }
  if (op == "ExpandDims") {
    arity(2);
    const int64_t dim = NormalizeAxis(in[1].item<int64_t>(), in[0].dim() + 1);
    return {in[0].unsqueeze(dim)};
  }
  if (op == "Squeeze") {
    torch::Tensor x = in.at(0);
    std::vector<int64_t> dims = node.squeeze_dims;
    for (int64_t& d : dims) d = NormalizeAxis(d, x.dim());
    std::sort(dims.rbegin(), dims.rend());
    if (dims.empty()) return {x.squeeze()};
    for (int64_t d : dims) x = x.squeeze(d);
    return {x};
  }
  if (op == "Reshape") {
    arity(2);
    torch::Tensor shape = in[1].to(torch::kLong).contiguous();
    std::vector<int64_t> sizes(shape.data_ptr<int64_t>(),
                               shape.data_ptr<int64_t>() + shape.numel());
    return {in[0].reshape(sizes)};
  }
  if (op == "Sub") {
    arity(2);
    return {in[0] - in[1]};
  }
  if (op == "Mul") {
    arity(2);
    return {in[0] * in[1]};
  }
  if (op == "AddV2") {
    arity(2);
    return {in[0] + in[1]};
  }
  if (op == "RealDiv") {
    arity(2);
    return {in[0] / in[1]};
  }
  if (op == "FloorDiv") {
    arity(2);
    return {FloorDivide(in[0], in[1])};
  }
  if (op == "SquaredDifference") {
    arity(2);
    torch::Tensor d = in[0] - in[1];
    return {d * d};
  }
  if (op == "Sqrt") return {torch::sqrt(in.at(0))};
  if (op == "Sigmoid") return {torch::sigmoid(in.at(0))};
  if (op == "_FusedConv2D") {
    arity(2);
    // Filter HWIO -> OIHW.
    torch::Tensor weight = in[1].permute({3, 2, 0, 1}).contiguous();
    torch::Tensor bias = in.size() > 2 ? in[2] : torch::Tensor();
    torch::Tensor out = ConvNhwc(in[0], weight, bias, node.strides,
                                 node.dilations, node.padding, 1);
    return {ApplyFusedActivations(out, node.fused_ops)};
  }
  if (op == "FusedDepthwiseConv2dNative" || op == "DepthwiseConv2dNative") {
    arity(2);
    // Filter [H, W, C, M] -> [C*M, 1, H, W], groups C.
    const torch::Tensor& filter = in[1];
    const int64_t channels = filter.size(2), multiplier = filter.size(3);
    torch::Tensor weight =
        filter.permute({2, 3, 0, 1})
            .reshape({channels * multiplier, 1, filter.size(0), filter.size(1)})
            .contiguous();
    torch::Tensor bias = (op == "FusedDepthwiseConv2dNative" && in.size() > 2)
                             ? in[2]
                             : torch::Tensor();
    torch::Tensor out = ConvNhwc(in[0], weight, bias, node.strides,
                                 node.dilations, node.padding, channels);
    return {ApplyFusedActivations(out, node.fused_ops)};
  }
  if (op == "ResizeBilinear") {
    arity(2);
    torch::Tensor size = in[1].to(torch::kLong).contiguous();
    const std::vector<int64_t> out_size = {size.data_ptr<int64_t>()[0],
                                           size.data_ptr<int64_t>()[1]};
    if (!node.half_pixel_centers && !node.align_corners) {
      throw InputError(path_, "node " + node.name +
                                  ": ResizeBilinear without half-pixel "
                                  "centres is not supported");
    }
    torch::Tensor nchw = in[0].to(torch::kFloat).permute({0, 3, 1, 2});
    torch::Tensor out =
        F::interpolate(nchw, F::InterpolateFuncOptions()
                                 .size(out_size)
                                 .mode(torch::kBilinear)
                                 .align_corners(node.align_corners));
    return {out.permute({0, 2, 3, 1})};
  }
  if (op == "ArgMax") {
    arity(2);
    const int64_t dim = NormalizeAxis(in[1].item<int64_t>(), in[0].dim());
    return {torch::argmax(in[0], dim).to(torch::kInt)};
  }
  if (op == "Pack") {
    return {torch::stack(in, NormalizeAxis(node.axis, in.at(0).dim() + 1))};
  }
  if (op == "ConcatV2") {
    arity(2);
    std::vector<torch::Tensor> parts(in.begin(), in.end() - 1);
    const int64_t axis =
        NormalizeAxis(in.back().item<int64_t>(), parts[0].dim());
    return {torch::cat(parts, axis)};
  }
  if (op == "GatherNd") {
    arity(2);
    return {GatherNd(in[0], in[1])};
  }
  // MoveNet MultiPose's ops.
  if (op == "Shape") {
    std::vector<int32_t> sizes(in.at(0).sizes().begin(), in[0].sizes().end());
    return {torch::tensor(sizes, torch::kInt)};
  }
  if (op == "Size")
    return {torch::tensor(static_cast<int32_t>(in.at(0).numel()), torch::kInt)};
  if (op == "StridedSlice") {
    arity(4);
    return {StridedSlice(in[0], in[1], in[2], in[3], node.begin_mask,
                         node.end_mask, node.new_axis_mask,
                         node.shrink_axis_mask, path_ + " node " + node.name)};
  }
  if (op == "MaxPool") {
    torch::Tensor nchw = in.at(0).permute({0, 3, 1, 2});
    const int64_t kh = node.ksize.at(1), kw = node.ksize.at(2);
    const int64_t sh = node.strides.at(1), sw = node.strides.at(2);
    if (node.padding == "SAME") {
      const auto [top, bottom] = SamePadding(nchw.size(2), kh, sh, 1);
      const auto [left, right] = SamePadding(nchw.size(3), kw, sw, 1);
      nchw = F::pad(nchw, F::PadFuncOptions({left, right, top, bottom})
                              .value(-std::numeric_limits<float>::infinity()));
    }
    return {torch::max_pool2d(nchw, {kh, kw}, {sh, sw}).permute({0, 2, 3, 1})};
  }
  if (op == "Abs") return {torch::abs(in.at(0))};
  if (op == "Exp") return {torch::exp(in.at(0))};
  if (op == "Reciprocal") return {torch::reciprocal(in.at(0))};
  if (op == "Minimum") {
    arity(2);
    return {torch::minimum(in[0], in[1])};
  }
  if (op == "Maximum") {
    arity(2);
    return {torch::maximum(in[0], in[1])};
  }
  if (op == "Less") {
    arity(2);
    return {torch::lt(in[0], in[1])};
  }
  if (op == "Greater") {
    arity(2);
    return {torch::gt(in[0], in[1])};
  }
  if (op == "GreaterEqual") {
    arity(2);
    return {torch::ge(in[0], in[1])};
  }
  if (op == "Equal") {
    arity(2);
    return {torch::eq(in[0], in[1])};
  }
  if (op == "LogicalAnd") {
    arity(2);
    return {torch::logical_and(in[0], in[1])};
  }
  if (op == "Range") {
    arity(3);
    const torch::ScalarType dtype = in[0].scalar_type();
    return {torch::arange(in[0].item<double>(), in[1].item<double>(),
                          in[2].item<double>(), torch::TensorOptions(dtype))};
  }
  if (op == "Tile") {
    arity(2);
    return {in[0].repeat(ToSizes(in[1]))};
  }
  if (op == "Fill") {
    arity(2);
    return {torch::full(ToSizes(in[0]), in[1].item(),
                        torch::TensorOptions(in[1].scalar_type()))};
  }
  if (op == "TopKV2") {
    arity(2);
    auto [values, indices] =
        torch::topk(in[0], in[1].item<int64_t>(), -1, true, true);
    return {values, indices.to(torch::kInt)};
  }
  if (op == "AddN") {
    torch::Tensor sum = in.at(0);
    for (size_t i = 1; i < in.size(); ++i) sum = sum + in[i];
    return {sum};
  }
  if (op == "Split") {
    arity(2);  // split_dim, value
    const int64_t axis = NormalizeAxis(in[0].item<int64_t>(), in[1].dim());
    return torch::chunk(in[1], node.num, axis);
  }
  if (op == "Max" || op == "Sum") {
    arity(2);
    const std::vector<int64_t> axes = ReductionAxes(in[1], in[0].dim());
    if (op == "Sum") return {torch::sum(in[0], axes, node.keep_dims)};
    return {torch::amax(in[0], axes, node.keep_dims)};
  }
  if (op == "Select") {
    arity(3);
    torch::Tensor condition = in[0];
    // TF's Select: a vector condition picks whole rows of higher-rank values.
    while (condition.dim() < in[1].dim()) condition = condition.unsqueeze(-1);
    return {torch::where(condition, in[1], in[2])};
  }
  throw InputError(path_, "node " + node.name + ": op '" + op +
                              "' is not supported by this interpreter");
}

}  // namespace m2d
