#include "common/advantage/advantage.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/advantage/estimator_kernels.h"

namespace vantage {
namespace {

std::string ShapeString(const at::Tensor& tensor) {
  return absl::StrCat("[", absl::StrJoin(tensor.sizes(), ", "), "]");
}

absl::Status CheckTensor(const at::Tensor& tensor, const char* name,
                         at::IntArrayRef shape, bool boolean) {
  if (!tensor.defined()) {
    return absl::InvalidArgumentError(absl::StrCat(name, " is missing"));
  }
  if (tensor.sizes() != shape) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " has shape ", ShapeString(tensor), ", expected [",
                     absl::StrJoin(shape, ", "), "]"));
  }
  const bool dtype_ok = boolean ? tensor.scalar_type() == at::kBool
                                : (tensor.scalar_type() == at::kFloat ||
                                   tensor.scalar_type() == at::kDouble);
  if (!dtype_ok) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " has dtype ", at::toString(tensor.scalar_type()),
                     ", expected ", boolean ? "Bool" : "Float or Double"));
  }
  if (!tensor.device().is_cpu()) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " must be a CPU tensor"));
  }
  return absl::OkStatus();
}

absl::Status CheckStructure(const AdvantageInputs& in) {
  if (!in.rewards.defined()) {
    return absl::InvalidArgumentError("rewards is missing");
  }
  if (in.rewards.dim() != 2 || in.rewards.size(0) < 1 ||
      in.rewards.size(1) < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("rewards must be a non-empty [T, N] tensor, got shape ",
                     ShapeString(in.rewards)));
  }
  const at::IntArrayRef shape = in.rewards.sizes();
  const int64_t streams = in.rewards.size(1);
  for (const auto& [tensor, name, boolean] :
       {std::make_tuple(&in.rewards, "rewards", false),
        std::make_tuple(&in.values, "values", false),
        std::make_tuple(&in.terminated, "terminated", true),
        std::make_tuple(&in.truncated, "truncated", true),
        std::make_tuple(&in.truncation_values, "truncation_values", false)}) {
    if (absl::Status status = CheckTensor(*tensor, name, shape, boolean);
        !status.ok()) {
      return status;
    }
  }
  return CheckTensor(in.last_values, "last_values", {streams}, false);
}

// The TD errors and continuation flags that every estimator shares,
// computed once from the inputs.
class PreparedRollout {
 public:
  static absl::StatusOr<PreparedRollout> Create(const AdvantageInputs& in,
                                                double gamma) {
    if (absl::Status status = CheckStructure(in); !status.ok()) return status;
    PreparedRollout prepared;
    prepared.gamma_ = gamma;
    prepared.steps_ = in.rewards.size(0);
    prepared.streams_ = in.rewards.size(1);
    const at::ScalarType dtype = in.rewards.scalar_type();
    prepared.delta_ =
        at::empty({prepared.steps_, prepared.streams_}, at::kDouble);
    prepared.continues_ = at::empty_like(prepared.delta_);
    if (dtype == at::kFloat) {
      prepared.Prepare<float>(in);
    } else {
      prepared.Prepare<double>(in);
    }
    return prepared;
  }

  at::Tensor Gae(double lambda) const {
    at::Tensor gae = NewOutput();
    if (gae.scalar_type() == at::kFloat) {
      GaeKernel(steps_, streams_, delta(), continues(), gamma_, lambda,
                gae.data_ptr<float>());
    } else {
      GaeKernel(steps_, streams_, delta(), continues(), gamma_, lambda,
                gae.data_ptr<double>());
    }
    return gae;
  }

  // `storage` keeps the arrays behind the returned pointers alive.
  PathEnsembleBasis Basis(at::Tensor* storage) const {
    *storage = at::empty({2, steps_, streams_}, at::kDouble);
    double* longest = storage->data_ptr<double>();
    double* remaining = longest + steps_ * streams_;
    ComputePathEnsembleBasis(steps_, streams_, delta(), continues(), gamma_,
                             longest, remaining);
    return PathEnsembleBasis{longest, remaining};
  }

  // The configured statistic; config.gamma must be this rollout's gamma.
  at::Tensor Biased(const AdvantageConfig& config) const {
    if (config.statistic.kind == StatisticKind::kGae) return Gae(config.lambda);
    std::vector<int64_t> ensemble = config.ensemble;
    std::sort(ensemble.begin(), ensemble.end());
    const at::Tensor basis = at::empty({2, steps_, streams_}, at::kDouble);
    double* longest = basis.data_ptr<double>();
    double* remaining = longest + steps_ * streams_;
    at::Tensor biased = NewOutput();
    if (biased.scalar_type() == at::kFloat) {
      EnsembleStatisticKernel(steps_, streams_, delta(), continues(), gamma_,
                              ensemble, config.statistic, longest, remaining,
                              biased.data_ptr<float>());
    } else {
      EnsembleStatisticKernel(steps_, streams_, delta(), continues(), gamma_,
                              ensemble, config.statistic, longest, remaining,
                              biased.data_ptr<double>());
    }
    return biased;
  }

  int64_t steps() const { return steps_; }
  int64_t streams() const { return streams_; }
  at::ScalarType output_dtype() const { return output_dtype_; }

 private:
  PreparedRollout() = default;

