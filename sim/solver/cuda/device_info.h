#pragma once
// Device presence and the two numbers the bench compares against: the device's name and
// its measured copy bandwidth (the DRAM roofline the step's bytes are held to).
#include <cstddef>
#include <string>

namespace softtled::cuda {

// Number of CUDA devices; 0 with a one-line reason in *why when there are none or no
// driver (cudaErrorInsufficientDriver, 35, on a machine without a GPU).
int device_count(std::string* why = nullptr);

struct DeviceInfo {
  std::string name;
  int sm_count = 0;
  int cc_major = 0, cc_minor = 0;
  std::size_t l2_bytes = 0;
  std::size_t global_mem_bytes = 0;
  int driver_version = 0, runtime_version = 0;
};
DeviceInfo device_info(int device = 0);

// Grid-stride float4 copy between two buffers of `bytes` each: median over reps of
// (bytes read + bytes written) / time, in GB/s (1e9 B/s).
double measure_copy_bandwidth_gbs(std::size_t bytes = std::size_t(1) << 30, int reps = 15);

}  // namespace softtled::cuda
