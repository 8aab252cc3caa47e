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

// The inputs as contiguous arrays in the rewards' dtype (no copies when they
// already are), ready for the kernels.
class RolloutArrays {
 public:
  explicit RolloutArrays(const AdvantageInputs& in)
      : dtype_(in.rewards.scalar_type()),
        rewards_(in.rewards.contiguous()),
        values_(in.values.to(dtype_).contiguous()),
        terminated_(in.terminated.contiguous()),
        truncated_(in.truncated.contiguous()),
        truncation_values_(in.truncation_values.to(dtype_).contiguous()),
        last_values_(in.last_values.to(dtype_).contiguous()) {}

  at::ScalarType dtype() const { return dtype_; }
  int64_t steps() const { return rewards_.size(0); }
  int64_t streams() const { return rewards_.size(1); }

  template <typename Scalar>
  RolloutView<Scalar> View() const {
    RolloutView<Scalar> view;
    view.steps = steps();
    view.streams = streams();
    view.rewards = rewards_.data_ptr<Scalar>();
    view.values = values_.data_ptr<Scalar>();
    view.terminated = terminated_.data_ptr<bool>();
    view.truncated = truncated_.data_ptr<bool>();
    view.truncation_values = truncation_values_.data_ptr<Scalar>();
    view.last_values = last_values_.data_ptr<Scalar>();
    return view;
  }

 private:
  at::ScalarType dtype_;
  at::Tensor rewards_;
  at::Tensor values_;
  at::Tensor terminated_;
  at::Tensor truncated_;
  at::Tensor truncation_values_;
  at::Tensor last_values_;
};

// Fills the requested tensors (undefined: not requested) in one pass. gae
// and biased take the inputs' dtype; basis is double [2, T, N].
struct RequestedOutputs {
  at::Tensor gae;
  at::Tensor biased;
  at::Tensor basis;
};

template <typename Scalar>
void RunTyped(const RolloutArrays& arrays, const EstimatorSettings& settings,
              RequestedOutputs* requested) {
  EstimatorOutputs<Scalar> outputs;
  if (requested->gae.defined()) outputs.gae = requested->gae.data_ptr<Scalar>();
  if (requested->biased.defined()) {
    outputs.biased = requested->biased.data_ptr<Scalar>();
  }
  if (requested->basis.defined()) {
    outputs.longest = requested->basis.data_ptr<double>();
    outputs.remaining = outputs.longest + arrays.steps() * arrays.streams();
  }
  RunEstimators(arrays.View<Scalar>(), settings, outputs);
}

// Computes what `want_gae` / `want_biased` / `want_basis` ask for.
RequestedOutputs Run(const RolloutArrays& arrays,
                     const EstimatorSettings& settings, bool want_gae,
                     bool want_biased, bool want_basis) {
  RequestedOutputs requested;
  const int64_t steps = arrays.steps();
  const int64_t streams = arrays.streams();
  if (want_gae) requested.gae = at::empty({steps, streams}, arrays.dtype());
  if (want_biased) {
    requested.biased = at::empty({steps, streams}, arrays.dtype());
  }
  if (want_biased || want_basis) {
    requested.basis = at::empty({2, steps, streams}, at::kDouble);
  }
  if (arrays.dtype() == at::kFloat) {
    RunTyped<float>(arrays, settings, &requested);
  } else {
    RunTyped<double>(arrays, settings, &requested);
  }
  return requested;
}

