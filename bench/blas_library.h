#ifndef VANTAGE_BENCH_BLAS_LIBRARY_H_
#define VANTAGE_BENCH_BLAS_LIBRARY_H_

#include <string>

namespace vantage {

// The BLAS this process's LibTorch runs its GEMMs on: LibTorch links
// libblas.so.3, which Debian's alternatives point at the reference BLAS or
// at an optimised one (OpenBLAS).
struct BlasLibrary {
  std::string path;  // the mapped file, symlinks resolved; empty: none found
  // "openblas" (with its build configuration in `details`), "reference"
  // (netlib's) or "other".
  std::string kind;
  std::string details;
};

BlasLibrary LoadedBlasLibrary();

}  // namespace vantage

#endif  // VANTAGE_BENCH_BLAS_LIBRARY_H_
