#ifndef VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_IO_H_
#define VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_IO_H_

// Typed reads and writes of LibTorch archives (the checkpoint format) that
// turn a missing or malformed entry into an error naming it.

#include <ATen/core/Tensor.h>

#include <string>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/nn/running_mean_std.h"

namespace torch::nn {
class Module;
}  // namespace torch::nn
namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

absl::Status ReadTensor(torch::serialize::InputArchive& archive,
                        const std::string& key, at::Tensor& tensor);

// Arbitrary bytes, stored as a uint8 tensor.
void WriteBytes(torch::serialize::OutputArchive& archive,
                const std::string& key, absl::string_view bytes);
absl::StatusOr<std::string> ReadBytes(torch::serialize::InputArchive& archive,
                                      const std::string& key);

void WriteRunningMeanStd(torch::serialize::OutputArchive& archive,
                         const std::string& key, const RunningMeanStd& stats);
// Checked like RunningMeanStd::Restore; `stats` is unchanged on error.
absl::Status ReadRunningMeanStd(torch::serialize::InputArchive& archive,
                                const std::string& key, RunningMeanStd& stats);

// A module's parameters and buffers, flat, as `key`.<name>. Loading
// checks every entry's presence, dtype, shape and finiteness before copying
// any, so on error the module is unchanged.
void WriteModule(torch::serialize::OutputArchive& archive,
                 const std::string& key, const torch::nn::Module& module);
absl::Status ReadModule(torch::serialize::InputArchive& archive,
                        const std::string& key, torch::nn::Module& module);

// Runs `read` and turns a LibTorch exception (a module or optimiser whose
// saved shapes do not fit, an archive whose TorchScript does not parse)
// into InvalidArgument naming `what`.
absl::Status CatchTorchErrors(absl::string_view what,
                              absl::FunctionRef<void()> read);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_IO_H_
