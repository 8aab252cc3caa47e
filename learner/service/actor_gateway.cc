#include "learner/service/actor_gateway.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

std::chrono::nanoseconds ToChrono(absl::Duration d) {
  return absl::ToChronoNanoseconds(d);
}

}  // namespace

ActorGateway::ActorGateway(GatewayConfig config, SegmentSink& sink)
    : config_(std::move(config)),
      sink_(sink),
      next_actor_id_(config_.first_actor_id) {}

absl::StatusOr<pb::RegisterResponse> ActorGateway::Register(
    const pb::RegisterRequest& request, absl::Duration timeout) {
  absl::StatusOr<EnvSpec> spec = EnvSpecFromProto(request.spec());
  if (!spec.ok()) return spec.status();
  if (!config_.run_config.env().empty() &&
      spec->name != config_.run_config.env()) {
    return absl::InvalidArgumentError(absl::StrCat("this learner trains ",
                                                   config_.run_config.env(),
                                                   ", not ", spec->name));
  }
  int64_t actor_id = 0;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (closed_) return absl::UnavailableError("the learner is shutting down");
    if (spec_.has_value()) {
      if (absl::Status status = CheckSameSpec(*spec_, *spec); !status.ok()) {
        return status;
      }
    } else {
      spec_ = *spec;
      changed_.notify_all();
    }
    actor_id = next_actor_id_++;
    actors_.insert(actor_id);
    ++counters_.registrations;
  }
  std::shared_ptr<const pb::Weights> weights =
      WaitForWeightsNewerThan(-1, timeout);
  if (weights == nullptr) {
    return absl::UnavailableError(
        "the learner has published no weights yet; retry");
  }
  pb::RegisterResponse response;
  response.set_actor_id(actor_id);
  *response.mutable_run_config() = config_.run_config;
  *response.mutable_weights() = *weights;
  return response;
}

absl::Status ActorGateway::Reject(const std::string& reason,
                                  absl::Status status) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.rejected[reason];
  return status;
}

absl::Status ActorGateway::Admit(const pb::Segment& proto,
                                 std::string* dropped) {
  if (dropped != nullptr) dropped->clear();
  int64_t newest = -1;
  std::optional<EnvSpec> spec;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (actors_.count(proto.actor_id()) == 0) {
      ++counters_.rejected["unknown_actor"];
      return absl::FailedPreconditionError(
          absl::StrCat("segment.actor_id ", proto.actor_id(),
                       " is not registered with this learner; register first"));
    }
    newest = weights_ == nullptr ? -1 : weights_->version();
    spec = spec_;
  }
  if (proto.policy_version() > newest) {
    return Reject("future_version",
                  absl::FailedPreconditionError(absl::StrCat(
                      "segment.policy_version ", proto.policy_version(),
                      " has not been published (newest: ", newest, ")")));
  }
  absl::StatusOr<Segment> segment =
      SegmentFromProto(proto, config_.max_tensor_bytes);
  if (!segment.ok()) return Reject("malformed", segment.status());
  if (absl::Status status =
          ValidateSegment(*segment, *spec, config_.max_segment_steps);
      !status.ok()) {
    return Reject("invalid", status);
  }
  if (config_.max_policy_lag >= 0 &&
      segment->policy_version < newest - config_.max_policy_lag) {
    if (dropped != nullptr) {
      *dropped = absl::StrCat(
          "segment.policy_version ", segment->policy_version, " is more than ",
          config_.max_policy_lag, " versions behind the newest (", newest, ")");
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.rejected["stale"];
    return absl::OkStatus();
  }
  const int64_t steps = segment->steps();
  if (absl::Status status = sink_.Send(*std::move(segment)); !status.ok()) {
    return absl::UnavailableError("the learner is shutting down");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.accepted_segments;
  counters_.accepted_steps += steps;
  return absl::OkStatus();
}

std::optional<EnvSpec> ActorGateway::WaitForSpec(absl::Duration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, ToChrono(timeout),
                    [&] { return spec_.has_value() || closed_; });
  return spec_;
}

void ActorGateway::SetSpec(const EnvSpec& spec) {
  std::lock_guard<std::mutex> lock(mutex_);
  spec_ = spec;
  changed_.notify_all();
}

void ActorGateway::Publish(const PolicyWeights& weights) {
  auto proto = std::make_shared<pb::Weights>();
  WeightsToProto(weights, proto.get());
  std::lock_guard<std::mutex> lock(mutex_);
  weights_ = std::move(proto);
  changed_.notify_all();
}

std::shared_ptr<const pb::Weights> ActorGateway::WaitForWeightsNewerThan(
    int64_t version, absl::Duration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool newer = changed_.wait_for(lock, ToChrono(timeout), [&] {
    return closed_ || (weights_ != nullptr && weights_->version() > version);
  });
  if (!newer || closed_) return nullptr;
  return weights_;
}

int64_t ActorGateway::published_version() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return weights_ == nullptr ? -1 : weights_->version();
}

int64_t ActorGateway::next_actor_id() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return next_actor_id_;
}

void ActorGateway::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  changed_.notify_all();
}

bool ActorGateway::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return closed_;
}

GatewayCounters ActorGateway::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

}  // namespace vantage
