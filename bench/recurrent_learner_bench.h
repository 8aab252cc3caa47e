#ifndef VANTAGE_BENCH_RECURRENT_LEARNER_BENCH_H_
#define VANTAGE_BENCH_RECURRENT_LEARNER_BENCH_H_

#include "common/nn/network_config.h"

namespace vantage {

// `vantage bench learner --core=gru|lstm [--core_size=N]`: one PPO update
// of a recurrent policy on a HalfCheetah-sized batch (16 streams x 128
// steps, chunks of 16 steps, 32 minibatches of 4 chunks, 10 epochs, a 64x64
// tanh encoder, the core, both heads on it) through the learner's
// PpoUpdater vs a bare LibTorch loop doing the same with torch::nn::LSTM
// (or GRU) over each minibatch's chunks from their start states, one
// thread. Ends with `RESULT learner_recurrent core=C ppo_samples_per_s=<x>
// bare_samples_per_s=<y> ratio=<x/y>`. Returns the exit code.
int RunRecurrentLearnerBenchmark(const NetworkConfig& network);

}  // namespace vantage

#endif  // VANTAGE_BENCH_RECURRENT_LEARNER_BENCH_H_
