// Compiled once per instruction set (see common/CMakeLists.txt): the
// build defines VANTAGE_KERNEL_ISA as the namespace of this copy, and
// estimator_dispatch.cc picks one at run time. Every copy performs the same
// IEEE operations in the same order (no FMA contraction), so all give
// bit-identical results.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

#include "common/advantage/estimator_kernels_isa.h"

#ifndef VANTAGE_KERNEL_ISA
#define VANTAGE_KERNEL_ISA isa_baseline
#endif

namespace vantage {
namespace VANTAGE_KERNEL_ISA {
namespace {

// Elements per block of the backward pass: the block's TD errors, basis
// rows and running statistic stay in L1/L2 while the members read them.
constexpr int64_t kBlockElements = 512;

// One ensemble member, with k clamped to the rollout length: every k >=
// steps gives the longest estimate, and clamping keeps k * streams from
// overflowing.
struct Member {
  double k = 0;
  double gamma_k = 0;
  int64_t offset = 0;  // k * streams: from element (t, s) to (t + k, s)
  // Elements before this index have t + k < steps; at or after it k >= L_t
  // and the member collapses to the longest estimate.
  int64_t in_range_end = 0;
};

Member MakeMember(int64_t k, int64_t steps, int64_t streams, double gamma) {
  k = std::min(k, steps);
  Member member;
  member.k = static_cast<double>(k);
  member.gamma_k = std::pow(gamma, member.k);
  member.offset = k * streams;
  member.in_range_end = (steps - k) * streams;
  return member;
}

// Folds one member's A^(k) over the elements [begin, end) into acc[0, end -
// begin): acc[j] = combine(acc[j], A^(k)). Before member.in_range_end the
// select between two constants and the unconditional read of
// longest[i + offset] let GCC vectorise (with a finite longest[],
// 0 * longest[i + offset] leaves longest[i] exact); after it the member is
// the longest estimate.
template <typename Combine>
inline void FoldMember(const Member& member, const double* __restrict longest,
                       const double* __restrict remaining, int64_t begin,
                       int64_t end, double* __restrict acc, Combine combine) {
  const int64_t split = std::clamp(member.in_range_end, begin, end);
  const double k = member.k;
  const double gamma_k = member.gamma_k;
  const double* __restrict tail = longest + member.offset;
  for (int64_t i = begin; i < split; ++i) {
    const double factor = k < remaining[i] ? gamma_k : 0.0;
    acc[i - begin] = combine(acc[i - begin], longest[i] - factor * tail[i]);
  }
  for (int64_t i = split; i < end; ++i) {
    acc[i - begin] = combine(acc[i - begin], longest[i]);
  }
}

inline double Assign(double, double estimate) { return estimate; }

// Ensembles up to this size reduce element by element with the members
// unrolled at compile time, so each element's running statistic stays in a
// register; larger ones (and order:d) go member by member.
constexpr int kMaxUnrolledMembers = 16;

// The running statistic over elements [begin, end) in which members
// [0, kActive) are in range and, if kCollapsed, the rest collapse to the
// longest estimate. Members are in ascending k and the collapsed ones come
// last, as maxabs's tie rule needs.
template <int kActive, bool kCollapsed, typename Combine>
void ReduceSegment(const Member* members, const double* __restrict longest,
                   const double* __restrict remaining, int64_t begin,
                   int64_t end, double* __restrict out) {
  double k[kActive > 0 ? kActive : 1];
  double gamma_k[kActive > 0 ? kActive : 1];
  const double* tail[kActive > 0 ? kActive : 1];
  for (int m = 0; m < kActive; ++m) {
    k[m] = members[m].k;
    gamma_k[m] = members[m].gamma_k;
    tail[m] = longest + members[m].offset;
  }
  const Combine combine;
  for (int64_t i = begin; i < end; ++i) {
    const double whole = longest[i];
    double best = whole;
    if constexpr (kActive > 0) {
      // As in FoldMember, for bit-identical members.
      best = whole - (k[0] < remaining[i] ? gamma_k[0] : 0.0) * tail[0][i];
      for (int m = 1; m < kActive; ++m) {
        const double factor = k[m] < remaining[i] ? gamma_k[m] : 0.0;
        best = combine(best, whole - factor * tail[m][i]);
      }
      if constexpr (kCollapsed) best = combine(best, whole);
    }
    out[i - begin] = best;
  }
}

using SegmentReducer = void (*)(const Member*, const double*, const double*,
                                int64_t, int64_t, double*);

// table[active][collapsed] for one statistic.
template <typename Combine, int... kActive>
constexpr std::array<std::array<SegmentReducer, 2>, sizeof...(kActive)>
SegmentTable(std::integer_sequence<int, kActive...>) {
  return {{{&ReduceSegment<kActive, false, Combine>,
            &ReduceSegment<kActive, true, Combine>}...}};
}

template <typename Combine>
const std::array<std::array<SegmentReducer, 2>, kMaxUnrolledMembers + 1>&
SegmentReducers() {
  static constexpr auto table = SegmentTable<Combine>(
      std::make_integer_sequence<int, kMaxUnrolledMembers + 1>());
  return table;
}

struct LargerOf {
  double operator()(double best, double a) const { return std::max(best, a); }
};
struct SmallerOf {
  double operator()(double best, double a) const { return std::min(best, a); }
};
// Strictly larger |A| only: folded in ascending k, ties keep the smaller k.
struct LargerMagnitudeOf {
  double operator()(double best, double a) const {
    return std::fabs(a) > std::fabs(best) ? a : best;
  }
};

// The statistic over the members (sorted by ascending k) for a block of
// elements, member by member so that every loop is long and vectorised.
class EnsembleReducer {
 public:
  EnsembleReducer(std::vector<Member> members, const Statistic& statistic,
                  int64_t max_block)
      : members_(std::move(members)),
        statistic_(statistic),
        network_(statistic.kind == StatisticKind::kOrder
                     ? SelectionNetwork(static_cast<int>(members_.size()),
                                        statistic.order - 1)
                     : std::vector<std::pair<int, int>>()),
        max_block_(max_block),
        buffers_(
            (statistic.kind == StatisticKind::kOrder ? members_.size() : 1) *
            max_block) {}

