#include "deploy/cli/export_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/run/trained_policy.h"

ABSL_FLAG(bool, distribution, false,
          "export: also output the action distribution's parameters (mean "
          "and log_std, or logits)");

namespace vantage {
namespace {

int Fail(int code, const std::string& message) {
  return CommandFailure("export", code, message);
}

// Writes `bytes` to a temporary file beside `path`, then renames it: a
// reader never sees half a model, and a failed write leaves no file.
absl::Status WriteWhole(const std::string& path, const std::string& bytes) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return absl::UnavailableError(absl::StrCat("cannot write ", path));
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    return absl::UnavailableError(absl::StrCat("cannot write ", path));
  }
  return absl::OkStatus();
}

int RunExport(const std::vector<std::string>&) {
  const std::string checkpoint = absl::GetFlag(FLAGS_checkpoint);
  const std::string out = absl::GetFlag(FLAGS_out);
  if (checkpoint.empty()) return Fail(kUsageError, "--checkpoint is required");
  if (out.empty()) return Fail(kUsageError, "--out=FILE.onnx is required");
  absl::StatusOr<TrainedPolicy> trained = LoadTrainedPolicy(checkpoint);
  if (!trained.ok()) {
    return Fail(kUsageError, absl::StrCat("--checkpoint=", checkpoint, ": ",
                                          trained.status().message()));
  }
  absl::StatusOr<std::string> model =
      trained->OnnxModel(absl::GetFlag(FLAGS_distribution));
  if (!model.ok()) {
    return Fail(kUsageError, absl::StrCat(trained->checkpoint_path, ": ",
                                          model.status().message()));
  }
  if (absl::Status status = WriteWhole(out, *model); !status.ok()) {
    return Fail(kRuntimeError, std::string(status.message()));
  }
  std::printf("export: %s (policy version %ld of %s, %zu bytes)\n", out.c_str(),
              static_cast<long>(trained->version),
              trained->checkpoint_path.c_str(), model->size());
  return 0;
}

}  // namespace

Command ExportCommand() {
  Command command;
  command.name = "export";
  command.summary = "a trained policy as an ONNX model";
  command.usage = "vantage export --checkpoint=RUN --out=FILE.onnx [flags]";
  command.description =
      "Writes the policy of a run directory's newest checkpoint (or of a\n"
      "checkpoint file) as an ONNX model (opset 10) that other programs run:\n"
      "input `observation` [batch, obs] as the environment gives it (the\n"
      "normaliser is inside), output `action`, the deterministic action (the\n"
      "Gaussian mean clipped to the action bounds, float [batch, k]; or the\n"
      "argmax, int64 [batch]); with --distribution also `mean` and `log_std`\n"
      "or `logits`. The model passes ONNX's checker before it is written.\n"
      "A policy it cannot express (a recurrent core) is refused by name\n"
      "(docs/export.md).";
  command.flags = {"checkpoint", "out", "distribution"};
  command.example = "vantage export --checkpoint=runs/hopper --out=hopper.onnx";
  command.run = RunExport;
  return command;
}

}  // namespace vantage
