#include "learner/checkpoint/archive_io.h"

#include <ATen/ATen.h>
#include <torch/nn/module.h>
#include <torch/serialize/archive.h>

#include <exception>
#include <vector>

#include "absl/strings/str_cat.h"

namespace vantage {

absl::Status CatchTorchErrors(absl::string_view what,
                              absl::FunctionRef<void()> read) {
  try {
    read();
  } catch (const c10::Error& error) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": ", error.what_without_backtrace()));
  } catch (const std::exception& error) {
    // Not every LibTorch error is a c10::Error: the TorchScript parser that
    // reads an archive's code/ entries throws std::runtime_error.
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", error.what()));
  }
  return absl::OkStatus();
}

absl::Status ReadTensor(torch::serialize::InputArchive& archive,
                        const std::string& key, at::Tensor& tensor) {
  at::Tensor read;
  absl::Status status = CatchTorchErrors(
      absl::StrCat("checkpoint entry '", key, "' is missing or unreadable"),
      [&] { archive.read(key, read); });
  if (!status.ok()) return status;
  tensor = read;
  return absl::OkStatus();
}

void WriteBytes(torch::serialize::OutputArchive& archive,
                const std::string& key, absl::string_view bytes) {
  at::Tensor tensor =
      at::empty({static_cast<int64_t>(bytes.size())}, at::kByte);
  if (!bytes.empty()) {
    std::memcpy(tensor.data_ptr<uint8_t>(), bytes.data(), bytes.size());
  }
  archive.write(key, tensor);
}

absl::StatusOr<std::string> ReadBytes(torch::serialize::InputArchive& archive,
                                      const std::string& key) {
  at::Tensor tensor;
  if (absl::Status status = ReadTensor(archive, key, tensor); !status.ok()) {
    return status;
  }
  if (tensor.scalar_type() != at::kByte || tensor.dim() != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("checkpoint entry '", key, "' is not a byte string"));
  }
  tensor = tensor.contiguous();
  return std::string(reinterpret_cast<const char*>(tensor.data_ptr<uint8_t>()),
                     tensor.numel());
}

void WriteRunningMeanStd(torch::serialize::OutputArchive& archive,
                         const std::string& key, const RunningMeanStd& stats) {
  archive.write(key + ".count", at::tensor({stats.count()}, at::kDouble));
  archive.write(key + ".mean", stats.mean());
  archive.write(key + ".var", stats.var());
}

absl::Status ReadRunningMeanStd(torch::serialize::InputArchive& archive,
                                const std::string& key, RunningMeanStd& stats) {
  at::Tensor count, mean, var;
  for (auto [name, tensor] :
       {std::pair{".count", &count}, std::pair{".mean", &mean},
        std::pair{".var", &var}}) {
    if (absl::Status status = ReadTensor(archive, key + name, *tensor);
        !status.ok()) {
      return status;
    }
  }
  if (count.numel() != 1 || !count.is_floating_point()) {
    return absl::InvalidArgumentError(
        absl::StrCat("checkpoint entry '", key, ".count' is not one number"));
  }
  RunningMeanStd restored = stats;
  if (absl::Status status = restored.Restore(count.item<double>(), mean, var);
      !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("checkpoint entry '", key, "': ", status.message()));
  }
  stats = restored;
  return absl::OkStatus();
}

namespace {

// Parameters and buffers, by name.
std::vector<std::pair<std::string, at::Tensor>> ModuleTensors(
    const torch::nn::Module& module) {
  std::vector<std::pair<std::string, at::Tensor>> tensors;
  for (const auto& p : module.named_parameters()) {
    tensors.emplace_back(p.key(), p.value());
  }
  for (const auto& b : module.named_buffers()) {
    tensors.emplace_back(b.key(), b.value());
  }
  return tensors;
}

}  // namespace

void WriteModule(torch::serialize::OutputArchive& archive,
                 const std::string& key, const torch::nn::Module& module) {
  for (const auto& [name, tensor] : ModuleTensors(module)) {
    archive.write(key + "." + name, tensor.detach());
  }
}

absl::Status ReadModule(torch::serialize::InputArchive& archive,
                        const std::string& key, torch::nn::Module& module) {
  const auto tensors = ModuleTensors(module);
  std::vector<at::Tensor> read(tensors.size());
  for (size_t i = 0; i < tensors.size(); ++i) {
    const std::string entry = key + "." + tensors[i].first;
    if (absl::Status status = ReadTensor(archive, entry, read[i]);
        !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("checkpoint networks do not fit the configured ones: ",
                       status.message()));
    }
    if (read[i].scalar_type() != tensors[i].second.scalar_type() ||
        !read[i].sizes().equals(tensors[i].second.sizes())) {
      return absl::InvalidArgumentError(
          absl::StrCat("checkpoint networks do not fit the configured ones: '",
                       entry, "' has shape ", c10::str(read[i].sizes()),
                       ", the network ", c10::str(tensors[i].second.sizes())));
    }
    // A learner publishes what it loads, and never non-finite weights.
    if (read[i].is_floating_point() &&
        !at::isfinite(read[i]).all().item<bool>()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "checkpoint entry '", entry, "' holds non-finite values"));
    }
  }
  at::NoGradGuard no_grad;
  for (size_t i = 0; i < tensors.size(); ++i) {
    at::Tensor target = tensors[i].second;
    target.copy_(read[i]);
  }
  return absl::OkStatus();
}

}  // namespace vantage
