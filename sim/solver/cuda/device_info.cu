#include <algorithm>
#include <vector>

#include "sim/solver/cuda/cuda_check.h"
#include "sim/solver/cuda/device_buffer.h"
#include "sim/solver/cuda/device_info.h"

namespace softtled::cuda {
namespace {

__global__ void copy_float4_kernel(const float4* __restrict__ src, float4* __restrict__ dst, std::size_t n) {
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x)
    dst[i] = src[i];
}

__global__ void fill_kernel(float4* dst, std::size_t n) {
  for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x)
    dst[i] = make_float4(float(i & 1023), 1.f, 2.f, 3.f);  // not zeros
}

}  // namespace

int device_count(std::string* why) {
  int n = 0;
  const cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess) {
    cudaGetLastError();  // clear the sticky-free error state
    if (why) *why = std::string("no usable CUDA device (cudaGetDeviceCount: ") + cudaGetErrorName(e) + ", " + std::to_string(int(e)) + ")";
    return 0;
  }
  if (n == 0 && why) *why = "no CUDA device found";
  return n;
}

DeviceInfo device_info(int device) {
  cudaDeviceProp p{};
  SOFTTLED_CUDA_CHECK(cudaGetDeviceProperties(&p, device));
  DeviceInfo d;
  d.name = p.name;
  d.sm_count = p.multiProcessorCount;
  d.cc_major = p.major;
  d.cc_minor = p.minor;
  d.l2_bytes = std::size_t(p.l2CacheSize);
  d.global_mem_bytes = p.totalGlobalMem;
  SOFTTLED_CUDA_CHECK(cudaDriverGetVersion(&d.driver_version));
  SOFTTLED_CUDA_CHECK(cudaRuntimeGetVersion(&d.runtime_version));
  return d;
}

double measure_copy_bandwidth_gbs(std::size_t bytes, int reps) {
  const std::size_t n = bytes / sizeof(float4);
  DeviceBuffer<float4> a(n), b(n);
  int dev = 0, nsm = 0;
  SOFTTLED_CUDA_CHECK(cudaGetDevice(&dev));
  SOFTTLED_CUDA_CHECK(cudaDeviceGetAttribute(&nsm, cudaDevAttrMultiProcessorCount, dev));
  const int grid = nsm * 8, block = 512;
  fill_kernel<<<grid, block>>>(a.data(), n);
  SOFTTLED_CUDA_CHECK(cudaGetLastError());
  cudaEvent_t t0, t1;
  SOFTTLED_CUDA_CHECK(cudaEventCreate(&t0));
  SOFTTLED_CUDA_CHECK(cudaEventCreate(&t1));
  std::vector<float> ms;
  for (int r = 0; r < reps + 2; ++r) {
    SOFTTLED_CUDA_CHECK(cudaEventRecord(t0));
    copy_float4_kernel<<<grid, block>>>(r % 2 ? b.data() : a.data(), r % 2 ? a.data() : b.data(), n);
    SOFTTLED_CUDA_CHECK(cudaGetLastError());
    SOFTTLED_CUDA_CHECK(cudaEventRecord(t1));
    SOFTTLED_CUDA_CHECK(cudaEventSynchronize(t1));
    float t = 0;
    SOFTTLED_CUDA_CHECK(cudaEventElapsedTime(&t, t0, t1));
    if (r >= 2) ms.push_back(t);  // two warm-ups
  }
  SOFTTLED_CUDA_CHECK(cudaEventDestroy(t0));
  SOFTTLED_CUDA_CHECK(cudaEventDestroy(t1));
  std::sort(ms.begin(), ms.end());
  const double med = ms[ms.size() / 2] * 1e-3;
  return 2.0 * double(n * sizeof(float4)) / med * 1e-9;
}

}  // namespace softtled::cuda
