#ifndef VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_
#define VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_

// Everything the learner's gRPC service does, without gRPC: actor
// registration and the sessions it hands out, admission of segments into
// the learner's queue, and the board of published weights. The service
// methods only translate.

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "common/env/environment.h"
#include "common/nn/policy_weights.h"
#include "common/rollout/horizon_pacer.h"
#include "common/rollout/segment.h"
#include "common/rollout/segment_queue.h"
#include "learner/ingest/segment_check.h"
#include "proto/run_config.pb.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"

namespace vantage {

// What actors are told once the run is complete (OUT_OF_RANGE).
inline constexpr char kRunOver[] = "the run is over: every step is done";

// What one client can make the learner hold. Defaults suit a cluster run of
// a few hundred actors; every one is a flag of `vantage learner`.
struct GatewayLimits {
  int64_t max_live_actors = 256;
  // A run config allows up to 4096 envs per actor and 4096 in all.
  int64_t max_envs_per_actor = 4096;
  // Env streams over all live registrations (twice a run's largest, for
  // the registrations of reconnected actors that have not expired yet).
  int64_t max_live_env_slots = 8192;
  // A registration with no open call for this long expires: its session
  // stops working and the learner frees what it buffered for it.
  absl::Duration actor_expiry = absl::Seconds(60);
  // A registration that has opened no call yet is unclaimed: it expires
  // after claim_timeout, and one peer host holds at most
  // max_unclaimed_per_peer of them, so that a client registering in a loop
  // cannot fill the table (an actor opens its calls within seconds).
  absl::Duration claim_timeout = absl::Seconds(30);
  int64_t max_unclaimed_per_peer = 64;
  int64_t max_tensor_bytes = 64 << 20;
  SpecLimits spec;
  ValueLimits values;

  absl::Status Validate() const;
};

// Limits of the gRPC service around a gateway (see LearnerService); here so
// that configuring them needs no gRPC headers.
struct ServiceLimits {
  // A segment stream that delivers nothing for this long is cancelled
  // (actors send at least one segment per policy version).
  absl::Duration idle_stream_timeout = absl::Seconds(300);
  // Bytes of one segment message (see MaxSegmentMessageBytes).
  int64_t max_segment_message_bytes = 64 << 20;
  // Register and weights requests are a few hundred bytes.
  int64_t max_request_bytes = 64 << 10;
};

struct GatewayConfig {
  pb::RunConfig run_config;  // resolved; sent to every registering actor
  // The run's environment, pinned by the learner's own configuration (or
  // its checkpoint); registrations must match it exactly.
  EnvSpec spec;
  // Floats of a recurrent policy's state that every segment carries (0: a
  // feed-forward policy, whose segments carry none).
  int64_t core_state_size = 0;
  int64_t max_segment_steps = 4096;
  // Segments older than the newest version minus this are dropped and
  // counted (not an error for the actor); -1: any age.
  int64_t max_policy_lag = 0;
  // Ids are never reused within a run: a resumed learner continues after
  // the ids its checkpoint had handed out.
  int64_t first_actor_id = 0;
  // The elastic pool: the rollouts of `horizon_steps` steps this learner's
  // batch takes, which Publish shares out over the live env slots as a
  // grant of horizons per slot (pb::Weights.horizons); the versions an
  // actor may lead by (0: sync; see HorizonPacer).
  int64_t batch_rollouts = 1;
  int64_t horizon_steps = 1;
  int64_t lead = 0;
  // An actor that owes segments and sends none for this long is stalled
  // (ExpireStalled); zero or less: never.
  absl::Duration stall_timeout = absl::Seconds(60);
  GatewayLimits limits;
};

// What the gateway saw, for logs, acks and metrics.
struct GatewayCounters {
  int64_t registrations = 0;  // granted, over the run of this process
  int64_t refused_registrations = 0;
  int64_t expirations = 0;  // idle past their expiry, or evicted
  int64_t stalls = 0;       // expired for owing segments too long
  int64_t live_actors = 0;  // registrations not expired
  int64_t live_env_slots = 0;
  int64_t accepted_segments = 0;
  int64_t accepted_steps = 0;
  std::map<std::string, int64_t> rejected;  // reason -> segments or calls
};

// What one live registration has done: the steps of its admitted segments,
// when it was last heard from, and whether a call of it is open now (a
// stream blocked by backpressure is one: the actor is there).
struct ActorActivity {
  int64_t actor_id = 0;
  int64_t accepted_steps = 0;
  absl::Time last_seen;
  bool connected = false;
};

// The actors that feed the learner now, as the elastic pool sees them: the
// registrations with a call open, and the grant in force.
struct PoolView {
  struct Member {
    int64_t actor_id = 0;
    int64_t env_slots = 0;
    // Steps its grant still allows (0 or less: it has sent all it may
    // until the next grant), counted from the segments admitted.
    int64_t owed_steps = 0;
  };
  int64_t version = -1;
  int64_t horizons = 0;  // per env slot, at `version`
  std::vector<Member> members;
  int64_t live_env_slots() const {
    int64_t slots = 0;
    for (const Member& member : members) slots += member.env_slots;
    return slots;
  }
};

// A registration that owed segments and sent none for the stall timeout.
struct StalledActor {
  int64_t actor_id = 0;
  std::string name;  // as it registered
  std::string peer;  // its host
  int64_t owed_steps = 0;
  absl::Duration silent;
};

class ActorGateway {
 public:
  // Admitted segments go to `sink` (which blocks when full: backpressure
  // reaches the actors through their streams).
  ActorGateway(GatewayConfig config, SegmentSink& sink);

