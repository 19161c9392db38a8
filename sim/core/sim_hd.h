#pragma once
// One kernel source for two backends: every per-element and per-node function is
// marked SIM_HD, which is __host__ __device__ under nvcc and nothing under g++, so the
// CPU backend loops over exactly the code the CUDA backend launches.
#if defined(__CUDACC__)
#define SIM_HD __host__ __device__
#else
#define SIM_HD
#endif