EstimatorSettings SettingsFor(const AdvantageConfig& config) {
  EstimatorSettings settings;
  settings.gamma = config.gamma;
  settings.lambda = config.lambda;
  settings.ensemble = config.ensemble;
  std::sort(settings.ensemble.begin(), settings.ensemble.end());
  settings.statistic = config.statistic;
  return settings;
}

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
  if (absl::Status status = CheckStructure(inputs); !status.ok()) {
    return status;
  }
  EstimatorSettings settings;
  settings.gamma = gamma;
  settings.lambda = lambda;
  return Run(RolloutArrays(inputs), settings, /*want_gae=*/true,
             /*want_biased=*/false, /*want_basis=*/false)
      .gae;
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
  if (absl::Status status = CheckStructure(inputs); !status.ok()) {
    return status;
  }
  const RolloutArrays arrays(inputs);
  EstimatorSettings settings;
  settings.gamma = gamma;
  const at::Tensor basis = Run(arrays, settings, /*want_gae=*/false,
                               /*want_biased=*/false, /*want_basis=*/true)
                               .basis;
  const int64_t steps = arrays.steps();
  const int64_t streams = arrays.streams();
  const double* longest = basis.data_ptr<double>();
  at::Tensor estimates =
      at::empty({static_cast<int64_t>(ks.size()), steps, streams}, at::kDouble);
  for (size_t m = 0; m < ks.size(); ++m) {
    KStepFromBasis(longest, longest + steps * streams, steps, streams, ks[m],
                   gamma, estimates.data_ptr<double>() + m * steps * streams);
  }
  return estimates.to(arrays.dtype());
}

absl::StatusOr<at::Tensor> ComputeBiasedAdvantage(
    const AdvantageInputs& inputs, const AdvantageConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (absl::Status status = CheckStructure(inputs); !status.ok()) {
    return status;
  }
  const bool unbiased = config.statistic.kind == StatisticKind::kGae;
  RequestedOutputs out = Run(RolloutArrays(inputs), SettingsFor(config),
                             /*want_gae=*/unbiased, /*want_biased=*/!unbiased,
                             /*want_basis=*/false);
  return unbiased ? out.gae : out.biased;
}

at::Tensor DrawBiasMask(at::IntArrayRef shape, double rho,
                        std::mt19937_64& rng) {
  // rho = 0 and rho = 1 need no randomness (and draw none).
  if (!(rho > 0.0)) return at::zeros(shape, at::kBool);
  if (!(rho < 1.0)) return at::ones(shape, at::kBool);
  at::Tensor mask = at::empty(shape, at::kBool);
  bool* data = mask.data_ptr<bool>();
  const int64_t count = mask.numel();
  // Each 64-bit draw gives two uniforms on the 2^-32 grid: m = u < rho.
  const double scale = 0x1.0p-32;
  for (int64_t i = 0; i < count; i += 2) {
    const uint64_t bits = rng();
    data[i] = static_cast<double>(bits >> 32) * scale < rho;
    if (i + 1 < count) {
      data[i + 1] = static_cast<double>(bits & 0xffffffffu) * scale < rho;
    }
  }
  return mask;
}

absl::StatusOr<Advantages> ComputeAdvantages(const AdvantageInputs& inputs,
                                             const AdvantageConfig& config,
                                             std::mt19937_64& rng) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (absl::Status status = CheckStructure(inputs); !status.ok()) {
    return status;
  }
  const bool unbiased = config.statistic.kind == StatisticKind::kGae;
  // GAE and the biased estimate share one pass over the rollout.
  RequestedOutputs computed =
      Run(RolloutArrays(inputs), SettingsFor(config), /*want_gae=*/true,
          /*want_biased=*/!unbiased, /*want_basis=*/false);
  Advantages out;
  out.gae = computed.gae;
  out.biased = unbiased ? computed.gae : computed.biased;
  out.mask = DrawBiasMask(out.gae.sizes(), config.rho, rng);
  // With no bias no sample takes the biased estimate, whatever rho says;
  // the mask is still drawn, so that the generator (and with it every
  // later minibatch) is where it was in runs made before this held.
  if (unbiased) out.mask.zero_();
  // A select, not m*A + (1-m)*Â, so that unmasked samples are GAE bit for bit.
  out.mixed = at::where(out.mask, out.biased, out.gae);
  out.returns = inputs.values.to(out.gae.scalar_type()) + out.gae;
  return out;
}

}  // namespace vantage
