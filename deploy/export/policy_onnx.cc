#include "deploy/export/policy_onnx.h"

#include <ATen/ATen.h>
#include <onnx/checker.h>
#include <onnx/onnx_pb.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/nn/distributions.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"

namespace vantage {
namespace {

// Opset 10: Clip's bounds are still attributes there (inputs from 11 on,
// which OpenCV's importer, among others, does not read).
constexpr int64_t kOpset = 10;

// Adds nodes and initialisers to a graph, each output a fresh name.
class GraphBuilder {
 public:
  explicit GraphBuilder(onnx::GraphProto& graph) : graph_(graph) {}

  std::string Floats(const std::string& name, const at::Tensor& values) {
    const at::Tensor data = values.detach().to(at::kFloat).contiguous();
    onnx::TensorProto* tensor = graph_.add_initializer();
    tensor->set_name(Fresh(name));
    tensor->set_data_type(onnx::TensorProto::FLOAT);
    for (int64_t size : data.sizes()) tensor->add_dims(size);
    tensor->set_raw_data(data.data_ptr<float>(), data.numel() * sizeof(float));
    return tensor->name();
  }

  std::string Int64s(const std::string& name,
                     const std::vector<int64_t>& values) {
    onnx::TensorProto* tensor = graph_.add_initializer();
    tensor->set_name(Fresh(name));
    tensor->set_data_type(onnx::TensorProto::INT64);
    tensor->add_dims(static_cast<int64_t>(values.size()));
    for (int64_t v : values) tensor->add_int64_data(v);
    return tensor->name();
  }

  // A node of `op` on `inputs`; its output is named `output` if given.
  onnx::NodeProto& Node(const std::string& op,
                        const std::vector<std::string>& inputs,
                        const std::string& output = "") {
    onnx::NodeProto* node = graph_.add_node();
    node->set_op_type(op);
    node->set_name(Fresh(op));
    for (const std::string& input : inputs) node->add_input(input);
    node->add_output(output.empty() ? Fresh(op + "_out") : output);
    return *node;
  }
  static std::string Out(const onnx::NodeProto& node) { return node.output(0); }

  static void Ints(onnx::NodeProto& node, const std::string& name,
                   const std::vector<int64_t>& values) {
    onnx::AttributeProto* attribute = node.add_attribute();
    attribute->set_name(name);
    if (values.size() == 1 && name != "strides" && name != "kernel_shape") {
      attribute->set_type(onnx::AttributeProto::INT);
      attribute->set_i(values[0]);
      return;
    }
    attribute->set_type(onnx::AttributeProto::INTS);
    for (int64_t v : values) attribute->add_ints(v);
  }

  static void Floats(onnx::NodeProto& node, const std::string& name,
                     float value) {
    onnx::AttributeProto* attribute = node.add_attribute();
    attribute->set_name(name);
    attribute->set_type(onnx::AttributeProto::FLOAT);
    attribute->set_f(value);
  }

  void Value(google::protobuf::RepeatedPtrField<onnx::ValueInfoProto>* into,
             const std::string& name, int32_t type,
             const std::vector<int64_t>& dims) {
    onnx::ValueInfoProto* value = into->Add();
    value->set_name(name);
    onnx::TypeProto::Tensor* tensor =
        value->mutable_type()->mutable_tensor_type();
    tensor->set_elem_type(type);
    onnx::TensorShapeProto* shape = tensor->mutable_shape();
    for (int64_t d : dims) {
      // -1: the batch, of any size.
      if (d < 0) {
        shape->add_dim()->set_dim_param("batch");
      } else {
        shape->add_dim()->set_dim_value(d);
      }
    }
  }

 private:
  std::string Fresh(const std::string& stem) {
    return absl::StrCat(stem, "_", next_++);
  }

