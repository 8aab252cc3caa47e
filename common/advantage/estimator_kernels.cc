#include "common/advantage/estimator_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vantage {
namespace {

// Rows of the fused backward pass in EnsembleStatisticKernel hold about
// this many elements: the basis rows just computed are still in L1 when the
// statistic reads them.
constexpr int64_t kBlockElements = 1024;

// Four doubles: one AVX register, or two SSE2 ones on a baseline x86-64
// build. GCC's vector extensions keep this portable.
constexpr int kLanes = 2;
typedef double Vec __attribute__((vector_size(kLanes * sizeof(double))));

inline Vec Load(const double* p) {
  Vec v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline void Store(double* p, Vec v) { std::memcpy(p, &v, sizeof(v)); }
inline Vec Splat(double x) { return Vec{x, x}; }
inline Vec Max(Vec a, Vec b) { return a > b ? a : b; }
inline Vec Min(Vec a, Vec b) { return a < b ? a : b; }
inline Vec Abs(Vec a) { return a < Splat(0.0) ? -a : a; }

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

// A^(k)_i for an element before member.in_range_end. A select between two
// constants is what GCC vectorises; with a finite longest[],
// 0 * longest[i + offset] leaves longest[i] exact.
inline double KStepAt(const Member& member, const double* longest,
                      const double* remaining, int64_t i) {
  const double factor = member.k < remaining[i] ? member.gamma_k : 0.0;
  return longest[i] - factor * longest[i + member.offset];
}

// The basis rows [first_row, end_row), computed backwards; rows at or after
// end_row must be done already.
void BasisRows(int64_t steps, int64_t streams, const double* __restrict delta,
               const double* __restrict continues, double gamma,
               int64_t first_row, int64_t end_row, double* __restrict longest,
               double* __restrict remaining) {
  const int64_t n = streams;
  for (int64_t t = end_row - 1; t >= first_row; --t) {
    if (t == steps - 1) {
      for (int64_t i = t * n; i < (t + 1) * n; ++i) {
        longest[i] = delta[i];
        remaining[i] = 1.0;
      }
      continue;
    }
    // longest[t] = delta_t + gamma * longest[t+1] inside an episode: the
    // telescoped sum of TD errors up to the episode's or rollout's end.
    // continues[] is 0 or 1 and everything is finite, so multiplying by it
    // resets exactly and keeps the loop branch-free.
    for (int64_t i = t * n; i < (t + 1) * n; ++i) {
      longest[i] = delta[i] + gamma * continues[i] * longest[i + n];
      remaining[i] = continues[i] * remaining[i + n] + 1.0;
    }
  }
}

// The statistic over the members (sorted by ascending k) on flat elements.
class EnsembleReducer {
 public:
  EnsembleReducer(const std::vector<Member>& members,
                  const Statistic& statistic, const double* longest,
                  const double* remaining)
      : members_(members),
        statistic_(statistic),
        longest_(longest),
        remaining_(remaining),
        network_(statistic.kind == StatisticKind::kOrder
                     ? SortingNetwork(static_cast<int>(members.size()))
                     : std::vector<std::pair<int, int>>()),
        vector_scratch_(members.size()),
        scalar_scratch_(members.size()) {}

  // Elements [begin, end) into out[0, end - begin).
  void Reduce(int64_t begin, int64_t end, double* out) {
    const int count = static_cast<int>(members_.size());
    // Members are sorted by k, so their in_range_end decreases: the first
    // `active` are in range for the whole chunk, the rest collapse to the
    // longest estimate unless one straddles the chunk.
    int active = count;
    int64_t i = begin;
    for (; i + kLanes <= end; i += kLanes) {
      while (active > 0 && members_[active - 1].in_range_end < i + kLanes) {
        --active;
      }
      if (active < count && members_[active].in_range_end > i) {
        for (int64_t j = i; j < i + kLanes; ++j) out[j - begin] = ReduceOne(j);
        continue;
      }
      Store(out + (i - begin), ReduceChunk(i, active));
    }
    for (; i < end; ++i) out[i - begin] = ReduceOne(i);
  }

 private:
  inline Vec KStepChunk(const Member& member, Vec longest, Vec remaining,
                        int64_t i) const {
    const Vec factor =
        Splat(member.k) < remaining ? Splat(member.gamma_k) : Splat(0.0);
    return longest - factor * Load(longest_ + i + member.offset);
  }

  Vec ReduceChunk(int64_t i, int active) {
    const int count = static_cast<int>(members_.size());
    const Vec longest = Load(longest_ + i);
    const Vec remaining = Load(remaining_ + i);
    const bool collapsed = active < count;
    switch (statistic_.kind) {
      case StatisticKind::kMax: {
        // The collapsed members all equal the longest estimate.
        Vec best = collapsed ? longest
                             : KStepChunk(members_[0], longest, remaining, i);
        for (int m = collapsed ? 0 : 1; m < active; ++m) {
          best = Max(best, KStepChunk(members_[m], longest, remaining, i));
        }
        return best;
      }
      case StatisticKind::kMin: {
        // The collapsed members all equal the longest estimate.
        Vec best = collapsed ? longest
                             : KStepChunk(members_[0], longest, remaining, i);
        for (int m = collapsed ? 0 : 1; m < active; ++m) {
          best = Min(best, KStepChunk(members_[m], longest, remaining, i));
        }
        return best;
      }
      case StatisticKind::kMaxAbs: {
        // In ascending k, replacing only on a strictly larger |A|: ties go
        // to the smaller k. The collapsed members have the largest k.
        Vec best = active > 0 ? KStepChunk(members_[0], longest, remaining, i)
                              : longest;
        for (int m = 1; m < active; ++m) {
          const Vec a = KStepChunk(members_[m], longest, remaining, i);
          best = Abs(a) > Abs(best) ? a : best;
        }
        if (collapsed) best = Abs(longest) > Abs(best) ? longest : best;
        return best;
      }
      case StatisticKind::kOrder: {
        Vec* values = vector_scratch_.data();
        for (int m = 0; m < active; ++m) {
          values[m] = KStepChunk(members_[m], longest, remaining, i);
        }
        for (int m = active; m < count; ++m) values[m] = longest;
        for (const auto& [a, b] : network_) {
          const Vec x = values[a];
          const Vec y = values[b];
          values[a] = Min(x, y);
          values[b] = Max(x, y);
        }
        return values[statistic_.order - 1];
      }
      case StatisticKind::kGae:
        break;
    }
    return longest;
  }

  // The same statistic for one element, for chunks that straddle a
  // member's in_range_end and for the tail.
  double ReduceOne(int64_t i) {
    double* values = scalar_scratch_.data();
    const int count = static_cast<int>(members_.size());
    for (int m = 0; m < count; ++m) {
      values[m] = i < members_[m].in_range_end
                      ? KStepAt(members_[m], longest_, remaining_, i)
                      : longest_[i];
    }
    switch (statistic_.kind) {
      case StatisticKind::kMax:
        return *std::max_element(values, values + count);
      case StatisticKind::kMin:
        return *std::min_element(values, values + count);
      case StatisticKind::kMaxAbs: {
        double best = values[0];
        for (int m = 1; m < count; ++m) {
          if (std::fabs(values[m]) > std::fabs(best)) best = values[m];
        }
        return best;
      }
      case StatisticKind::kOrder:
        std::nth_element(values, values + statistic_.order - 1, values + count);
        return values[statistic_.order - 1];
      case StatisticKind::kGae:
        break;
    }
    return longest_[i];
  }

  const std::vector<Member>& members_;
  const Statistic statistic_;
  const double* longest_;
  const double* remaining_;
  const std::vector<std::pair<int, int>> network_;
  std::vector<Vec> vector_scratch_;
  std::vector<double> scalar_scratch_;
};

// True if any of the 8 flags starting at `flags` is set.
inline bool AnyOfEight(const bool* flags) {
  uint64_t word;
  std::memcpy(&word, flags, sizeof(word));
  return word != 0;
}

}  // namespace

template <typename Scalar>
void ComputeTdErrors(const RolloutView<Scalar>& rollout, double gamma,
                     double* __restrict delta, double* __restrict continues) {
  const int64_t n = rollout.streams;
  const int64_t total = rollout.steps * n;
  const int64_t last_row = total - n;
  const Scalar* __restrict r = rollout.rewards;
  const Scalar* __restrict v = rollout.values;
  // The common case, vectorised: no episode ends, bootstrap from V(s_{t+1})
  // and V(s_T) on the last row.
  for (int64_t i = 0; i < last_row; ++i) {
    delta[i] = static_cast<double>(r[i]) +
               gamma * static_cast<double>(v[i + n]) -
               static_cast<double>(v[i]);
    continues[i] = 1.0;
  }
  for (int64_t i = last_row; i < total; ++i) {
    delta[i] = static_cast<double>(r[i]) +
               gamma * static_cast<double>(rollout.last_values[i - last_row]) -
               static_cast<double>(v[i]);
    continues[i] = 0.0;
  }
  // Episode ends are rare: patch them, skipping 8 flag bytes at a time.
  const bool* terminated = rollout.terminated;
  const bool* truncated = rollout.truncated;
  for (int64_t begin = 0; begin < total; begin += 8) {
    if (begin + 8 <= total && !AnyOfEight(terminated + begin) &&
        !AnyOfEight(truncated + begin)) {
      continue;
    }
    for (int64_t i = begin; i < std::min(total, begin + 8); ++i) {
      if (!terminated[i] && !truncated[i]) continue;
      const double bootstrap =
          terminated[i] ? 0.0
                        : static_cast<double>(rollout.truncation_values[i]);
      delta[i] = static_cast<double>(r[i]) + gamma * bootstrap -
                 static_cast<double>(v[i]);
      continues[i] = 0.0;
    }
  }
}

template <typename Out>
void GaeKernel(int64_t steps, int64_t streams, const double* __restrict delta,
               const double* __restrict continues, double gamma, double lambda,
               Out* __restrict gae) {
  const double decay = gamma * lambda;
  // The running estimate of the next row, kept in double precision.
  std::vector<double> next(streams, 0.0);
  double* __restrict carry = next.data();
  for (int64_t t = steps - 1; t >= 0; --t) {
    const double* __restrict d = delta + t * streams;
    const double* __restrict c = continues + t * streams;
    Out* __restrict row = gae + t * streams;
    // continues[] is 0 or 1 and everything is finite, so multiplying by it
    // resets exactly and keeps the loop branch-free.
    for (int64_t s = 0; s < streams; ++s) {
      carry[s] = d[s] + decay * c[s] * carry[s];
      row[s] = static_cast<Out>(carry[s]);
    }
  }
}

void ComputePathEnsembleBasis(int64_t steps, int64_t streams,
                              const double* delta, const double* continues,
                              double gamma, double* longest,
                              double* remaining) {
  BasisRows(steps, streams, delta, continues, gamma, 0, steps, longest,
            remaining);
}

void KStepKernel(const PathEnsembleBasis& basis, int64_t steps, int64_t streams,
                 int64_t k, double gamma, double* __restrict out) {
  const Member member = MakeMember(k, steps, streams, gamma);
  for (int64_t i = 0; i < member.in_range_end; ++i) {
    out[i] = KStepAt(member, basis.longest, basis.remaining, i);
  }
  for (int64_t i = member.in_range_end; i < steps * streams; ++i) {
    out[i] = basis.longest[i];
  }
}

template <typename Out>
void EnsembleStatisticKernel(int64_t steps, int64_t streams,
                             const double* delta, const double* continues,
                             double gamma, const std::vector<int64_t>& ensemble,
                             const Statistic& statistic, double* longest,
                             double* remaining, Out* out) {
  std::vector<Member> members;
  for (int64_t k : ensemble) {
    members.push_back(MakeMember(k, steps, streams, gamma));
  }
  EnsembleReducer reducer(members, statistic, longest, remaining);
  const int64_t rows_per_block = std::max<int64_t>(1, kBlockElements / streams);
  std::vector<double> block(rows_per_block * streams);
  // Backwards, a block of rows at a time: each member reads rows t + k,
  // which are either in this block or in one done before it.
  for (int64_t end_row = steps; end_row > 0;) {
    const int64_t first_row = std::max<int64_t>(0, end_row - rows_per_block);
    BasisRows(steps, streams, delta, continues, gamma, first_row, end_row,
              longest, remaining);
    const int64_t begin = first_row * streams;
    const int64_t end = end_row * streams;
    reducer.Reduce(begin, end, block.data());
    for (int64_t i = begin; i < end; ++i) {
      out[i] = static_cast<Out>(block[i - begin]);
    }
    end_row = first_row;
  }
}

std::vector<std::pair<int, int>> SortingNetwork(int n) {
  std::vector<std::pair<int, int>> pairs;
  if (n < 2) return pairs;
  int top = 1;  // 2^(t-1) with t = ceil(log2 n), Knuth's Algorithm 5.2.2M
  while (2 * top < n) top *= 2;
  for (int p = top; p > 0; p /= 2) {
    int q = top;
    int r = 0;
    int d = p;
    while (true) {
      for (int i = 0; i + d < n; ++i) {
        if ((i & p) == r) pairs.emplace_back(i, i + d);
      }
      if (q == p) break;
      d = q - p;
      q /= 2;
      r = p;
    }
  }
  return pairs;
}

template void ComputeTdErrors<float>(const RolloutView<float>&, double, double*,
                                     double*);
template void ComputeTdErrors<double>(const RolloutView<double>&, double,
                                      double*, double*);
template void GaeKernel<float>(int64_t, int64_t, const double*, const double*,
                               double, double, float*);
template void GaeKernel<double>(int64_t, int64_t, const double*, const double*,
                                double, double, double*);
template void EnsembleStatisticKernel<float>(int64_t, int64_t, const double*,
                                             const double*, double,
                                             const std::vector<int64_t>&,
                                             const Statistic&, double*, double*,
                                             float*);
template void EnsembleStatisticKernel<double>(int64_t, int64_t, const double*,
                                              const double*, double,
                                              const std::vector<int64_t>&,
                                              const Statistic&, double*,
                                              double*, double*);

}  // namespace vantage
