#ifndef VANTAGE_DEPLOY_CLI_RUN_REQUEST_H_
#define VANTAGE_DEPLOY_CLI_RUN_REQUEST_H_

// A training run as `vantage train` and `vantage learner` are asked for it
// (a config file, the flags given on top, or a run to resume), and the one
// resolved configuration that comes out.

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "deploy/run/run_plan.h"
#include "learner/run/progress_columns.h"
#include "learner/run/run_directory.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct RunRequest {
  // The fields whose flags were given (command line, --flagfile,
  // --fromenv); the others stay absent and take the defaults.
  pb::RunConfig flags;
  std::vector<std::string> given_flags;  // their names, for messages
  // --algo, if given: it switches a config file's algorithm (dropping the
  // file's settings of the other one); else the flags' algorithm settings
  // must be the file's algorithm's.
  std::string algo;
  // --exploration, if given: none drops a config file's exploration
  // section; a method selects it (with the file's settings of it, if any).
  std::string exploration;
  std::string config_file;  // --config: JSON RunConfig under the flags
  // A config already read, used instead of reading `config_file` (which
  // then only names it in messages).
  std::optional<pb::RunConfig> config;
  std::string run_dir;  // --run_dir: where the run is recorded
  std::string resume;   // --resume: a run directory to continue
  // --resume_if_exists: `run_dir` may hold this run already (continued).
  bool resume_if_exists = false;
};

struct ResolvedRun {
  pb::RunConfig config;  // every field set
  RunPlan plan;          // of `config`, with the request's run directory
  // --resume_if_exists found this run in its directory before its first
  // checkpoint: the directory is cleared and the run starts over.
  bool start_over = false;
};

// The config file (if any) under the given flags, or the resumed run's own
// config.json (then no flag may change it), resolved and checked. With
// resume_if_exists, a run directory holding a run resolved the same way is
// resumed (or started over, before its first checkpoint). Every error is
// the request's: InvalidArgument or NotFound naming the flag or file.
absl::StatusOr<ResolvedRun> ResolveRunRequest(const RunRequest& request);

// `RESULT train env=.. algo=.. estimator=.. rho=.. steps=.. mean_return=..
// elapsed_s=.. sps=..` on stdout, the line scripts and tests read.
void PrintTrainResult(const pb::RunConfig& config, const ProgressRow& last);
// `RUN_DIR is finished already (S steps); nothing to do` on stdout: what a
// resumed run with no update left says instead (a requeued job or a
// restarted pod repeats its command after the end).
void PrintFinishedAlready(const ResolvedRun& run);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_RUN_REQUEST_H_
