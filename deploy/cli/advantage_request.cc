#include "deploy/cli/advantage_request.h"

#include <ATen/ATen.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "proto/advantage.pb.h"

namespace vantage {
namespace {

absl::Status Missing(const char* key) {
  return absl::InvalidArgumentError(absl::StrCat("missing key '", key, "'"));
}

template <typename List>
absl::Status CheckLength(const List& list, const char* key, int steps) {
  if (list.size() != steps) {
    return absl::InvalidArgumentError(absl::StrCat(
        "'", key, "' has ", list.size(), " entries but 'rewards' has ", steps));
  }
  return absl::OkStatus();
}

absl::Status CheckFinite(double value, const char* key) {
  if (!std::isfinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("'", key, "' must be a finite number, got ", value));
  }
  return absl::OkStatus();
}

template <typename List>
absl::Status CheckFiniteList(const List& list, const char* key) {
  for (int i = 0; i < list.size(); ++i) {
    if (!std::isfinite(list[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "'", key, "'[", i, "] must be a finite number, got ", list[i]));
    }
  }
  return absl::OkStatus();
}

template <typename List>
at::Tensor ColumnTensor(const List& list, at::ScalarType dtype) {
  at::Tensor column = at::empty({static_cast<int64_t>(list.size()), 1}, dtype);
  if (dtype == at::kBool) {
    std::copy(list.begin(), list.end(), column.data_ptr<bool>());
  } else {
    std::copy(list.begin(), list.end(), column.data_ptr<double>());
  }
  return column;
}

template <typename Field>
void AppendColumn(const at::Tensor& tensor, Field* field) {
  const at::Tensor flat = tensor.reshape({-1}).to(at::kDouble).contiguous();
  const double* data = flat.data_ptr<double>();
  field->Add(data, data + flat.numel());
}

absl::Status CheckPresent(const pb::AdvantageRequest& message) {
  if (!message.has_gamma()) return Missing("gamma");
  if (!message.has_lambda()) return Missing("lambda");
  if (message.ensemble().empty()) return Missing("ensemble");
  if (!message.has_statistic()) return Missing("statistic");
  if (!message.has_rho()) return Missing("rho");
  if (!message.has_seed()) return Missing("seed");
  if (message.rewards().empty()) return Missing("rewards");
  if (message.values().empty()) return Missing("values");
  if (message.terminated().empty()) return Missing("terminated");
  if (message.truncated().empty()) return Missing("truncated");
  if (message.truncation_values().empty()) return Missing("truncation_values");
  if (!message.has_last_value()) return Missing("last_value");
  return absl::OkStatus();
}

absl::Status CheckLengthsAndNumbers(const pb::AdvantageRequest& message) {
  const int steps = message.rewards_size();
  for (absl::Status status :
       {CheckLength(message.values(), "values", steps),
        CheckLength(message.terminated(), "terminated", steps),
        CheckLength(message.truncated(), "truncated", steps),
        CheckLength(message.truncation_values(), "truncation_values", steps),
        CheckFinite(message.gamma(), "gamma"),
        CheckFinite(message.lambda(), "lambda"),
        CheckFinite(message.rho(), "rho"),
        CheckFinite(message.last_value(), "last_value"),
        CheckFiniteList(message.rewards(), "rewards"),
        CheckFiniteList(message.values(), "values"),
        CheckFiniteList(message.truncation_values(), "truncation_values")}) {
    if (!status.ok()) return status;
  }
  return absl::OkStatus();
}

absl::StatusOr<AdvantageConfig> ConfigOf(const pb::AdvantageRequest& message) {
  AdvantageConfig config;
  config.gamma = message.gamma();
  config.lambda = message.lambda();
  config.rho = message.rho();
  config.ensemble.assign(message.ensemble().begin(), message.ensemble().end());
  absl::StatusOr<Statistic> statistic = ParseStatistic(message.statistic());
  if (!statistic.ok()) return statistic.status();
  config.statistic = *statistic;
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  return config;
}

absl::StatusOr<AdvantageInputs> InputsOf(const pb::AdvantageRequest& message) {
  AdvantageInputs in;
  in.rewards = ColumnTensor(message.rewards(), at::kDouble);
  in.values = ColumnTensor(message.values(), at::kDouble);
  in.terminated = ColumnTensor(message.terminated(), at::kBool);
  in.truncated = ColumnTensor(message.truncated(), at::kBool);
  in.truncation_values = ColumnTensor(message.truncation_values(), at::kDouble);
  in.last_values = at::full({1}, message.last_value(), at::kDouble);
  if (absl::Status status = ValidateAdvantageInputs(in); !status.ok()) {
    return status;
  }
  return in;
}

}  // namespace

absl::StatusOr<AdvantageRequest> ParseAdvantageRequest(
    const std::string& json) {
  pb::AdvantageRequest message;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto parsed =
      google::protobuf::util::JsonStringToMessage(json, &message, options);
  if (!parsed.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("invalid JSON input: ", parsed.message().as_string()));
  }
  if (absl::Status status = CheckPresent(message); !status.ok()) return status;
  if (absl::Status status = CheckLengthsAndNumbers(message); !status.ok()) {
    return status;
  }
  AdvantageRequest request;
  absl::StatusOr<AdvantageConfig> config = ConfigOf(message);
  if (!config.ok()) return config.status();
  request.config = *std::move(config);
  request.seed = message.seed();
  absl::StatusOr<AdvantageInputs> inputs = InputsOf(message);
  if (!inputs.ok()) return inputs.status();
  request.inputs = *std::move(inputs);
  return request;
}

std::string AdvantagesToJson(const Advantages& advantages) {
  pb::AdvantageResponse response;
  AppendColumn(advantages.gae, response.mutable_gae());
  AppendColumn(advantages.biased, response.mutable_biased());
  AppendColumn(advantages.mixed, response.mutable_mixed());
  AppendColumn(advantages.returns, response.mutable_returns());
  const at::Tensor mask = advantages.mask.reshape({-1}).contiguous();
  for (int64_t i = 0; i < mask.numel(); ++i) {
    response.add_mask(mask.data_ptr<bool>()[i] ? 1 : 0);
  }
  google::protobuf::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  // Printing a message we built ourselves cannot fail.
  (void)google::protobuf::util::MessageToJsonString(response, &json, options);
  return json;
}

}  // namespace vantage
