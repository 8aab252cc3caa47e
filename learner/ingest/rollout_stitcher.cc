#include "learner/ingest/rollout_stitcher.h"

#include <ATen/ATen.h>

#include <limits>
#include <memory>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

// The step of its episode each of a segment's T + 1 observations is.
at::Tensor EpisodeSteps(const Segment& segment) {
  const int64_t steps = segment.steps();
  at::Tensor out = at::empty({steps + 1}, at::kLong);
  int64_t* step = out.data_ptr<int64_t>();
  const at::Tensor ended =
      at::logical_or(segment.terminated, segment.truncated).contiguous();
  const bool* end = ended.data_ptr<bool>();
  step[0] = segment.first_episode_step;
  for (int64_t t = 0; t < steps; ++t) step[t + 1] = end[t] ? 0 : step[t] + 1;
  return out;
}

}  // namespace

RolloutStitcher::RolloutStitcher(int64_t horizon)
    : horizon_(horizon < 1 ? 1 : horizon) {}

absl::Status RolloutStitcher::Add(Segment segment) {
  const int64_t actor_id = segment.actor_id;
  const int64_t env_slot = segment.env_slot;
  Stream& stream = streams_[{actor_id, env_slot}];
  if (stream.started && segment.sequence < stream.next_sequence) {
    ++stats_.stale_segments;
    return absl::FailedPreconditionError(absl::StrCat(
        "segment ", segment.sequence, " of actor ", segment.actor_id, " slot ",
        segment.env_slot, " arrived after ", stream.next_sequence - 1));
  }
  if (stream.started && segment.sequence > stream.next_sequence) {
    ++stats_.gaps;
    stats_.dropped_steps += stream.steps;
    buffered_ -= stream.steps;
    stream.pieces.clear();
    stream.steps = 0;
  }
  stream.started = true;
  stream.next_sequence = segment.sequence + 1;
  stream.last_fed = ++adds_;
  ++stats_.segments;
  const int64_t steps = segment.steps();
  at::Tensor episode_steps = EpisodeSteps(segment);
  stream.pieces.push_back({std::make_shared<const Segment>(std::move(segment)),
                           0, steps, std::move(episode_steps)});
  stream.steps += steps;
  buffered_ += steps;
  while (stream.steps >= horizon_) {
    ready_.push_back(Cut(actor_id, env_slot, stream));
    ++stats_.rollouts;
  }
  return absl::OkStatus();
}

Rollout RolloutStitcher::Cut(int64_t actor_id, int64_t env_slot,
                             Stream& stream) {
  std::vector<at::Tensor> observations, actions, rewards, terminated, truncated,
      finals, log_probs, versions, masks, episode_steps;
  int64_t needed = horizon_;
  at::Tensor next_observation;  // s_T: the observation after the last step
  at::Tensor next_episode_step;
  // Recurrent runs take whole segments, so a rollout starts where one does.
  const at::Tensor core_state = stream.pieces.front().segment->core_state;
  while (needed > 0) {
    Piece& piece = stream.pieces.front();
    const Segment& s = *piece.segment;
    const int64_t take = std::min(needed, piece.end - piece.begin);
    const int64_t b = piece.begin;
    const int64_t e = b + take;
    observations.push_back(s.observations.slice(0, b, e));
    actions.push_back(s.actions.slice(0, b, e));
    rewards.push_back(s.rewards.slice(0, b, e));
    terminated.push_back(s.terminated.slice(0, b, e));
    truncated.push_back(s.truncated.slice(0, b, e));
    log_probs.push_back(s.behaviour_log_probs.slice(0, b, e));
    if (s.action_masks.defined())
      masks.push_back(s.action_masks.slice(0, b, e));
    versions.push_back(at::full({take}, s.policy_version, at::kLong));
    // The final observations of the truncated steps in [b, e).
    const int64_t before = s.truncated.slice(0, 0, b).sum().item<int64_t>();
    const int64_t count = s.truncated.slice(0, b, e).sum().item<int64_t>();
    finals.push_back(s.final_observations.slice(0, before, before + count));
    // A slice shares the segment's storage, which outlives the piece.
    next_observation = s.observations.slice(0, e, e + 1);
    episode_steps.push_back(piece.episode_steps.slice(0, b, e));
    next_episode_step = piece.episode_steps.slice(0, e, e + 1);
    needed -= take;
    stream.steps -= take;
    buffered_ -= take;
    piece.begin = e;
    if (piece.begin == piece.end) stream.pieces.pop_front();
  }
  observations.push_back(next_observation);
  episode_steps.push_back(next_episode_step);
  Rollout rollout;
  rollout.actor_id = actor_id;
  rollout.env_slot = env_slot;
  rollout.observations = at::cat(observations);
  rollout.actions = at::cat(actions);
  rollout.rewards = at::cat(rewards);
  rollout.terminated = at::cat(terminated);
  rollout.truncated = at::cat(truncated);
  rollout.final_observations = at::cat(finals);
  rollout.behaviour_log_probs = at::cat(log_probs);
  rollout.policy_versions = at::cat(versions);
  rollout.core_state = core_state;
  if (!masks.empty()) rollout.action_masks = at::cat(masks);
  rollout.episode_steps = at::cat(episode_steps);
  return rollout;
}

std::vector<Rollout> RolloutStitcher::TakeReady() {
  std::vector<Rollout> ready = std::move(ready_);
  ready_.clear();
  return ready;
}

int64_t RolloutStitcher::DropStepsOlderThan(int64_t min_version) {
  int64_t dropped = 0;
  for (auto& entry : streams_) {
    Stream& stream = entry.second;
    // Versions never decrease along a stream, so the stale steps lead.
    while (!stream.pieces.empty() &&
           stream.pieces.front().segment->policy_version < min_version) {
      const Piece& piece = stream.pieces.front();
      dropped += piece.end - piece.begin;
      stream.steps -= piece.end - piece.begin;
      buffered_ -= piece.end - piece.begin;
      stream.pieces.pop_front();
    }
  }
  stats_.stale_steps += dropped;
  return dropped;
}

int64_t RolloutStitcher::EvictDownTo(int64_t max_steps, int64_t actor_id,
                                     int64_t env_slot) {
  int64_t evicted = 0;
  while (buffered_ > max_steps) {
    auto oldest = streams_.end();
    for (auto it = streams_.begin(); it != streams_.end(); ++it) {
      if (it->second.steps == 0 ||
          it->first == std::make_pair(actor_id, env_slot)) {
        continue;
      }
      if (oldest == streams_.end() ||
          it->second.last_fed < oldest->second.last_fed) {
        oldest = it;
      }
    }
    if (oldest == streams_.end()) break;
    buffered_ -= oldest->second.steps;
    evicted += oldest->second.steps;
    // The stream's next segment starts it afresh, as after a gap.
    oldest->second.pieces.clear();
    oldest->second.steps = 0;
    oldest->second.started = false;
  }
  stats_.evicted_steps += evicted;
  return evicted;
}

int64_t RolloutStitcher::ForgetActor(int64_t actor_id) {
  constexpr int64_t kLowest = std::numeric_limits<int64_t>::min();
  const auto begin = streams_.lower_bound({actor_id, kLowest});
  auto end = begin;
  int64_t dropped = 0;
  while (end != streams_.end() && end->first.first == actor_id) {
    dropped += end->second.steps;
    ++end;
  }
  streams_.erase(begin, end);
  buffered_ -= dropped;
  stats_.dropped_steps += dropped;
  return dropped;
}

}  // namespace vantage