  // Checks the spec against the run's (InvalidArgument naming the field)
  // and num_envs against the limits, then grants an actor id and a secret
  // session. `peer` names the caller's host (see PeerHost). When the live
  // actors or env slots are at their limit, registrations with no open
  // call make room, the longest idle first; ResourceExhausted when they
  // cannot, or when `peer` holds max_unclaimed_per_peer unclaimed
  // registrations. Answers once the first weights are published;
  // Unavailable if none arrive within `timeout`.
  absl::StatusOr<pb::RegisterResponse> Register(
      const pb::RegisterRequest& request, absl::string_view peer,
      absl::Duration timeout);

  // Binds a call to the registration whose session it carries and keeps
  // that registration alive until Detach. NotFound for a session that is
  // unknown or expired (register again), PermissionDenied for a wrong
  // secret; both counted.
  absl::StatusOr<int64_t> Attach(absl::string_view session);
  void Detach(int64_t actor_id);

  // Decodes and validates one segment of a stream bound to `actor_id` and
  // hands it to the learner. PermissionDenied for a segment of another
  // actor or of a slot the registration does not have; InvalidArgument
  // (malformed, or wrong for the spec) and FailedPrecondition (a version
  // not published yet) name the problem. A too stale version or an already
  // admitted sequence number is dropped with OK and, if `dropped` is not
  // null, *dropped says why (else it is cleared). Every refusal and drop is
  // counted by reason.
  absl::Status Admit(int64_t actor_id, const pb::Segment& segment,
                     std::string* dropped = nullptr);
  // Counts a refusal that happened before Admit (for example, bytes that
  // are no segment at all).
  void CountRejected(const std::string& reason);

  // Expires the registrations idle since before now - actor_expiry and the
  // unclaimed ones older than claim_timeout, and returns their ids and
  // those of registrations evicted since the last call (each once), so
  // that the learner can free them.
  std::vector<int64_t> ExpireIdle(absl::Time now = absl::Now());

  // Expires the registrations that owe segments (their grant allows more
  // than they sent) and have sent none, with no call blocked sending one,
  // for the stall timeout since the later of their last segment, their
  // attaching and the grant; returns them (their ids also go to the next
  // ExpireIdle). A hung actor stops holding up the batch.
  std::vector<StalledActor> ExpireStalled(absl::Time now = absl::Now());

  const EnvSpec& spec() const { return config_.spec; }

  // Publishes a new version with a grant that lets the live env slots (or,
  // with none live, the batch's own number of them) fill the batch:
  // ceil(batch_rollouts / live env slots) horizons each.
  void Publish(const PolicyWeights& weights);
  // Sends `version` again with a grant of `horizons` (when the live actors
  // cannot fill the batch with the grant they have, or 0 once a sync batch
  // is complete); no-op if `version` is no longer the newest.
  void Grant(int64_t version, int64_t horizons);
  PoolView Pool() const;

