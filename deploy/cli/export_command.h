#ifndef VANTAGE_DEPLOY_CLI_EXPORT_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_EXPORT_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage export --checkpoint=RUN --out=policy.onnx`: a trained policy as
// an ONNX model (deploy/export/policy_onnx.h).
Command ExportCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_EXPORT_COMMAND_H_
