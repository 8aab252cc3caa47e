#ifndef VANTAGE_BENCH_LEARNER_BENCH_H_
#define VANTAGE_BENCH_LEARNER_BENCH_H_

#include <string>

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
// The second replica of a running `bench learner`, at its rendezvous.
int RunLearnerBenchmarkReplica(const std::string& rendezvous);

}  // namespace vantage

#endif  // VANTAGE_BENCH_LEARNER_BENCH_H_