  // The newest weights if newer than `version`, waiting up to `timeout`;
  // null on timeout or once closed.
  std::shared_ptr<const pb::Weights> WaitForWeightsNewerThan(
      int64_t version, absl::Duration timeout);
  // The weights as last published or granted, once that happened after
  // `*seen` (updated; -1 at first: the weights in force), waiting up to
  // `timeout`; null on timeout or once closed.
  std::shared_ptr<const pb::Weights> WaitForWeightsAfter(
      int64_t* seen, absl::Duration timeout);
  int64_t published_version() const;
  // The id the next registration gets (saved in checkpoints).
  int64_t next_actor_id() const;

  // Wakes every waiter; no more registrations or weights.
  void Close();
  bool closed() const;
  // Closes because the run is complete: registrations and weight
  // subscriptions then end with kRunOver's OUT_OF_RANGE, which actors take
  // as the end of their work (a plain Close is a learner going away, after
  // which they reconnect).
  void FinishRun();
  bool run_over() const;

  GatewayCounters counters() const;
  // One entry per live registration, by actor id.
  std::vector<ActorActivity> activity() const;

 private:
  struct Registration {
    std::string secret;
    std::string peer;
    std::string name;
    int64_t num_envs = 0;
    bool claimed = false;  // has opened a call
    // Per env slot: the lowest sequence number not yet admitted.
    std::vector<int64_t> next_sequence;
    int64_t open_calls = 0;
    int64_t accepted_steps = 0;
    absl::Time last_seen;
    // The steps admitted per policy version (the learner's count of the
    // actor's HorizonPacer), the last admission or attach, and the calls
    // inside Admit now (a stream blocked on a full queue is no stall).
    HorizonPacer admitted{0};
    absl::Time last_progress;
    int64_t admitting = 0;
  };

  // With mutex_ held.
  int64_t OwedStepsLocked(const Registration& registration) const;
  int64_t GrantedLocked() const;

  absl::Status Reject(const std::string& reason, absl::Status status);

  // Register's steps: the request against the run's spec and the limits,
  // then (taking mutex_) the new registration's id, or why there is no room.
  absl::Status CheckRegisterRequest(const pb::RegisterRequest& request) const;
  absl::StatusOr<int64_t> AddRegistration(absl::string_view peer,
                                          const pb::RegisterRequest& request,
                                          const std::string& secret);

  // Admit's steps. Each takes mutex_ only around what it reads or writes of
  // the gateway's state, so that the lock is never held while a segment is
  // decoded or while sink_ blocks. CheckSender refuses a segment of another
  // actor or slot and returns the newest published version as of the same
  // lock. AdvanceSequence is false for a sequence number already admitted
  // (the segment is then dropped, counted, and *dropped says why).
  absl::StatusOr<int64_t> CheckSender(int64_t actor_id,
                                      const pb::Segment& proto);
  absl::StatusOr<Segment> DecodeSegment(const pb::Segment& proto,
                                        int64_t newest);
  bool AdvanceSequence(int64_t actor_id, const Segment& segment,
                       std::string* dropped);
  absl::Status Deliver(int64_t actor_id, Segment segment);

  // With mutex_ held: whether `peer` may hold one more unclaimed
  // registration, and room for `num_envs` more env slots made by evicting
  // idle registrations (false if there is not enough to evict).
  absl::Status CheckUnclaimedQuota(absl::string_view peer,
                                   absl::Time now) const;
  bool MakeRoom(int64_t num_envs);
  void RemoveLocked(std::map<int64_t, Registration>::iterator it);

  const GatewayConfig config_;
  const SegmentCheck check_;
  SegmentSink& sink_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<int64_t, Registration> actors_;
  int64_t next_actor_id_ = 0;
  std::vector<int64_t> evicted_;  // not yet returned by ExpireIdle
  std::shared_ptr<const pb::Weights> weights_;
  // Counts Publish and Grant (what WaitForWeightsAfter waits on), and when
  // the grant in force was made.
  int64_t weights_sequence_ = 0;
  absl::Time granted_at_;
  bool closed_ = false;
  bool run_over_ = false;
  GatewayCounters counters_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_
