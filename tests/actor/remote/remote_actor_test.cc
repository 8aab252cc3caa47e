#include "actor/remote/remote_actor.h"

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "actor/envs/env_registry.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

// A learner that completes its run while an actor streams to it, the way a
// loaded machine can order it: the segment stream is cut by the shutdown
// first, and the subscription's word that the run is over comes
// `run_over_delay` later.
class CompletingLearner final : public pb::Learner::Service {
 public:
  explicit CompletingLearner(std::chrono::milliseconds run_over_delay)
      : run_over_delay_(run_over_delay) {}

  grpc::Status Register(grpc::ServerContext*, const pb::RegisterRequest*,
                        pb::RegisterResponse* response) override {
    ++registrations_;
    response->set_actor_id(registrations_ - 1);
    response->set_session("0:session");
    pb::TrainingSettings& training =
        *response->mutable_run_config()->mutable_training();
    training.set_seed(1);
    training.set_horizon(64);
    training.set_segment_length(16);
    training.add_hidden(8);
    training.set_torso("mlp");
    response->mutable_run_config()->mutable_distributed()->set_sync(true);
    const EnvSpec spec = (*MakeEnvironment("InvertedPendulum"))->spec();
    NetworkConfig network;
    network.hidden = {8};
    PolicyNetwork policy(spec, network);
    WeightsToProto(
        ExportPolicyWeights(*policy, RunningMeanStd(spec.observation_size), 0),
        response->mutable_weights());
    weights_ = response->weights();
    return grpc::Status::OK;
  }

  grpc::Status SubscribeWeights(
      grpc::ServerContext* context, const pb::WeightsRequest*,
      grpc::ServerWriter<pb::Weights>* writer) override {
    // As a learner does, the weights in force first.
    writer->Write(weights_);
    std::unique_lock<std::mutex> lock(mutex_);
    while (!cut_ && !context->IsCancelled()) {
      changed_.wait_for(lock, std::chrono::milliseconds(10));
    }
    lock.unlock();
    std::this_thread::sleep_for(run_over_delay_);
    return grpc::Status(grpc::StatusCode::OUT_OF_RANGE,
                        "the run is over: every step is done");
  }

  grpc::Status StreamSegments(grpc::ServerContext*,
                              grpc::ServerReader<pb::Segment>* reader,
                              pb::SegmentAck*) override {
    pb::Segment segment;
    reader->Read(&segment);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cut_ = true;
    }
    changed_.notify_all();
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the learner is shutting down");
  }

  int registrations() const { return registrations_; }

 private:
  const std::chrono::milliseconds run_over_delay_;
  std::atomic<int> registrations_{0};
  pb::Weights weights_;  // those of the last registration
  std::mutex mutex_;
  std::condition_variable changed_;
  bool cut_ = false;
};

TEST(RemoteActorTest, ExitsWhenTheRunIsOverThoughItsStreamWasCutFirst) {
  CompletingLearner learner(std::chrono::milliseconds(300));
  int port = 0;
  grpc::ServerBuilder builder;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(),
                           &port);
  builder.RegisterService(&learner);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);

  RemoteActorConfig config;
  config.learner = "127.0.0.1:" + std::to_string(port);
  config.name = "actor-under-test";
  // A reconnect would be the fault: the run is over, not the learner gone.
  config.max_reconnects = 0;
  std::atomic<bool> stop{false};
  const absl::Status status = RunRemoteActor(config, stop);
  EXPECT_TRUE(status.ok()) << status;
  EXPECT_EQ(learner.registrations(), 1);
  server->Shutdown(std::chrono::system_clock::now() +
                   std::chrono::milliseconds(100));
}

}  // namespace
}  // namespace vantage
