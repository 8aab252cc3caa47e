#include "learner/run/background_evaluator.h"

#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <utility>

namespace vantage {

BackgroundEvaluator::BackgroundEvaluator(EvaluatePolicy evaluate)
    : evaluate_(std::move(evaluate)), thread_([this] { Loop(); }) {}

BackgroundEvaluator::~BackgroundEvaluator() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void BackgroundEvaluator::Submit(PolicyWeights weights) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (waiting_.has_value()) {
      if (skipped_ == 0) {
        std::fprintf(stderr,
                     "learner: version %ld was not evaluated: version %ld "
                     "came while an evaluation was still running (the "
                     "evaluations take longer than --eval_every updates; "
                     "said once)\n",
                     static_cast<long>(waiting_->version),
                     static_cast<long>(weights.version));
      }
      ++skipped_;
    }
    waiting_ = std::move(weights);
  }
  wake_.notify_all();
}

std::vector<PolicyEvaluation> BackgroundEvaluator::TakeFinished() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<PolicyEvaluation> finished;
  finished.swap(finished_);
  return finished;
}

void BackgroundEvaluator::Drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return !busy_ && !waiting_.has_value(); });
}

int64_t BackgroundEvaluator::skipped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

void BackgroundEvaluator::Loop() {
  // Linux schedules each thread on its own: SCHED_IDLE runs it only when
  // nothing else wants the core (below even nice 19, which it falls back
  // to where the policy is refused).
  sched_param idle{};
  if (sched_setscheduler(0, SCHED_IDLE, &idle) != 0) {
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  }
  while (true) {
    PolicyWeights weights;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || waiting_.has_value(); });
      if (stopping_) return;
      weights = std::move(*waiting_);
      waiting_.reset();
      busy_ = true;
    }
    absl::StatusOr<PolicyEvaluation> evaluation = evaluate_(weights);
    if (!evaluation.ok()) {
      std::fprintf(stderr,
                   "learner: the evaluation of version %ld failed: %s\n",
                   static_cast<long>(weights.version),
                   std::string(evaluation.status().message()).c_str());
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (evaluation.ok()) finished_.push_back(*std::move(evaluation));
      busy_ = false;
    }
    wake_.notify_all();
  }
}

}  // namespace vantage
