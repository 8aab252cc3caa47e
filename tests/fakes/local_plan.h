#ifndef VANTAGE_TESTS_FAKES_LOCAL_PLAN_H_
#define VANTAGE_TESTS_FAKES_LOCAL_PLAN_H_

#include "deploy/run/run_config.h"
#include "deploy/run/run_plan.h"
#include "gtest/gtest.h"
#include "proto/run_config.pb.h"

namespace vantage {

// The plan of `run` as a local run: resolved with every default as `vantage
// train --mode=local` resolves it, and planned. A config that does not
// resolve fails the test.
inline RunPlan LocalPlan(pb::RunConfig run) {
  run.set_mode("local");
  absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(run);
  EXPECT_TRUE(resolved.ok()) << resolved.status();
  if (!resolved.ok()) return RunPlan();
  absl::StatusOr<RunPlan> plan = PlanRun(*resolved);
  EXPECT_TRUE(plan.ok()) << plan.status();
  return plan.ok() ? *std::move(plan) : RunPlan();
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_LOCAL_PLAN_H_
