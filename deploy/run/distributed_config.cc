#include "deploy/run/distributed_config.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<DistributedConfig, pb::DistributedSettings>&
DistributedTable() {
  using C = DistributedConfig;
  static const auto* table =
      new SettingsTable<DistributedConfig, pb::DistributedSettings>(
          "distributed",
          {{"actors", &C::actors, AtLeast(1), AtMost(256)},
           {"envs_per_actor", &C::envs_per_actor, AtLeast(1), AtMost(4096)},
           {"sync", &C::sync},
           {"max_policy_lag", &C::max_policy_lag, AtLeast(0)},
           {"learners", &C::learners, AtLeast(1), AtMost(64)},
           {"learner_threads", &C::learner_threads, AtLeast(0), AtMost(256),
            "(0: automatic)"},
           {"actor_stall_timeout_s", &C::actor_stall_timeout_s, AtLeast(1),
            AtMost(86400)}},
          SettingNames::kFlag);
  return *table;
}

// The defaults that depend on what else was given: two actor processes,
// over which a batch given as --envs alone is split (over one actor if it
// does not split evenly); an asynchronous run's policy lag.
void InferLayout(const pb::TrainingSettings& t, pb::DistributedSettings& d) {
  if (!d.has_actors()) {
    const int64_t per_actor = d.has_envs_per_actor() ? d.envs_per_actor() : 0;
    if (t.has_envs() && per_actor > 0) {
      d.set_actors(static_cast<int32_t>(t.envs() / per_actor));
    } else {
      d.set_actors(t.has_envs() && t.envs() % 2 != 0 ? 1 : 2);
    }
  }
  if (!d.has_envs_per_actor()) {
    d.set_envs_per_actor(
        t.has_envs() ? static_cast<int32_t>(t.envs() / std::max(1, d.actors()))
                     : 1);
  }
  if (!d.has_max_policy_lag() && d.has_sync() && !d.sync()) {
    d.set_max_policy_lag(4);
  }
}

// The rules across settings: the batch defaults to one rollout per actor
// environment, sync means no lag, the learners share the actors evenly,
// and a sync actor sends whole horizons. The batch and the actors'
// environments may differ: the learner has each live environment act as
// many horizons per version as fill the batch (an elastic pool), so a run
// keeps its batch whatever number of actors serve it.
absl::Status CheckLayout(pb::TrainingSettings& t,
                         const pb::DistributedSettings& d) {
  // At most 256 x 4096: the product fits an int32.
  const int32_t streams = d.actors() * d.envs_per_actor();
  if (streams > 4096) {
    return FlagError("envs_per_actor",
                     absl::StrCat("makes --actors x --envs_per_actor = ",
                                  streams, " streams, more than 4096"));
  }
  if (!t.has_envs()) t.set_envs(streams);
  if (d.sync() && d.max_policy_lag() != 0) {
    return FlagError("max_policy_lag", "must be 0 with --sync");
  }
  if (d.actors() % d.learners() != 0) {
    return FlagError("learners",
                     absl::StrCat("must divide --actors (", d.actors(),
                                  "): every learner serves as many actors"));
  }
  if (t.envs() % d.learners() != 0) {
    return FlagError("learners",
                     absl::StrCat("must divide the batch's --envs (", t.envs(),
                                  "): every learner takes an equal share"));
  }
  if (d.sync() && t.horizon() % t.segment_length() != 0) {
    return FlagError("segment_length",
                     "must divide --horizon in a --sync run (each actor sends "
                     "exactly one horizon per policy version)");
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status DistributedConfig::Validate() const {
  return DistributedTable().Validate(*this);
}

absl::Status ResolveDistributedSettings(pb::TrainingSettings& training,
                                        pb::DistributedSettings& settings) {
  InferLayout(training, settings);
  if (absl::Status status =
          DistributedTable().Resolve(DistributedConfig(), settings).status();
      !status.ok()) {
    return status;
  }
  return CheckLayout(training, settings);
}

}  // namespace vantage
