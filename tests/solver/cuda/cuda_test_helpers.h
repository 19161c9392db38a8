#pragma once
// Shared by the CUDA test files: skip without a device, build a simulation on a backend or
// in a CUDA execution mode, and compare two runs' states.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "scene_helpers.h"
#include "sim/solver/cuda/cuda_solver.h"
#include "sim/solver/cuda/device_info.h"
#include "sim/scene/simulation.h"

#define SKIP_WITHOUT_GPU()                                                              \
  do {                                                                                  \
    std::string why;                                                                    \
    if (softtled::cuda::device_count(&why) <= 0) GTEST_SKIP() << "CUDA tests: " << why; \
  } while (0)

namespace softtled::test {

inline std::unique_ptr<Simulation> make_sim(const Scene& s, const std::string& backend) {
  auto sim = std::make_unique<Simulation>(s, backend);
  if (backend == "cpu") sim->solver().set_cpu_threads(std::min(8, omp_get_max_threads()));
  return sim;
}

// A CUDA simulation in the given execution mode.
inline std::unique_ptr<Simulation> make_gpu(const Scene& s, cuda::ExecMode m) {
  auto sim = make_sim(s, "cuda");
  auto* api = dynamic_cast<cuda::CudaSolverApi*>(&sim->solver());
  if (!api) throw std::runtime_error("not the CUDA backend");
  api->set_exec_mode(m);
  return sim;
}

// Largest node position difference [m].
inline double max_diff(Simulation& a, Simulation& b) {
  HostState sa, sb;
  a.solver().get_state(sa);
  b.solver().get_state(sb);
  const int n = a.mesh().nnode();
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = sa.u[k * n + i] - sb.u[k * n + i];
      d2 += d * d;
    }
    worst = std::max(worst, std::sqrt(d2));
  }
  return worst;
}

inline bool bitwise_equal(const HostState& a, const HostState& b) {
  return a.u.size() == b.u.size() && a.du.size() == b.du.size() && a.contact == b.contact &&
         std::memcmp(a.u.data(), b.u.data(), a.u.size() * sizeof(double)) == 0 &&
         std::memcmp(a.du.data(), b.du.data(), a.du.size() * sizeof(double)) == 0;
}

}  // namespace softtled::test
