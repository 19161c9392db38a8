#pragma once
// One kernel source for two backends: every per-element and per-node function is
// marked SIM_HD, which is __host__ __device__ under nvcc and nothing under g++, so the
// CPU backend loops over exactly the code the CUDA backend launches.
#if defined(__CUDACC__)
#define SIM_HD __host__ __device__
#else
#define SIM_HD
#endif

// A rarely taken branch's function kept out of line on the device, so its registers do not
// count against the kernel that calls it (the step kernels are latency-bound: bench/NOTES.md).
#if defined(__CUDACC__)
#define SIM_NOINLINE __noinline__
#else
#define SIM_NOINLINE
#endif