  // Elements [begin, end), at most max_block of them; returns the block's
  // results, valid until the next call.
  const double* Reduce(const double* longest, const double* remaining,
                       int64_t begin, int64_t end) {
    switch (statistic_.kind) {
      case StatisticKind::kMax:
        return Running<LargerOf>(longest, remaining, begin, end);
      case StatisticKind::kMin:
        return Running<SmallerOf>(longest, remaining, begin, end);
      case StatisticKind::kMaxAbs:
        return Running<LargerMagnitudeOf>(longest, remaining, begin, end);
      case StatisticKind::kOrder:
        return SelectOrder(longest, remaining, begin, end);
      case StatisticKind::kGae:
        break;
    }
    return buffers_.data();
  }

 private:
  // max, min or maxabs: a running fold.
  template <typename Combine>
  const double* Running(const double* longest, const double* remaining,
                        int64_t begin, int64_t end) {
    double* acc = buffers_.data();
    const int count = static_cast<int>(members_.size());
    if (count > kMaxUnrolledMembers) {
      FoldMember(members_[0], longest, remaining, begin, end, acc, Assign);
      for (int m = 1; m < count; ++m) {
        FoldMember(members_[m], longest, remaining, begin, end, acc, Combine());
      }
      return acc;
    }
    // Split the block where a member leaves its range: members are sorted
    // by k, so the in-range ones are always a prefix, shrinking with i.
    int active = count;
    while (active > 0 && members_[active - 1].in_range_end <= begin) --active;
    for (int64_t i = begin; i < end;) {
      const int64_t segment_end =
          active > 0 ? std::min(end, members_[active - 1].in_range_end) : end;
      SegmentReducers<Combine>()[active][active < count ? 1 : 0](
          members_.data(), longest, remaining, i, segment_end,
          acc + (i - begin));
      i = segment_end;
      while (active > 0 && members_[active - 1].in_range_end <= i) --active;
    }
    return acc;
  }

