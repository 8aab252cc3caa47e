#include "learner/service/actor_gateway.h"

#include <algorithm>
#include <random>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/env/frame_stack.h"
#include "common/util/constant_time.h"

namespace vantage {
namespace {

std::chrono::nanoseconds ToChrono(absl::Duration d) {
  return absl::ToChronoNanoseconds(d);
}

// 128 bits from the operating system's generator (std::random_device is
// getrandom(2) on Linux), as 32 hex digits.
std::string NewSecret() {
  std::random_device device;
  std::string secret;
  for (int i = 0; i < 4; ++i) {
    absl::StrAppendFormat(&secret, "%08x", static_cast<uint32_t>(device()));
  }
  return secret;
}

absl::Status AtLeastOne(int64_t value, const char* name) {
  if (value < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " must be >= 1, got ", value));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status GatewayLimits::Validate() const {
  for (absl::Status status :
       {AtLeastOne(max_live_actors, "max_live_actors"),
        AtLeastOne(max_envs_per_actor, "max_envs_per_actor"),
        AtLeastOne(max_live_env_slots, "max_live_env_slots"),
        AtLeastOne(max_tensor_bytes, "max_tensor_bytes"),
        AtLeastOne(max_unclaimed_per_peer, "max_unclaimed_per_peer"),
        values.Validate()}) {
    if (!status.ok()) return status;
  }
  if (actor_expiry <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("actor_expiry must be > 0");
  }
  if (claim_timeout <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("claim_timeout must be > 0");
  }
  return absl::OkStatus();
}

ActorGateway::ActorGateway(GatewayConfig config, SegmentSink& sink)
    : config_(std::move(config)),
      check_(config_.spec, config_.max_segment_steps, config_.limits.values,
             config_.max_policy_lag, config_.core_state_size),
      sink_(sink),
      next_actor_id_(config_.first_actor_id) {}

absl::StatusOr<pb::RegisterResponse> ActorGateway::Register(
    const pb::RegisterRequest& request, absl::string_view peer,
    absl::Duration timeout) {
  if (absl::Status status = CheckRegisterRequest(request); !status.ok()) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.refused_registrations;
    return status;
  }
  std::string secret = NewSecret();
  absl::StatusOr<int64_t> actor_id = AddRegistration(peer, request, secret);
  if (!actor_id.ok()) return actor_id.status();
  std::shared_ptr<const pb::Weights> weights =
      WaitForWeightsNewerThan(-1, timeout);
  if (weights == nullptr) {
    return absl::UnavailableError(
        "the learner has published no weights yet; retry");
  }
  pb::RegisterResponse response;
  response.set_actor_id(*actor_id);
  response.set_session(absl::StrCat(*actor_id, ":", secret));
  *response.mutable_run_config() = config_.run_config;
  *response.mutable_weights() = *weights;
  return response;
}

absl::Status ActorGateway::CheckRegisterRequest(
    const pb::RegisterRequest& request) const {
  absl::StatusOr<EnvSpec> spec =
      EnvSpecFromProto(request.spec(), config_.limits.spec);
  if (!spec.ok()) return spec.status();
  if (spec->name != config_.spec.name) {
    return absl::InvalidArgumentError(absl::StrCat(
        "this learner trains ", config_.spec.name, ", not ", spec->name));
  }
  // Actors register their environment's own spec and wrap it as the run
  // config they receive says.
  const int64_t frames = config_.run_config.training().frame_stack();
  if (absl::Status status =
          CheckSameSpec(config_.spec, StackedSpec(*spec, frames));
      !status.ok()) {
    return status;
  }
  const int64_t num_envs = request.num_envs();
  if (num_envs < 1 || num_envs > config_.limits.max_envs_per_actor) {
    return absl::InvalidArgumentError(
        absl::StrCat("num_envs is ", num_envs, ", expected 1..",
                     config_.limits.max_envs_per_actor));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> ActorGateway::AddRegistration(
    absl::string_view peer, const pb::RegisterRequest& request,
    const std::string& secret) {
  const int64_t num_envs = request.num_envs();
  std::unique_lock<std::mutex> lock(mutex_);
  if (run_over_) return absl::OutOfRangeError(kRunOver);
  if (closed_) return absl::UnavailableError("the learner is shutting down");
  const absl::Time now = absl::Now();
  if (absl::Status quota = CheckUnclaimedQuota(peer, now); !quota.ok()) {
    ++counters_.refused_registrations;
    return quota;
  }
  if (!MakeRoom(num_envs)) {
    ++counters_.refused_registrations;
    return absl::ResourceExhaustedError(absl::StrCat(
        "the learner serves at most ", config_.limits.max_live_actors,
        " actors and ", config_.limits.max_live_env_slots,
        " env slots at once (now ", actors_.size(), " and ",
        counters_.live_env_slots, "), and every registration has a call open"));
  }
  const int64_t actor_id = next_actor_id_++;
  Registration& registration = actors_[actor_id];
  registration.secret = secret;
  registration.peer = std::string(peer);
  // For the learner's log: at most 128 printable characters (a name is
  // whatever the client sent).
  registration.name = request.actor_name().substr(0, 128);
  for (char& c : registration.name) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  registration.num_envs = num_envs;
  registration.admitted = HorizonPacer(config_.lead);
  registration.next_sequence.assign(num_envs, 0);
  registration.last_seen = now;
  ++counters_.registrations;
  counters_.live_env_slots += num_envs;
  return actor_id;
}

absl::StatusOr<int64_t> ActorGateway::Attach(absl::string_view session) {
  const size_t colon = session.find(':');
  int64_t actor_id = -1;
  std::lock_guard<std::mutex> lock(mutex_);
  if (colon == absl::string_view::npos ||
      !absl::SimpleAtoi(session.substr(0, colon), &actor_id)) {
    ++counters_.rejected["bad_session"];
    return absl::PermissionDeniedError(
        "the call carries no valid session; register first and send the "
        "session it returned");
  }
  auto it = actors_.find(actor_id);
  if (it == actors_.end()) {
    ++counters_.rejected["unknown_session"];
    return absl::NotFoundError(absl::StrCat(
        "actor ", actor_id,
        " has no live registration (never registered, or expired); "
        "register again"));
  }
  if (!ConstantTimeEquals(session.substr(colon + 1), it->second.secret)) {
    ++counters_.rejected["bad_session"];
    return absl::PermissionDeniedError(
        absl::StrCat("wrong session secret for actor ", actor_id));
  }
  ++it->second.open_calls;
  it->second.claimed = true;
  it->second.last_seen = absl::Now();
  it->second.last_progress = it->second.last_seen;
  return actor_id;
}

void ActorGateway::Detach(int64_t actor_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = actors_.find(actor_id);
  if (it == actors_.end()) return;
  --it->second.open_calls;
  it->second.last_seen = absl::Now();
}

std::vector<int64_t> ActorGateway::ExpireIdle(absl::Time now) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<int64_t> expired = std::move(evicted_);
  evicted_.clear();
  for (auto it = actors_.begin(); it != actors_.end();) {
    const Registration& registration = it->second;
    const absl::Duration expiry = registration.claimed
                                      ? config_.limits.actor_expiry
                                      : config_.limits.claim_timeout;
    if (registration.open_calls == 0 && now - registration.last_seen > expiry) {
      expired.push_back(it->first);
      RemoveLocked(it++);
    } else {
      ++it;
    }
  }
  return expired;
}

absl::Status ActorGateway::CheckUnclaimedQuota(absl::string_view peer,
                                               absl::Time now) const {
  int64_t unclaimed = 0;
  for (const auto& [actor_id, registration] : actors_) {
    if (!registration.claimed && registration.peer == peer &&
        now - registration.last_seen <= config_.limits.claim_timeout) {
      ++unclaimed;
    }
  }
  if (unclaimed < config_.limits.max_unclaimed_per_peer) {
    return absl::OkStatus();
  }
  return absl::ResourceExhaustedError(absl::StrCat(
      peer, " holds ", unclaimed,
      " registrations that have opened no call (at most ",
      config_.limits.max_unclaimed_per_peer, " per host); they expire after ",
      absl::FormatDuration(config_.limits.claim_timeout)));
}

bool ActorGateway::MakeRoom(int64_t num_envs) {
  auto full = [&] {
    return static_cast<int64_t>(actors_.size()) >=
               config_.limits.max_live_actors ||
           counters_.live_env_slots + num_envs >
               config_.limits.max_live_env_slots;
  };
  // Nothing is evicted for a registration that would not fit even then.
  int64_t idle_actors = 0;
  int64_t idle_slots = 0;
  for (const auto& [actor_id, registration] : actors_) {
    if (registration.open_calls > 0) continue;
    ++idle_actors;
    idle_slots += registration.num_envs;
  }
  if (static_cast<int64_t>(actors_.size()) - idle_actors >=
          config_.limits.max_live_actors ||
      counters_.live_env_slots - idle_slots + num_envs >
          config_.limits.max_live_env_slots) {
    return false;
  }
  while (full()) {
    // The registration longest without an open call: an actor that left,
    // or one that registered and never came back.
    auto idlest = actors_.end();
    for (auto it = actors_.begin(); it != actors_.end(); ++it) {
      if (it->second.open_calls > 0) continue;
      if (idlest == actors_.end() ||
          it->second.last_seen < idlest->second.last_seen) {
        idlest = it;
      }
    }
    if (idlest == actors_.end()) return false;
    evicted_.push_back(idlest->first);
    RemoveLocked(idlest);
  }
  return true;
}

void ActorGateway::RemoveLocked(std::map<int64_t, Registration>::iterator it) {
  counters_.live_env_slots -= it->second.num_envs;
  ++counters_.expirations;
  actors_.erase(it);
}

absl::Status ActorGateway::Reject(const std::string& reason,
                                  absl::Status status) {
  CountRejected(reason);
  return status;
}

void ActorGateway::CountRejected(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.rejected[reason];
}

absl::Status ActorGateway::Admit(int64_t actor_id, const pb::Segment& proto,
                                 std::string* dropped) {
  if (dropped != nullptr) dropped->clear();
  absl::StatusOr<int64_t> newest = CheckSender(actor_id, proto);
  if (!newest.ok()) return newest.status();
  // CheckSender counted this call in `admitting`; it ends here.
  struct Admitting {
    ActorGateway& gateway;
    int64_t actor_id;
    ~Admitting() {
      std::lock_guard<std::mutex> lock(gateway.mutex_);
      if (auto it = gateway.actors_.find(actor_id);
          it != gateway.actors_.end()) {
        --it->second.admitting;
      }
    }
  } admitting{*this, actor_id};
  absl::StatusOr<Segment> segment = DecodeSegment(proto, *newest);
  if (!segment.ok()) return segment.status();
  if (check_.TooStale(segment->policy_version, *newest)) {
    std::string why = absl::StrCat(
        "segment.policy_version ", segment->policy_version, " is more than ",
        config_.max_policy_lag, " versions behind the newest (", *newest, ")");
    if (dropped != nullptr) *dropped = std::move(why);
    CountRejected("stale");
    return absl::OkStatus();
  }
  if (!AdvanceSequence(actor_id, *segment, dropped)) return absl::OkStatus();
  return Deliver(actor_id, *std::move(segment));
}

absl::StatusOr<int64_t> ActorGateway::CheckSender(int64_t actor_id,
                                                  const pb::Segment& proto) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = actors_.find(actor_id);
  if (it == actors_.end()) {
    ++counters_.rejected["unknown_session"];
    return absl::NotFoundError(absl::StrCat(
        "actor ", actor_id, "'s registration expired; register again"));
  }
  if (proto.actor_id() != actor_id) {
    ++counters_.rejected["foreign_actor"];
    return absl::PermissionDeniedError(absl::StrCat(
        "segment.actor_id ", proto.actor_id(),
        " does not belong to this stream, which is actor ", actor_id, "'s"));
  }
  if (proto.env_slot() < 0 || proto.env_slot() >= it->second.num_envs) {
    ++counters_.rejected["foreign_slot"];
    return absl::PermissionDeniedError(absl::StrCat(
        "segment.env_slot ", proto.env_slot(), " is not one of actor ",
        actor_id, "'s ", it->second.num_envs, " env slots"));
  }
  it->second.last_seen = absl::Now();
  ++it->second.admitting;
  return weights_ == nullptr ? -1 : weights_->version();
}

absl::StatusOr<Segment> ActorGateway::DecodeSegment(const pb::Segment& proto,
                                                    int64_t newest) {
  if (absl::Status status =
          SegmentCheck::CheckPublished(proto.policy_version(), newest);
      !status.ok()) {
    return Reject("future_version", status);
  }
  absl::StatusOr<Segment> segment =
      SegmentFromProto(proto, config_.limits.max_tensor_bytes);
  if (!segment.ok()) return Reject("malformed", segment.status());
  if (absl::Status status = check_.Validate(*segment); !status.ok()) {
    return Reject("invalid", status);
  }
  return segment;
}

bool ActorGateway::AdvanceSequence(int64_t actor_id, const Segment& segment,
                                   std::string* dropped) {
  // Sequence numbers only grow along a slot's stream (a jump starts a new
  // stream); one already admitted would be stitched twice.
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = actors_.find(actor_id);
  if (it == actors_.end()) return true;
  int64_t& next = it->second.next_sequence[segment.env_slot];
  if (segment.sequence < next) {
    ++counters_.rejected["duplicate"];
    if (dropped != nullptr) {
      *dropped = absl::StrCat("segment.sequence ", segment.sequence,
                              " of slot ", segment.env_slot,
                              " was already admitted (next: ", next, ")");
    }
    return false;
  }
  next = segment.sequence + 1;
  return true;
}

absl::Status ActorGateway::Deliver(int64_t actor_id, Segment segment) {
  const int64_t steps = segment.steps();
  const int64_t version = segment.policy_version;
  if (absl::Status status = sink_.Send(std::move(segment)); !status.ok()) {
    return absl::UnavailableError("the learner is shutting down");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.accepted_segments;
  counters_.accepted_steps += steps;
  if (auto it = actors_.find(actor_id); it != actors_.end()) {
    it->second.accepted_steps += steps;
    it->second.admitted.Add(version, steps);
    it->second.last_progress = absl::Now();
  }
  return absl::OkStatus();
}

void ActorGateway::Publish(const PolicyWeights& weights) {
  auto proto = std::make_shared<pb::Weights>();
  WeightsToProto(weights, proto.get());
  std::lock_guard<std::mutex> lock(mutex_);
  proto->set_horizons(GrantedLocked());
  weights_ = std::move(proto);
  ++weights_sequence_;
  granted_at_ = absl::Now();
  changed_.notify_all();
}

int64_t ActorGateway::GrantedLocked() const {
  int64_t live_slots = 0;
  for (const auto& [actor_id, registration] : actors_) {
    if (registration.open_calls > 0) live_slots += registration.num_envs;
  }
  if (live_slots == 0) return 1;
  return (config_.batch_rollouts + live_slots - 1) / live_slots;
}

void ActorGateway::Grant(int64_t version, int64_t horizons) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (weights_ == nullptr || weights_->version() != version ||
      weights_->horizons() == horizons) {
    return;
  }
  // A copy: subscriptions may be writing the message in force.
  auto proto = std::make_shared<pb::Weights>(*weights_);
  proto->set_horizons(horizons);
  weights_ = std::move(proto);
  ++weights_sequence_;
  granted_at_ = absl::Now();
  changed_.notify_all();
}

int64_t ActorGateway::OwedStepsLocked(const Registration& registration) const {
  if (weights_ == nullptr) return 0;
  return registration.admitted.Credit(
      weights_->version(), weights_->horizons(),
      registration.num_envs * config_.horizon_steps);
}

PoolView ActorGateway::Pool() const {
  std::lock_guard<std::mutex> lock(mutex_);
  PoolView view;
  if (weights_ != nullptr) {
    view.version = weights_->version();
    view.horizons = weights_->horizons();
  }
  for (const auto& [actor_id, registration] : actors_) {
    if (registration.open_calls == 0) continue;
    view.members.push_back(
        {actor_id, registration.num_envs, OwedStepsLocked(registration)});
  }
  return view;
}

std::vector<StalledActor> ActorGateway::ExpireStalled(absl::Time now) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StalledActor> stalled;
  if (config_.stall_timeout <= absl::ZeroDuration()) return stalled;
  for (auto it = actors_.begin(); it != actors_.end();) {
    const Registration& registration = it->second;
    const int64_t owed = OwedStepsLocked(registration);
    const absl::Duration silent =
        now - std::max(registration.last_progress, granted_at_);
    if (registration.open_calls > 0 && registration.admitting == 0 &&
        owed > 0 && silent > config_.stall_timeout) {
      stalled.push_back(
          {it->first, registration.name, registration.peer, owed, silent});
      evicted_.push_back(it->first);
      ++counters_.stalls;
      RemoveLocked(it++);
    } else {
      ++it;
    }
  }
  return stalled;
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

std::shared_ptr<const pb::Weights> ActorGateway::WaitForWeightsAfter(
    int64_t* seen, absl::Duration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool newer = changed_.wait_for(lock, ToChrono(timeout), [&] {
    return closed_ || (weights_ != nullptr && weights_sequence_ > *seen);
  });
  if (!newer || closed_) return nullptr;
  *seen = weights_sequence_;
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

void ActorGateway::FinishRun() {
  std::lock_guard<std::mutex> lock(mutex_);
  run_over_ = true;
  closed_ = true;
  changed_.notify_all();
}

bool ActorGateway::run_over() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return run_over_;
}

GatewayCounters ActorGateway::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  GatewayCounters counters = counters_;
  counters.live_actors = static_cast<int64_t>(actors_.size());
  return counters;
}

std::vector<ActorActivity> ActorGateway::activity() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ActorActivity> activity;
  activity.reserve(actors_.size());
  for (const auto& [actor_id, registration] : actors_) {
    activity.push_back({actor_id, registration.accepted_steps,
                        registration.last_seen, registration.open_calls > 0});
  }
  return activity;
}

}  // namespace vantage
