#include "deploy/experiment/slurm_backend.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "deploy/experiment/experiment_directory.h"
#include "learner/run/run_directory.h"

namespace vantage {
namespace {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs a program (looked up on PATH) and collects what it prints.
absl::StatusOr<CommandResult> RunProgram(const std::vector<std::string>& args) {
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return absl::InternalError("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) return absl::InternalError("fork failed");
  if (pid == 0) {
    dup2(pipe_fds[1], STDOUT_FILENO);
    dup2(pipe_fds[1], STDERR_FILENO);
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    std::vector<char*> argv;
    for (const std::string& arg : args) {
      argv.push_back(const_cast<char*>(arg.c_str()));
    }
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    std::fprintf(stderr, "cannot run %s\n", argv[0]);
    _exit(127);
  }
  close(pipe_fds[1]);
  CommandResult result;
  char buffer[4096];
  ssize_t n;
  while ((n = read(pipe_fds[0], buffer, sizeof(buffer))) > 0) {
    result.output.append(buffer, static_cast<size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// One array task: the cell's command, appended to its log. A TERM (time
// limit, preemption, `scancel --signal=TERM --batch`) stops the run with a
// checkpoint and requeues the task, which then resumes it: the command is
// the same every time (--resume_if_exists).
constexpr char kArrayScript[] = R"(#!/usr/bin/env bash
# Written by `vantage experiment run --backend=slurm`: one cell per task.
set -uo pipefail
task="${VANTAGE_TASK_DIR}/${SLURM_ARRAY_TASK_ID}"
mapfile -t lines < "${task}"
log="${lines[0]}"
stopping=0
trap 'stopping=1; kill -TERM "${pid}" 2>/dev/null' TERM INT
"${VANTAGE_BIN}" "${lines[@]:1}" >> "${log}" 2>&1 &
pid=$!
wait "${pid}"
status=$?
while kill -0 "${pid}" 2>/dev/null; do wait "${pid}"; status=$?; done
if (( stopping )); then
  echo "slurm: task ${SLURM_ARRAY_TASK_ID} stopped; requeueing" >> "${log}"
  scontrol requeue "${SLURM_JOB_ID}"
  exit 0
fi
exit "${status}"
)";

std::string SelfPath() {
  std::error_code error;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? "vantage" : self.string();
}

class SlurmBackend : public ExperimentBackend {
 public:
  explicit SlurmBackend(const BackendOptions& options) : options_(options) {}

  std::vector<CellOutcome> Run(const std::vector<CellTask>& tasks,
                               const GridTotals& totals,
                               const std::atomic<bool>& stop) override {
    std::vector<CellOutcome> outcomes(tasks.size());
    if (tasks.empty()) return outcomes;
    absl::StatusOr<std::string> array = Submit(tasks);
    if (!array.ok()) {
      for (CellOutcome& outcome : outcomes) {
        outcome = {CellOutcome::Kind::kFailed,
                   std::string(array.status().message())};
      }
      return outcomes;
    }
    std::printf(
        "experiment: job array %s (%zu tasks); `scancel %s` stops them, each "
        "with a checkpoint\n",
        array->c_str(), tasks.size(), array->c_str());
    std::fflush(stdout);
    if (!WaitWhileQueued(*array, tasks, totals, stop)) {
      // The array belongs to the cluster now: it goes on without us.
      for (size_t i = 0; i < tasks.size(); ++i) {
        outcomes[i] = {CellOutcome::Kind::kStopped,
                       absl::StrCat("still in job array ", *array)};
      }
      std::printf(
          "experiment: job array %s keeps running; run the same command "
          "again once it has left the queue (squeue)\n",
          array->c_str());
      return outcomes;
    }
    outcomes = EndedOutcomes(tasks);
    std::remove(ArrayIdPath().c_str());
    return outcomes;
  }

  // The array an earlier invocation submitted runs on without it; its cells
  // must not be inspected (a cell before its first checkpoint would be
  // cleared) nor submitted twice.
  absl::Status CheckIdle() override {
    std::ifstream file(ArrayIdPath());
    std::string id;
    if (!(file >> id)) return absl::OkStatus();
    absl::StatusOr<int> queued = QueuedTasks(id);
    if (!queued.ok()) return queued.status();
    if (*queued == 0) return absl::OkStatus();
    return absl::FailedPreconditionError(absl::StrCat(
        "job array ", id, " of this experiment still has ", *queued,
        " tasks in the queue; wait for it (squeue --jobs=", id,
        ") or stop it (scancel ", id, "), then run again"));
  }

 private:
  std::string ArrayIdPath() const { return options_.work_dir + "/array_id"; }

  std::string TaskDir() const { return options_.work_dir + "/tasks"; }
  std::string ScriptPath() const { return options_.work_dir + "/array.sbatch"; }

  // Polls the queue until the cluster holds none of the array's tasks
  // (true) or `stop` is set (false), with a line whenever the steps grew.
  static bool WaitWhileQueued(const std::string& array,
                              const std::vector<CellTask>& tasks,
                              const GridTotals& totals,
                              const std::atomic<bool>& stop) {
    int64_t last_steps = -1;
    while (true) {
      absl::StatusOr<int> queued = QueuedTasks(array);
      int64_t steps = totals.steps_before;
      int finished = 0;
      for (const CellTask& task : tasks) {
        const int64_t done = LastProgressSteps(task.run_dir);
        steps += done;
        finished += done >= task.steps ? 1 : 0;
      }
      if (steps != last_steps) {
        std::printf(
            "experiment: %d of %zu cells finished, %s queued, %ld of "
            "%ld steps\n",
            finished, tasks.size(),
            queued.ok() ? absl::StrCat(*queued).c_str() : "?",
            static_cast<long>(steps), static_cast<long>(totals.steps));
        std::fflush(stdout);
        last_steps = steps;
      }
      if (queued.ok() && *queued == 0) return true;
      if (stop) return false;
      std::this_thread::sleep_for(std::chrono::seconds(2));
    }
  }

  // Once the array has left the queue: each cell's progress.csv says
  // whether its task completed the run.
  static std::vector<CellOutcome> EndedOutcomes(
      const std::vector<CellTask>& tasks) {
    std::vector<CellOutcome> outcomes(tasks.size());
    for (size_t i = 0; i < tasks.size(); ++i) {
      const int64_t steps = LastProgressSteps(tasks[i].run_dir);
      if (steps >= tasks[i].steps) {
        outcomes[i] = {CellOutcome::Kind::kFinished, ""};
      } else {
        outcomes[i] = {
            CellOutcome::Kind::kFailed,
            absl::StrCat("task ended at ", steps, " of ", tasks[i].steps,
                         " steps; ", tasks[i].log_path, ": ",
                         LastLogLine(tasks[i].log_path))};
      }
    }
    return outcomes;
  }

  absl::StatusOr<std::string> Submit(const std::vector<CellTask>& tasks) const {
    if (absl::Status status = WriteTaskFiles(tasks); !status.ok()) {
      return status;
    }
    if (absl::Status status = WriteFileAtomically(ScriptPath(), kArrayScript);
        !status.ok()) {
      return status;
    }
    const std::string self = SelfPath();
    const std::string task_dir = TaskDir();
    if (absl::StrContains(self, ",") || absl::StrContains(task_dir, ",")) {
      // sbatch --export separates its variables with commas.
      return absl::InvalidArgumentError(absl::StrCat(
          "a path with a comma cannot reach the tasks through sbatch "
          "--export: ",
          self, " or ", task_dir));
    }
    absl::StatusOr<CommandResult> submitted =
        RunProgram(SbatchArgs(tasks, self));
    if (!submitted.ok()) return submitted.status();
    const std::string output(absl::StripAsciiWhitespace(submitted->output));
    if (submitted->exit_code != 0) {
      return absl::UnavailableError(
          absl::StrCat("sbatch refused the job array: ", output));
    }
    // --parsable: "JOBID" or "JOBID;CLUSTER".
    const std::string id = std::vector<std::string>(
        absl::StrSplit(output, absl::ByAnyChar(";\n")))[0];
    if (absl::Status status = WriteFileAtomically(ArrayIdPath(), id + "\n");
        !status.ok()) {
      return status;
    }
    return id;
  }

  // Task i's file: its log's path, then its command's arguments, a line
  // each (the array script reads them by the task's id).
  absl::Status WriteTaskFiles(const std::vector<CellTask>& tasks) const {
    const std::string task_dir = TaskDir();
    std::error_code error;
    std::filesystem::remove_all(task_dir, error);
    std::filesystem::create_directories(task_dir, error);
    if (error) {
      return absl::FailedPreconditionError(
          absl::StrCat("cannot create ", task_dir, ": ", error.message()));
    }
    for (size_t i = 0; i < tasks.size(); ++i) {
      std::string lines = absl::StrCat(tasks[i].log_path, "\n");
      for (const std::string& arg : tasks[i].repeatable_args) {
        absl::StrAppend(&lines, arg, "\n");
      }
      if (absl::Status status =
              WriteFileAtomically(absl::StrCat(task_dir, "/", i), lines);
          !status.ok()) {
        return status;
      }
    }
    return absl::OkStatus();
  }

  std::vector<std::string> SbatchArgs(const std::vector<CellTask>& tasks,
                                      const std::string& self) const {
    int cores = 1;
    for (const CellTask& task : tasks) cores = std::max(cores, task.cores);
    std::vector<std::string> args = {
        "sbatch",
        "--parsable",
        absl::StrCat("--array=0-", tasks.size() - 1, "%",
                     std::max(1, options_.jobs)),
        "--job-name=vantage-experiment",
        absl::StrCat("--output=", options_.work_dir, "/array-%A_%a.out"),
        "--open-mode=append",
        "--requeue",
        "--signal=B:TERM@120",
        "--ntasks=1",
        absl::StrCat("--cpus-per-task=", cores),
        absl::StrCat("--export=ALL,VANTAGE_BIN=", self,
                     ",VANTAGE_TASK_DIR=", TaskDir())};
    args.insert(args.end(), options_.scheduler_args.begin(),
                options_.scheduler_args.end());
    args.push_back(ScriptPath());
    return args;
  }

  // The array's tasks the cluster still holds (pending, running, requeued).
  static absl::StatusOr<int> QueuedTasks(const std::string& array) {
    absl::StatusOr<CommandResult> listed =
        RunProgram({"squeue", "--noheader", "--array",
                    absl::StrCat("--jobs=", array), "--format=%i %T"});
    if (!listed.ok()) return listed.status();
    if (listed->exit_code != 0) {
      // squeue refuses the id of a job that has left the queue.
      if (listed->output.find("Invalid job id") != std::string::npos) return 0;
      return absl::UnavailableError(absl::StrCat(
          "squeue failed: ", absl::StripAsciiWhitespace(listed->output)));
    }
    int count = 0;
    for (absl::string_view line :
         absl::StrSplit(listed->output, '\n', absl::SkipWhitespace())) {
      (void)line;
      ++count;
    }
    return count;
  }

  BackendOptions options_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeSlurmBackend(
    const BackendOptions& options) {
  return std::make_unique<SlurmBackend>(options);
}

}  // namespace vantage
