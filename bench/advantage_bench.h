#ifndef VANTAGE_BENCH_ADVANTAGE_BENCH_H_
#define VANTAGE_BENCH_ADVANTAGE_BENCH_H_

#include <cstdint>

namespace vantage {

// `vantage bench advantages`: GAE alone against the path ensemble plus each
// statistic for |E| = 4 and |E| = 12 on one [steps, streams] float32 batch.
// Prints Google Benchmark's table, then a line per statistic and finally
// `RESULT advantages ratio_e4=<x> ratio_e12=<y> order_ratio_e4=<a>
// order_ratio_e12=<b>`: the time of the slowest of max/min/maxabs (and of
// order:d) over GAE's, fastest of 30 repetitions each. Returns the exit
// code.
int RunAdvantageBenchmark(int64_t steps, int64_t streams);

}  // namespace vantage

#endif  // VANTAGE_BENCH_ADVANTAGE_BENCH_H_
