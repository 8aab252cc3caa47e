#ifndef VANTAGE_COMMON_NN_CPU_SAMPLING_H_
#define VANTAGE_COMMON_NN_CPU_SAMPLING_H_

// Draws from a CPU generator as LibTorch's own CPU kernels do, for code
// that samples without tensors: the same calls consume the same numbers
// from the stream (so a generator saved and restored continues as it
// would have) and give the same values up to the last bits of LibTorch's
// vectorised log, sin and cos.

#include <ATen/core/Generator.h>

#include <cstdint>

namespace vantage {

// What at::normal(0, 1, {n}, generator) of float32 holds: n standard normal
// draws.
void FillStandardNormal(at::Generator& generator, float* out, int64_t n);

// For each of `rows` rows of `probabilities` [rows, n] (non-negative, not
// all zero), the index at::multinomial(probabilities, 1, false, generator)
// picks: the argmax of p / q over Exp(1) draws q.
void SampleCategorical(at::Generator& generator, const float* probabilities,
                       int64_t rows, int64_t n, int64_t* out);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_CPU_SAMPLING_H_
