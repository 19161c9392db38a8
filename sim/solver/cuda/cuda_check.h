#pragma once
// Every CUDA runtime call's return code is checked: a failure becomes a CudaError
// naming the call, the error and the source line (main() prints it and exits).
#include <cuda_runtime_api.h>

#include <stdexcept>
#include <string>

namespace softtled::cuda {

struct CudaError : std::runtime_error {
  cudaError_t code;
  CudaError(cudaError_t c, const std::string& what) : std::runtime_error(what), code(c) {}
};

inline void check(cudaError_t e, const char* call, const char* file, int line) {
  if (e == cudaSuccess) return;
  throw CudaError(e, std::string("CUDA error ") + std::to_string(int(e)) + " (" + cudaGetErrorName(e) + ": " +
                         cudaGetErrorString(e) + ") in " + call + " at " + file + ":" + std::to_string(line));
}

}  // namespace softtled::cuda

#define SOFTTLED_CUDA_CHECK(call) ::softtled::cuda::check((call), #call, __FILE__, __LINE__)