  const double* SelectOrder(const double* longest, const double* remaining,
                            int64_t begin, int64_t end) {
    const int64_t len = end - begin;
    for (size_t m = 0; m < members_.size(); ++m) {
      FoldMember(members_[m], longest, remaining, begin, end,
                 buffers_.data() + m * max_block_, Assign);
    }
    for (const auto& [a, b] : network_) {
      double* __restrict lo = buffers_.data() + a * max_block_;
      double* __restrict hi = buffers_.data() + b * max_block_;
      for (int64_t j = 0; j < len; ++j) {
        const double x = lo[j];
        const double y = hi[j];
        lo[j] = std::min(x, y);
        hi[j] = std::max(x, y);
      }
    }
    return buffers_.data() + (statistic_.order - 1) * max_block_;
  }

  const std::vector<Member> members_;
  const Statistic statistic_;
  const std::vector<std::pair<int, int>> network_;
  const int64_t max_block_;
  std::vector<double> buffers_;
};

// True if any of the 32 flags starting at `flags` is set.
inline bool AnyOf32(const bool* flags) {
  uint64_t words[4];
  std::memcpy(words, flags, sizeof(words));
  return (words[0] | words[1] | words[2] | words[3]) != 0;
}

// delta and continues (1 if step t+1 belongs to t's episode inside the
// rollout, else 0) for rows [first_row, end_row), written from index 0.
template <typename Scalar>
void TdErrorRows(const RolloutView<Scalar>& rollout, double gamma,
                 int64_t first_row, int64_t end_row, double* __restrict delta,
                 double* __restrict continues) {
  const int64_t n = rollout.streams;
  const int64_t begin = first_row * n;
  const int64_t inner_end = std::min(end_row, rollout.steps - 1) * n;
  const int64_t end = end_row * n;
  const Scalar* __restrict r = rollout.rewards;
  const Scalar* __restrict v = rollout.values;
  // The common case, vectorised: no episode end, bootstrap from V(s_{t+1}),
  // and from V(s_T) on the rollout's last row.
  for (int64_t i = begin; i < inner_end; ++i) {
    delta[i - begin] = static_cast<double>(r[i]) +
                       gamma * static_cast<double>(v[i + n]) -
                       static_cast<double>(v[i]);
    continues[i - begin] = 1.0;
  }
  for (int64_t i = inner_end; i < end; ++i) {
    delta[i - begin] =
        static_cast<double>(r[i]) +
        gamma * static_cast<double>(rollout.last_values[i - inner_end]) -
        static_cast<double>(v[i]);
    continues[i - begin] = 0.0;
  }
  // Episode ends are rare: patch them, skipping 32 flag bytes at a time.
  const bool* terminated = rollout.terminated;
  const bool* truncated = rollout.truncated;
  for (int64_t chunk = begin; chunk < end; chunk += 32) {
    const int64_t chunk_end = std::min(end, chunk + 32);
    if (chunk_end - chunk == 32 && !AnyOf32(terminated + chunk) &&
        !AnyOf32(truncated + chunk)) {
      continue;
    }
    for (int64_t i = chunk; i < chunk_end; ++i) {
      if (!terminated[i] && !truncated[i]) continue;
      const double bootstrap =
          terminated[i] ? 0.0
                        : static_cast<double>(rollout.truncation_values[i]);
      delta[i - begin] = static_cast<double>(r[i]) + gamma * bootstrap -
                         static_cast<double>(v[i]);
      continues[i - begin] = 0.0;
    }
  }
}

// One backward step of GAE over a row of streams, kept in double in `row`
// and written to `out`:  gae_t = delta_t + decay * continues_t * gae_{t+1}.
// continues is 0 or 1 and everything is finite, so multiplying by it resets
// exactly and keeps the loop branch-free.
template <typename Out>
inline void GaeRow(int64_t streams, const double* __restrict delta,
                   const double* __restrict continues, double decay,
                   const double* __restrict next, double* __restrict row,
                   Out* __restrict out) {
  for (int64_t s = 0; s < streams; ++s) {
    row[s] = delta[s] + decay * continues[s] * next[s];
    out[s] = static_cast<Out>(row[s]);
  }
}

// One backward step of the basis: longest_t = delta_t + gamma * longest_{t+1}
// inside an episode (the telescoped sum of TD errors up to its end) and
// remaining_t = 1 + remaining_{t+1}, both reset where continues is 0.
inline void BasisRow(int64_t streams, const double* __restrict delta,
                     const double* __restrict continues, double gamma,
                     const double* __restrict next_longest,
                     const double* __restrict next_remaining,
                     double* __restrict longest, double* __restrict remaining) {
  for (int64_t s = 0; s < streams; ++s) {
    longest[s] = delta[s] + gamma * continues[s] * next_longest[s];
    remaining[s] = 1.0 + continues[s] * next_remaining[s];
  }
}

}  // namespace

template <typename Scalar, typename Out>
void RunEstimators(const RolloutView<Scalar>& rollout,
                   const EstimatorSettings& settings,
                   const EstimatorOutputs<Out>& outputs) {
  const int64_t steps = rollout.steps;
  const int64_t n = rollout.streams;
  const double gamma = settings.gamma;
  const double decay = settings.gamma * settings.lambda;
  const int64_t rows_per_block = std::max<int64_t>(1, kBlockElements / n);
  const int64_t block = rows_per_block * n;
  const bool want_basis = outputs.longest != nullptr;

  std::vector<double> scratch(2 * block + 2 * n, 0.0);
  double* delta = scratch.data();
  double* continues = delta + block;
  // GAE of the row after the current one; zero past the rollout's end,
  // where continues is 0 anyway.
  double* gae_next = continues + block;
  double* gae_row = gae_next + n;
  const std::vector<double> zeros(n, 0.0);

  std::vector<Member> members;
  for (int64_t k : settings.ensemble) {
    members.push_back(MakeMember(k, steps, n, gamma));
  }
  std::optional<EnsembleReducer> reducer;
  if (outputs.biased != nullptr) {
    reducer.emplace(std::move(members), settings.statistic, block);
  }

  // Backwards a block of rows at a time: each member reads rows t + k,
  // which are in this block or in one done before it.
  for (int64_t end_row = steps; end_row > 0;) {
    const int64_t first_row = std::max<int64_t>(0, end_row - rows_per_block);
    TdErrorRows(rollout, gamma, first_row, end_row, delta, continues);
    for (int64_t t = end_row - 1; t >= first_row; --t) {
      const double* d = delta + (t - first_row) * n;
      const double* c = continues + (t - first_row) * n;
      if (outputs.gae != nullptr) {
        GaeRow(n, d, c, decay, gae_next, gae_row, outputs.gae + t * n);
        std::swap(gae_next, gae_row);
      }
      if (want_basis) {
        const bool last = t + 1 == steps;
        BasisRow(n, d, c, gamma,
                 last ? zeros.data() : outputs.longest + (t + 1) * n,
                 last ? zeros.data() : outputs.remaining + (t + 1) * n,
                 outputs.longest + t * n, outputs.remaining + t * n);
      }
    }
    if (reducer.has_value()) {
      const int64_t begin = first_row * n;
      const int64_t end = end_row * n;
      const double* result =
          reducer->Reduce(outputs.longest, outputs.remaining, begin, end);
      for (int64_t i = begin; i < end; ++i) {
        outputs.biased[i] = static_cast<Out>(result[i - begin]);
      }
    }
    end_row = first_row;
  }
}

void KStepFromBasis(const double* longest, const double* remaining,
                    int64_t steps, int64_t streams, int64_t k, double gamma,
                    double* out) {
  FoldMember(MakeMember(k, steps, streams, gamma), longest, remaining, 0,
             steps * streams, out, Assign);
}

template void RunEstimators<float, float>(const RolloutView<float>&,
                                          const EstimatorSettings&,
                                          const EstimatorOutputs<float>&);
template void RunEstimators<double, double>(const RolloutView<double>&,
                                            const EstimatorSettings&,
                                            const EstimatorOutputs<double>&);

}  // namespace VANTAGE_KERNEL_ISA
}  // namespace vantage
