#ifndef VANTAGE_COMMON_ROLLOUT_HORIZON_PACER_H_
#define VANTAGE_COMMON_ROLLOUT_HORIZON_PACER_H_

// How far an actor may act ahead of its learner. The learner grants each
// env slot `horizons` horizons per policy version (pb::Weights.horizons,
// set from the env slots that are live so that they fill a batch together);
// an actor that may lead by `lead` versions (0 in a sync run) may have
// begun at most (1 + lead) x the newest grant over the versions of its
// window [version - lead, version]. The actor counts the horizons it began;
// the learner counts the ones it admitted, with the same rule, to tell an
// actor that owes it segments from one that is waiting for a grant.

#include <cstdint>
#include <iterator>
#include <map>

namespace vantage {

class HorizonPacer {
 public:
  explicit HorizonPacer(int64_t lead) : lead_(lead < 0 ? 0 : lead) {}

  // Horizons (or fractions of them, in whatever unit Add counts) that may
  // still begin with `version` under a grant of `horizons` per version.
  int64_t Credit(int64_t version, int64_t horizons,
                 int64_t units_per_horizon = 1) const {
    int64_t used = 0;
    for (auto it = began_.lower_bound(version - lead_);
         it != began_.end() && it->first <= version; ++it) {
      used += it->second;
    }
    return (1 + lead_) * horizons * units_per_horizon - used;
  }

  // `units` of work began with `version`; versions older than the window
  // of `version` are forgotten.
  void Add(int64_t version, int64_t units) {
    began_[version] += units;
    began_.erase(began_.begin(), began_.lower_bound(version - lead_));
  }

  // Work counted at `version` exactly.
  int64_t At(int64_t version) const {
    auto it = began_.find(version);
    return it == began_.end() ? 0 : it->second;
  }

 private:
  int64_t lead_;
  std::map<int64_t, int64_t> began_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_HORIZON_PACER_H_
