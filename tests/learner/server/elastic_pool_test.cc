// The elastic actor pool: what the gateway grants, how it tells an actor
// that owes segments from one waiting for a grant, when a stalled one
// expires, and when the learner's plan closes, waits for or raises a batch.

#include <ATen/ATen.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "common/rollout/horizon_pacer.h"
#include "common/rollout/segment.h"
#include "common/rollout/segment_queue.h"
#include "gtest/gtest.h"
#include "learner/server/elastic_batch_plan.h"
#include "learner/service/actor_gateway.h"
#include "proto/run_config.pb.h"
#include "proto/wire_format.h"
#include "tests/fakes/pendulum_spec.h"

namespace vantage {
namespace {

constexpr int64_t kSteps = 5;  // per segment, and per horizon of a slot

PolicyWeights Weights(int64_t version) {
  NetworkConfig network;
  network.hidden = {4};
  PolicyNetwork policy(PendulumSpec(), network);
  return ExportPolicyWeights(*policy, RunningMeanStd(kPendulumObservationSize),
                             version);
}

pb::Segment SegmentOf(int64_t actor_id, int64_t slot, int64_t version,
                      int64_t sequence) {
  Segment segment;
  segment.actor_id = actor_id;
  segment.env_slot = slot;
  segment.sequence = sequence;
  segment.policy_version = version;
  segment.observations =
      at::zeros({kSteps + 1, kPendulumObservationSize}, at::kFloat);
  segment.actions = at::zeros({kSteps, kPendulumActionSize}, at::kFloat);
  segment.rewards = at::zeros({kSteps}, at::kFloat);
  segment.terminated = at::zeros({kSteps}, at::kBool);
  segment.truncated = at::zeros({kSteps}, at::kBool);
  segment.final_observations =
      at::zeros({0, kPendulumObservationSize}, at::kFloat);
  segment.behaviour_log_probs = at::zeros({kSteps}, at::kFloat);
  pb::Segment proto;
  SegmentToProto(segment, &proto);
  return proto;
}

class ElasticPoolTest : public ::testing::Test {
 protected:
  ~ElasticPoolTest() override {
    gateway_->Close();
    queue_.Close();
  }

  // A learner whose batch is `batch` rollouts of one 5-step segment.
  void Start(int64_t batch, int64_t lead = 0) {
    GatewayConfig config;
    config.run_config.mutable_training()->set_horizon(kSteps);
    config.spec = PendulumSpec();
    config.max_segment_steps = kSteps;
    config.max_policy_lag = lead == 0 ? 0 : 4;
    config.batch_rollouts = batch;
    config.horizon_steps = kSteps;
    config.lead = lead;
    config.stall_timeout = absl::Seconds(10);
    gateway_ = std::make_unique<ActorGateway>(config, queue_);
  }

  // Registers an actor of `slots` env slots, with a call open unless
  // `attach` is false; returns its id.
  int64_t Join(int64_t slots, bool attach = true,
               const std::string& name = "pool-actor") {
    pb::RegisterRequest request;
    EnvSpecToProto(PendulumSpec(), request.mutable_spec());
    request.set_actor_name(name);
    request.set_num_envs(static_cast<int32_t>(slots));
    absl::StatusOr<pb::RegisterResponse> response =
        gateway_->Register(request, "10.0.0.7", absl::Seconds(5));
    EXPECT_TRUE(response.ok()) << response.status();
    if (attach) EXPECT_TRUE(gateway_->Attach(response->session()).ok());
    return response->actor_id();
  }

  // Actor `id` sends one horizon of each of its `slots` slots at `version`.
  void SendHorizon(int64_t id, int64_t slots, int64_t version) {
    for (int64_t slot = 0; slot < slots; ++slot) {
      ASSERT_TRUE(
          gateway_->Admit(id, SegmentOf(id, slot, version, sequence_[id]++))
              .ok());
    }
  }

  // A sync learner of a 4-rollout batch at version 0 and two live actors of
  // two env slots each (the run's plan); returns their ids.
  std::pair<int64_t, int64_t> StartSyncPool() {
    Start(/*batch=*/4);
    gateway_->Publish(Weights(0));
    const int64_t a = Join(2);
    return {a, Join(2)};
  }
  // Its plan, raising without a grace.
  ElasticBatchPlan SyncPlan() {
    return ElasticBatchPlan(
        *gateway_, /*sync=*/true, 4, /*planned_slots=*/4, [] { return 0; },
        absl::ZeroDuration());
  }

