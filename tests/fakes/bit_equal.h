#ifndef VANTAGE_TESTS_FAKES_BIT_EQUAL_H_
#define VANTAGE_TESTS_FAKES_BIT_EQUAL_H_

#include <ATen/core/Tensor.h>

#include <cstring>

#include "gtest/gtest.h"

namespace vantage {

// Same dtype, same shape and the same bytes: NaN payloads and signed zeros
// must survive a round trip, which a value comparison would not check.
inline ::testing::AssertionResult BitEqual(const at::Tensor& a,
                                           const at::Tensor& b) {
  if (a.defined() != b.defined()) {
    return ::testing::AssertionFailure() << "one tensor is undefined";
  }
  if (!a.defined()) return ::testing::AssertionSuccess();
  if (a.scalar_type() != b.scalar_type() || a.sizes() != b.sizes()) {
    return ::testing::AssertionFailure()
           << a.scalar_type() << a.sizes() << " vs " << b.scalar_type()
           << b.sizes();
  }
  const at::Tensor ca = a.contiguous();
  const at::Tensor cb = b.contiguous();
  if (ca.nbytes() > 0 &&
      std::memcmp(ca.data_ptr(), cb.data_ptr(), ca.nbytes()) != 0) {
    return ::testing::AssertionFailure() << "bytes differ";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_BIT_EQUAL_H_
