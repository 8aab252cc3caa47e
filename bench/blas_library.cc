#include "bench/blas_library.h"

#include <dlfcn.h>

#include <filesystem>

namespace vantage {

BlasLibrary LoadedBlasLibrary() {
  BlasLibrary blas;
  // The library LibTorch's float GEMM calls resolve to: with Debian's
  // alternatives, libblas.so.3 and liblapack.so.3 may each be another
  // implementation, and the first one loaded that defines sgemm_ wins.
  void* sgemm = dlsym(RTLD_DEFAULT, "sgemm_");
  Dl_info info{};
  if (sgemm == nullptr || dladdr(sgemm, &info) == 0 ||
      info.dli_fname == nullptr) {
    blas.kind = "none";
    return blas;
  }
  std::error_code error;
  const std::filesystem::path real =
      std::filesystem::canonical(info.dli_fname, error);
  blas.path = error ? std::string(info.dli_fname) : real.string();
  if (blas.path.find("openblas") != std::string::npos) {
    blas.kind = "openblas";
    // OpenBLAS names its build (version, kernel, threading) on request.
    using GetConfig = char* (*)();
    if (auto* get_config = reinterpret_cast<GetConfig>(
            dlsym(RTLD_DEFAULT, "openblas_get_config"));
        get_config != nullptr) {
      blas.details = get_config();
    }
  } else if (blas.path.find("/blas/") != std::string::npos) {
    blas.kind = "reference";
    blas.details = "netlib reference BLAS";
  } else {
    blas.kind = "other";
  }
  return blas;
}

}  // namespace vantage
