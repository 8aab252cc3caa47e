#ifndef VANTAGE_BENCH_LEARNER_BENCH_H_
#define VANTAGE_BENCH_LEARNER_BENCH_H_

#include <cstdint>
#include <string>
#include <vector>

namespace vantage {

// `vantage bench learner`: one PPO update of a HalfCheetah-sized batch
// (2048 samples, 32 minibatches, 10 epochs, 64x64 networks) through the
// learner's PpoUpdater vs a bare LibTorch loop doing the same forward,
// backward and Adam steps on the same shapes, one thread; ends with
// `RESULT learner ppo_samples_per_s=<x> bare_samples_per_s=<y> ratio=<x/y>`
// (samples = minibatch rows processed, epochs included).
// Also measures two data-parallel replicas (the second a child process
// running RunLearnerBenchmarkReplica) and names the BLAS in use.
int RunLearnerBenchmark();
// The second replica of a running `bench learner` or `bench
// learner_scaling` (`minibatch` > 0: the scaling sweep's shape with that
// minibatch size), at its rendezvous.
int RunLearnerBenchmarkReplica(const std::string& rendezvous,
                               int64_t minibatch = 0);

// `vantage bench learner_scaling`: samples/s of PPO updates of 8192
// samples against the minibatch size, for one learner at each of
// `thread_counts` intra-op threads and for two data-parallel replicas
// (processes, one thread each); where the paper's minibatch of 64 stops
// scaling, and what a larger one buys.
int RunLearnerScalingBenchmark(const std::vector<int64_t>& minibatches,
                               const std::vector<int>& thread_counts);

}  // namespace vantage

#endif  // VANTAGE_BENCH_LEARNER_BENCH_H_