  onnx::GraphProto& graph_;
  int next_ = 0;
};

// Linear layers with tanh between them (none after the last), as TanhMlp.
std::string AddMlp(GraphBuilder& g, const TanhMlp& mlp, std::string x) {
  const torch::nn::ModuleList& layers = mlp->layers();
  for (size_t i = 0; i < layers->size(); ++i) {
    const auto& linear = layers->at<torch::nn::LinearImpl>(i);
    onnx::NodeProto& gemm = g.Node(
        "Gemm",
        {x, g.Floats("weight", linear.weight), g.Floats("bias", linear.bias)});
    GraphBuilder::Ints(gemm, "transB", {1});
    x = GraphBuilder::Out(gemm);
    if (i + 1 < layers->size()) x = GraphBuilder::Out(g.Node("Tanh", {x}));
  }
  return x;
}

// The convolutions, flattening and dense layer of ConvTorsoImpl, ReLU after
// each, on flat rows reshaped to [batch, C, H, W].
std::string AddConvTorso(GraphBuilder& g, const ConvTorso& torso,
                         const std::vector<int64_t>& shape, std::string x) {
  // 0: the batch as it comes (a -1 would be inferred, which OpenCV's
  // importer gets wrong before a Concat with another entry's features).
  x = GraphBuilder::Out(g.Node(
      "Reshape", {x, g.Int64s("shape", {0, shape[0], shape[1], shape[2]})}));
  for (const auto& module : torso->layers()->children()) {
    if (const auto* conv = module->as<torch::nn::Conv2dImpl>()) {
      onnx::NodeProto& node =
          g.Node("Conv", {x, g.Floats("conv_weight", conv->weight),
                          g.Floats("conv_bias", conv->bias)});
      GraphBuilder::Ints(
          node, "strides",
          {conv->options.stride()->at(0), conv->options.stride()->at(1)});
      GraphBuilder::Ints(node, "kernel_shape",
                         {conv->options.kernel_size()->at(0),
                          conv->options.kernel_size()->at(1)});
      x = GraphBuilder::Out(node);
    } else if (const auto* linear = module->as<torch::nn::LinearImpl>()) {
      onnx::NodeProto& gemm =
          g.Node("Gemm", {x, g.Floats("weight", linear->weight),
                          g.Floats("bias", linear->bias)});
      GraphBuilder::Ints(gemm, "transB", {1});
      x = GraphBuilder::Out(gemm);
    } else if (module->as<torch::nn::FlattenImpl>() != nullptr) {
      onnx::NodeProto& flatten = g.Node("Flatten", {x});
      GraphBuilder::Ints(flatten, "axis", {1});
      x = GraphBuilder::Out(flatten);
    } else {
      x = GraphBuilder::Out(g.Node("Relu", {x}));
    }
  }
  return x;
}

// (x - mean) / std, clipped to [-clip, clip] unless the clip is infinite
// (a run that does not normalise its observations passes them as they are).
std::string AddNormalise(GraphBuilder& g, const at::Tensor& mean,
                         const at::Tensor& std, double clip,
                         const std::string& x) {
  const std::string centred =
      GraphBuilder::Out(g.Node("Sub", {x, g.Floats("mean", mean)}));
  const std::string scaled =
      GraphBuilder::Out(g.Node("Div", {centred, g.Floats("std", std)}));
  if (!std::isfinite(clip)) return scaled;
  onnx::NodeProto& clipped = g.Node("Clip", {scaled});
  GraphBuilder::Floats(clipped, "min", static_cast<float>(-clip));
  GraphBuilder::Floats(clipped, "max", static_cast<float>(clip));
  return GraphBuilder::Out(clipped);
}

// The network's inputs from the environment's values: bytes divided by
// their high, other values normalised and clipped.
std::string AddInputs(GraphBuilder& g, const EnvSpec& spec,
                      const RunningMeanStd& normalizer, double clip,
                      const std::string& x) {
  if (spec.byte_observations()) {
    const double scale =
        1.0 / static_cast<double>(std::max<int64_t>(spec.observation_high, 1));
    return GraphBuilder::Out(g.Node(
        "Mul",
        {x, g.Floats("scale", at::tensor({static_cast<float>(scale)}))}));
  }
  return AddNormalise(g, normalizer.mean(), at::sqrt(normalizer.var() + 1e-8),
                      clip, x);
}

// A Dict observation's torso: each entry's slice of the row, vectors
// normalised and clipped with their slice of the normaliser, images divided
// by their high and through their own convolutional torso; the features
// side by side.
std::string AddDictTorso(GraphBuilder& g, const DictTorso& torso,
                         const RunningMeanStd& normalizer, double clip,
                         const std::string& x) {
  const at::Tensor mean = normalizer.mean();
  const at::Tensor std = at::sqrt(normalizer.var() + 1e-8);
  std::vector<std::string> features;
  int64_t offset = 0;
  for (size_t i = 0; i < torso->keys().size(); ++i) {
    const ObservationKey& key = torso->keys()[i];
    const int64_t end = offset + key.size;
    std::string part = GraphBuilder::Out(
        g.Node("Slice", {x, g.Int64s("starts", {offset}),
                         g.Int64s("ends", {end}), g.Int64s("axes", {1})}));
    if (key.image()) {
      part = GraphBuilder::Out(g.Node(
          "Mul",
          {part, g.Floats("inverse_high", at::tensor({1.0f / key.high}))}));
      part = AddConvTorso(g, torso->convs()[i], key.shape, part);
    } else {
      part = AddNormalise(g, mean.slice(0, offset, end),
                          std.slice(0, offset, end), clip, part);
    }
    features.push_back(part);
    offset = end;
  }
  onnx::NodeProto& concat = g.Node("Concat", features);
  GraphBuilder::Ints(concat, "axis", {1});
  return GraphBuilder::Out(concat);
}

// `x` clipped to the action bounds, dimension by dimension (an unbounded
// one as it is): max(x, low) = x + relu(low - x) and min(y, high) = y -
// relu(y - high), with masks for the unbounded sides. Relu, Add, Sub and
// Mul by constants, which every runtime reads (OpenCV's importer takes no
// constant operand to Max or Min).
std::string ClipToBounds(GraphBuilder& g, const EnvSpec& spec,
                         const std::string& x) {
  const int64_t k = spec.action_size;
  std::vector<float> low(k, 0.0f), high(k, 0.0f), has_low(k, 0.0f),
      has_high(k, 0.0f);
  for (int64_t j = 0; j < k; ++j) {
    if (std::isfinite(spec.action_low[j])) {
      low[j] = static_cast<float>(spec.action_low[j]);
      has_low[j] = 1.0f;
    }
    if (std::isfinite(spec.action_high[j])) {
      high[j] = static_cast<float>(spec.action_high[j]);
      has_high[j] = 1.0f;
    }
  }
  const auto out = [&](const std::string& op,
                       const std::vector<std::string>& inputs) {
    return GraphBuilder::Out(g.Node(op, inputs));
  };
  const std::string below =
      out("Relu",
          {out("Mul", {out("Sub", {x, g.Floats("action_low", at::tensor(low))}),
                       g.Floats("minus_one", at::tensor({-1.0f}))})});
  const std::string raised =
      out("Add",
          {x, out("Mul", {below, g.Floats("has_low", at::tensor(has_low))})});
  const std::string above =
      out("Relu",
          {out("Sub", {raised, g.Floats("action_high", at::tensor(high))})});
  return out("Sub",
             {raised,
              out("Mul", {above, g.Floats("has_high", at::tensor(has_high))})});
}

// Masked discrete actions: the logits with an illegal action's replaced by
// kIllegalLogit, as vantage scores and acts, from the input `action_mask`
// (1 legal, 0 illegal): logits * mask + (mask - 1) * 1e9.
std::string AddMask(GraphBuilder& g, onnx::GraphProto& graph,
                    const EnvSpec& spec, const std::string& logits) {
  g.Value(graph.mutable_input(), "action_mask", onnx::TensorProto::FLOAT,
          {-1, spec.action_size});
  const auto out = [&](const std::string& op,
                       const std::vector<std::string>& inputs) {
    return GraphBuilder::Out(g.Node(op, inputs));
  };
  const std::string kept = out("Mul", {logits, "action_mask"});
  const std::string illegal = out(
      "Mul", {out("Sub", {"action_mask", g.Floats("one", at::tensor({1.0f}))}),
              g.Floats("illegal", at::tensor({-kIllegalLogit}))});
  return out("Add", {kept, illegal});
}

// The most likely action: int64 [batch] for Discrete, [batch, heads] for
// MultiDiscrete (each head's slice of the logits in turn).
void AddDiscreteAction(GraphBuilder& g, onnx::GraphProto& graph,
                       const EnvSpec& spec, const std::string& output) {
  if (spec.action_nvec.empty()) {
    onnx::NodeProto& argmax = g.Node("ArgMax", {output}, "action");
    GraphBuilder::Ints(argmax, "axis", {1});
    GraphBuilder::Ints(argmax, "keepdims", {0});
    g.Value(graph.mutable_output(), "action", onnx::TensorProto::INT64, {-1});
    return;
  }
  std::vector<std::string> choices;
  int64_t offset = 0;
  for (int64_t n : spec.action_nvec) {
    const std::string head = GraphBuilder::Out(g.Node(
        "Slice", {output, g.Int64s("starts", {offset}),
                  g.Int64s("ends", {offset + n}), g.Int64s("axes", {1})}));
    onnx::NodeProto& argmax = g.Node("ArgMax", {head});
    GraphBuilder::Ints(argmax, "axis", {1});
    GraphBuilder::Ints(argmax, "keepdims", {1});
    choices.push_back(GraphBuilder::Out(argmax));
    offset += n;
  }
  GraphBuilder::Ints(g.Node("Concat", choices, "action"), "axis", {1});
  g.Value(graph.mutable_output(), "action", onnx::TensorProto::INT64,
          {-1, static_cast<int64_t>(spec.action_nvec.size())});
}

// The graph's outputs from the policy head's `output`.
void AddOutputs(GraphBuilder& g, onnx::GraphProto& graph, const EnvSpec& spec,
                PolicyNetworkImpl& policy, const std::string& output,
                bool distribution) {
  const int64_t k = spec.action_size;
  if (spec.discrete) {
    AddDiscreteAction(g, graph, spec, output);
    if (distribution) {
      g.Node("Identity", {output}, "logits");
      g.Value(graph.mutable_output(), "logits", onnx::TensorProto::FLOAT,
              {-1, k});
    }
    return;
  }
  g.Node("Identity", {ClipToBounds(g, spec, output)}, "action");
  g.Value(graph.mutable_output(), "action", onnx::TensorProto::FLOAT, {-1, k});
  if (distribution) {
    g.Node("Identity", {output}, "mean");
    // Per row ([batch, k], 0 * mean + log_std): a graph output computed
    // from the input, which runtimes that fold constants away still give.
    g.Node("Add",
           {GraphBuilder::Out(
                g.Node("Mul", {output, g.Floats("zero", at::tensor({0.0f}))})),
            g.Floats("log_std_value", policy.log_std())},
           "log_std");
    g.Value(graph.mutable_output(), "mean", onnx::TensorProto::FLOAT, {-1, k});
    g.Value(graph.mutable_output(), "log_std", onnx::TensorProto::FLOAT,
            {-1, k});
  }
}

}  // namespace

absl::StatusOr<std::string> PolicyToOnnx(const EnvSpec& spec,
                                         PolicyNetworkImpl& policy,
                                         const RunningMeanStd& normalizer,
                                         double observation_clip,
                                         const OnnxExportOptions& options) {
  if (policy.recurrent()) {
    return absl::UnimplementedError(absl::StrCat(
        "the policy has a recurrent core (", CoreName(policy.trunk()->core()),
        "), which export does not express: its state would be an input and "
        "an output of every step"));
  }
  at::NoGradGuard no_grad;
  onnx::ModelProto model;
  model.set_ir_version(onnx::IR_VERSION);
  model.set_producer_name("vantage");
  model.set_producer_version(options.producer_version);
  onnx::OperatorSetIdProto* opset = model.add_opset_import();
  opset->set_domain("");
  opset->set_version(kOpset);
  onnx::GraphProto& graph = *model.mutable_graph();
  graph.set_name(absl::StrCat(spec.name, " policy"));
  GraphBuilder g(graph);
  g.Value(graph.mutable_input(), "observation", onnx::TensorProto::FLOAT,
          {-1, spec.observation_size});
  std::string x =
      policy.dict_torso().is_empty()
          ? AddInputs(g, spec, normalizer, observation_clip, "observation")
          : AddDictTorso(g, policy.dict_torso(), normalizer, observation_clip,
                         "observation");
  if (!policy.conv_torso().is_empty()) {
    x = AddConvTorso(g, policy.conv_torso(), spec.observation_shape, x);
  }
  std::string output = AddMlp(g, policy.body(), x);
  if (spec.action_masks) output = AddMask(g, graph, spec, output);
  AddOutputs(g, graph, spec, policy, output, options.distribution);
  try {
    onnx::checker::check_model(model);
  } catch (const std::exception& error) {
    return absl::InternalError(
        absl::StrCat("ONNX's checker refused the model: ", error.what()));
  }
  return model.SerializeAsString();
}

}  // namespace vantage