  int64_t Horizons() {
    return gateway_->WaitForWeightsNewerThan(-1, absl::ZeroDuration())
        ->horizons();
  }

  SegmentQueue queue_{1024, /*checked=*/true};
  std::unique_ptr<ActorGateway> gateway_;
  std::map<int64_t, int64_t> sequence_;
};

TEST(HorizonPacerTest, ASyncActorActsItsGrantWithEachVersion) {
  HorizonPacer pacer(0);
  EXPECT_EQ(pacer.Credit(0, 2), 2);
  pacer.Add(0, 1);
  pacer.Add(0, 1);
  EXPECT_EQ(pacer.Credit(0, 2), 0);
  EXPECT_EQ(pacer.Credit(0, 3), 1);  // a raise of the same version
  EXPECT_EQ(pacer.Credit(1, 2), 2);  // a new version
}

TEST(HorizonPacerTest, AnAsynchronousActorLeadsWithinItsWindow) {
  HorizonPacer pacer(2);
  EXPECT_EQ(pacer.Credit(0, 1), 3);  // (1 + lead) horizons ahead
  for (int i = 0; i < 3; ++i) pacer.Add(0, 1);
  EXPECT_EQ(pacer.Credit(0, 1), 0);
  EXPECT_EQ(pacer.Credit(1, 1), 0);  // versions 0 and 1 are in the window
  EXPECT_EQ(pacer.Credit(3, 1), 3);  // version 0 left it
  pacer.Add(3, 2);
  EXPECT_EQ(pacer.At(0), 0);  // forgotten
  EXPECT_EQ(pacer.Credit(3, 1), 1);
}

TEST_F(ElasticPoolTest, EachVersionGrantsTheLiveSlotsWhatFillsTheBatch) {
  Start(/*batch=*/8);
  gateway_->Publish(Weights(0));
  EXPECT_EQ(Horizons(), 1);  // nobody live yet
  const int64_t a = Join(2);
  Join(2);
  Join(4, /*attach=*/false);  // registered, but no call open: not live
  gateway_->Publish(Weights(1));
  EXPECT_EQ(Horizons(), 2);  // 8 rollouts over 4 live slots
  PoolView pool = gateway_->Pool();
  ASSERT_EQ(pool.members.size(), 2u);
  EXPECT_EQ(pool.live_env_slots(), 4);
  EXPECT_EQ(pool.members[0].owed_steps, 2 * 2 * kSteps);
  SendHorizon(a, 2, 1);
  EXPECT_EQ(gateway_->Pool().members[0].owed_steps, 2 * kSteps);
  gateway_->Grant(1, 3);
  EXPECT_EQ(Horizons(), 3);
  gateway_->Grant(0, 7);  // an old version's grant is ignored
  EXPECT_EQ(Horizons(), 3);
  gateway_->Detach(a);
  gateway_->Publish(Weights(2));
  EXPECT_EQ(Horizons(), 4);  // 8 over the 2 slots still live
  const int64_t c = Join(6);
  gateway_->Publish(Weights(3));
  EXPECT_EQ(Horizons(), 1);  // 8 slots: one each, a batch of 8
  EXPECT_EQ(gateway_->Pool().members.back().actor_id, c);
}

TEST_F(ElasticPoolTest, AnActorThatOwesSegmentsAndSendsNoneExpiresAsStalled) {
  Start(/*batch=*/2);
  gateway_->Publish(Weights(0));
  const int64_t sender = Join(1);
  // A name is the client's: the log gets it printable.
  const int64_t silent = Join(1, true, "pool-actor\nlearner: forged");
  SendHorizon(sender, 1, 0);  // its whole grant: it owes nothing
  const absl::Time now = absl::Now();
  EXPECT_TRUE(gateway_->ExpireStalled(now).empty());
  const std::vector<StalledActor> stalled =
      gateway_->ExpireStalled(now + absl::Seconds(11));
  ASSERT_EQ(stalled.size(), 1u);
  EXPECT_EQ(stalled[0].actor_id, silent);
  EXPECT_EQ(stalled[0].name, "pool-actor?learner: forged");
  EXPECT_EQ(stalled[0].peer, "10.0.0.7");
  EXPECT_EQ(stalled[0].owed_steps, kSteps);
  const GatewayCounters counters = gateway_->counters();
  EXPECT_EQ(counters.stalls, 1);
  EXPECT_EQ(counters.live_actors, 1);
  // The learner frees what it buffered for it, as for any expiry.
  EXPECT_EQ(gateway_->ExpireIdle(now), std::vector<int64_t>{silent});
  // Its session ends: it must register again.
  EXPECT_TRUE(
      absl::IsNotFound(gateway_->Admit(silent, SegmentOf(silent, 0, 0, 0))));
}

TEST_F(ElasticPoolTest, AWaitingActorIsNoStallNorIsANewGrantAtOnce) {
  Start(/*batch=*/1);
  gateway_->Publish(Weights(0));
  const int64_t a = Join(1);
  SendHorizon(a, 1, 0);
  const absl::Time later = absl::Now() + absl::Seconds(30);
  EXPECT_TRUE(gateway_->ExpireStalled(later).empty());  // owes nothing
  // A new version: owed again, but silent only since the grant.
  gateway_->Publish(Weights(1));
  EXPECT_TRUE(gateway_->ExpireStalled(absl::Now() + absl::Seconds(5)).empty());
  EXPECT_EQ(gateway_->ExpireStalled(absl::Now() + absl::Seconds(11)).size(),
            1u);
}

TEST_F(ElasticPoolTest, ASyncBatchWaitsForEveryLiveActorThenClosesTheGrant) {
  const auto [a, b] = StartSyncPool();
  ElasticBatchPlan plan = SyncPlan();
  EXPECT_EQ(plan.BatchSize(0, {{a, 2}}, 2), 0);  // b owes its horizon
  // A newcomer during the version takes the grant in force and is waited
  // for: the batch grows.
  const int64_t c = Join(1);
  EXPECT_EQ(plan.BatchSize(0, {{a, 2}, {b, 2}}, 4), 0);
  EXPECT_EQ(plan.BatchSize(0, {{a, 2}, {b, 2}, {c, 1}}, 5), 5);
  EXPECT_EQ(Horizons(), 0);  // late joiners wait for the next version
  EXPECT_EQ(plan.raises(), 0);
}

TEST_F(ElasticPoolTest, ASyncBatchShortOfActorsRaisesTheGrant) {
  const auto [a, b] = StartSyncPool();
  ElasticBatchPlan plan = SyncPlan();
  gateway_->Detach(b);  // b left after sending one of its slots' rollouts
  EXPECT_EQ(plan.BatchSize(0, {{a, 2}, {b, 1}}, 3), 0);
  EXPECT_EQ(Horizons(), 2);  // a's two slots act one more horizon each
  EXPECT_EQ(plan.raises(), 1);
  EXPECT_EQ(plan.BatchSize(0, {{a, 3}, {b, 1}}, 4), 0);  // a owes one more
  EXPECT_EQ(plan.BatchSize(0, {{a, 4}, {b, 1}}, 5), 5);  // b's stay in
}

TEST_F(ElasticPoolTest, ARaiseWaitsOutTheGraceWhileFewerSlotsThanPlannedLive) {
  Start(/*batch=*/4);
  gateway_->Publish(Weights(0));
  const int64_t a = Join(2);
  ElasticBatchPlan plan(
      *gateway_, /*sync=*/true, 4, /*planned_slots=*/4, [] { return 0; },
      absl::Seconds(30));
  // The run's second actor may still be starting.
  EXPECT_EQ(plan.BatchSize(0, {{a, 2}}, 2), 0);
  EXPECT_EQ(Horizons(), 1);
  EXPECT_EQ(plan.raises(), 0);
}

TEST_F(ElasticPoolTest, AnAsynchronousBatchTakesTheOldestAndRaisesWhenAllWait) {
  Start(/*batch=*/4, /*lead=*/2);
  gateway_->Publish(Weights(0));
  const int64_t a = Join(1);
  int64_t queued = 0;
  ElasticBatchPlan plan(
      *gateway_, /*sync=*/false, 4, /*planned_slots=*/1, [&] { return queued; },
      absl::ZeroDuration());
  EXPECT_EQ(plan.BatchSize(0, {{a, 5}}, 5), 4);  // the rest waits
  // a has sent its (1 + 2) horizons: with the queue drained, more.
  for (int i = 0; i < 3; ++i) SendHorizon(a, 1, 0);
  queued = 2;
  EXPECT_EQ(plan.BatchSize(0, {{a, 1}}, 1), 0);
  EXPECT_EQ(Horizons(), 1);  // the intake has yet to receive what is queued
  queued = 0;
  EXPECT_EQ(plan.BatchSize(0, {{a, 3}}, 3), 0);
  EXPECT_EQ(Horizons(), 2);
}

}  // namespace
}  // namespace vantage