  template <typename Scalar>
  void Prepare(const AdvantageInputs& in) {
    output_dtype_ = in.rewards.scalar_type();
    // The float inputs in the rewards' dtype; no copies when they already are.
    const at::Tensor rewards = in.rewards.contiguous();
    const at::Tensor values = in.values.to(output_dtype_).contiguous();
    const at::Tensor truncation_values =
        in.truncation_values.to(output_dtype_).contiguous();
    const at::Tensor last_values =
        in.last_values.to(output_dtype_).contiguous();
    const at::Tensor terminated = in.terminated.contiguous();
    const at::Tensor truncated = in.truncated.contiguous();
    RolloutView<Scalar> view;
    view.steps = steps_;
    view.streams = streams_;
    view.rewards = rewards.data_ptr<Scalar>();
    view.values = values.data_ptr<Scalar>();
    view.terminated = terminated.data_ptr<bool>();
    view.truncated = truncated.data_ptr<bool>();
    view.truncation_values = truncation_values.data_ptr<Scalar>();
    view.last_values = last_values.data_ptr<Scalar>();
    ComputeTdErrors(view, gamma_, delta_.data_ptr<double>(),
                    continues_.data_ptr<double>());
  }

  at::Tensor NewOutput() const {
    return at::empty({steps_, streams_}, output_dtype_);
  }
  const double* delta() const { return delta_.data_ptr<double>(); }
  const double* continues() const { return continues_.data_ptr<double>(); }

  double gamma_ = 1.0;
  int64_t steps_ = 0;
  int64_t streams_ = 0;
  at::ScalarType output_dtype_ = at::kDouble;
  at::Tensor delta_;
  at::Tensor continues_;
};

absl::Status CheckFinite(const at::Tensor& tensor, const char* name) {
  const at::Tensor finite = at::isfinite(tensor);
  if (finite.all().item<bool>()) return absl::OkStatus();
  const at::Tensor first = at::nonzero(finite.logical_not())[0];
  return absl::InvalidArgumentError(absl::StrCat(
      name, " has a non-finite value at index [",
      absl::StrJoin(first.data_ptr<int64_t>(),
                    first.data_ptr<int64_t>() + first.numel(), ", "),
      "]"));
}

}  // namespace

absl::Status ValidateAdvantageInputs(const AdvantageInputs& inputs) {
  if (absl::Status status = CheckStructure(inputs); !status.ok()) {
    return status;
  }
  for (const auto& [tensor, name] :
       {std::make_pair(&inputs.rewards, "rewards"),
        std::make_pair(&inputs.values, "values"),
        std::make_pair(&inputs.last_values, "last_values")}) {
    if (absl::Status status = CheckFinite(*tensor, name); !status.ok()) {
      return status;
    }
  }
  // Only the entries at truncated steps are ever read.
  return CheckFinite(at::where(inputs.truncated, inputs.truncation_values,
                               at::zeros_like(inputs.truncation_values)),
                     "truncation_values (at a truncated step)");
}

absl::StatusOr<at::Tensor> ComputeGae(const AdvantageInputs& inputs,
                                      double gamma, double lambda) {
  absl::StatusOr<PreparedRollout> prepared =
      PreparedRollout::Create(inputs, gamma);
  if (!prepared.ok()) return prepared.status();
  return prepared->Gae(lambda);
}

absl::StatusOr<at::Tensor> ComputeKStepEstimates(
    const AdvantageInputs& inputs, double gamma,
    const std::vector<int64_t>& ks) {
  for (int64_t k : ks) {
    if (k < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("k-step estimates need k >= 1, got ", k));
    }
  }
  absl::StatusOr<PreparedRollout> prepared =
      PreparedRollout::Create(inputs, gamma);
  if (!prepared.ok()) return prepared.status();
  at::Tensor storage;
  const PathEnsembleBasis basis = prepared->Basis(&storage);
  const int64_t steps = prepared->steps();
  const int64_t streams = prepared->streams();
  at::Tensor estimates =
      at::empty({static_cast<int64_t>(ks.size()), steps, streams}, at::kDouble);
  for (size_t m = 0; m < ks.size(); ++m) {
    KStepKernel(basis, steps, streams, ks[m], gamma,
                estimates.data_ptr<double>() + m * steps * streams);
  }
  return estimates.to(prepared->output_dtype());
}

absl::StatusOr<at::Tensor> ComputeBiasedAdvantage(
    const AdvantageInputs& inputs, const AdvantageConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  absl::StatusOr<PreparedRollout> prepared =
      PreparedRollout::Create(inputs, config.gamma);
  if (!prepared.ok()) return prepared.status();
  return prepared->Biased(config);
}

at::Tensor DrawBiasMask(at::IntArrayRef shape, double rho,
                        std::mt19937_64& rng) {
  at::Tensor mask = at::empty(shape, at::kBool);
  bool* data = mask.data_ptr<bool>();
  for (int64_t i = 0; i < mask.numel(); ++i) {
    // 53 random bits give a uniform double in [0, 1): never below 0, always
    // below 1, so rho = 0 and rho = 1 are exact.
    const double uniform = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    data[i] = uniform < rho;
  }
  return mask;
}

absl::StatusOr<Advantages> ComputeAdvantages(const AdvantageInputs& inputs,
                                             const AdvantageConfig& config,
                                             std::mt19937_64& rng) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  absl::StatusOr<PreparedRollout> prepared =
      PreparedRollout::Create(inputs, config.gamma);
  if (!prepared.ok()) return prepared.status();
  Advantages out;
  out.gae = prepared->Gae(config.lambda);
  out.biased = config.statistic.kind == StatisticKind::kGae
                   ? out.gae
                   : prepared->Biased(config);
  out.mask = DrawBiasMask(out.gae.sizes(), config.rho, rng);
  // A select, not m*A + (1-m)*Â, so that unmasked samples are GAE bit for bit.
  out.mixed = at::where(out.mask, out.biased, out.gae);
  out.returns = inputs.values.to(out.gae.scalar_type()) + out.gae;
  return out;
}

}  // namespace vantage
