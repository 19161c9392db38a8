#pragma once
// Shared by the CUDA test files: skip without a device, build a simulation on a backend or
// in a CUDA execution mode, and compare two runs' states.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "scene_helpers.h"
#include "sim/solver/cuda/cuda_solver.h"
#include "sim/solver/cuda/device_info.h"
#include "sim/scene/simulation.h"
#include "sim/scene/solver_access.h"

#define SKIP_WITHOUT_GPU()                                                              \
  do {                                                                                  \
    std::string why;                                                                    \
    if (softtled::cuda::device_count(&why) <= 0) GTEST_SKIP() << "CUDA tests: " << why; \
  } while (0)

namespace softtled::test {

inline std::unique_ptr<Simulation> make_sim(const Scene& s, const std::string& backend) {
  auto sim = std::make_unique<Simulation>(s, backend);
  if (backend == "cpu") SolverAccess::of(*sim).set_cpu_threads(std::min(8, omp_get_max_threads()));
  return sim;
}

// A CUDA simulation in the given execution mode.
inline std::unique_ptr<Simulation> make_gpu(const Scene& s, cuda::ExecMode m) {
  auto sim = make_sim(s, "cuda");
  auto* api = dynamic_cast<cuda::CudaSolverApi*>(&SolverAccess::of(*sim));
  if (!api) throw std::runtime_error("not the CUDA backend");
  api->set_exec_mode(m);
  return sim;
}

// Largest node position difference [m].
inline double max_diff(Simulation& a, Simulation& b) {
  HostState sa, sb;
  sa = a.state();
  sb = b.state();
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

// Every execution mode (graph-pdl twice, graph, fused, multi, halo, auto) from the same start, at 8, 4
// and 1 lanes per node: within a lane count the runs must be bitwise identical; another
// lane count sums in another (fixed) order, so it may differ by rounding only (lanes_tol,
// 1e-6 m by default). check_mode(requested, api) asserts which mode the solver actually runs.
template <class CheckMode>
void expect_modes_bitwise_identical(const Scene& s, long steps, const std::string& label, CheckMode&& check_mode,
                                    double lanes_tol = 1e-6) {
  HostState lanes8;
  for (int lanes : {8, 4, 1}) {
    HostState ref;
    bool have_ref = false;
    for (cuda::ExecMode m : {cuda::ExecMode::kGraphPdl, cuda::ExecMode::kGraphPdl, cuda::ExecMode::kGraph,
                             cuda::ExecMode::kFused, cuda::ExecMode::kMulti, cuda::ExecMode::kHalo,
                             cuda::ExecMode::kAuto}) {
      auto sim = make_sim(s, "cuda");
      auto* api = dynamic_cast<cuda::CudaSolverApi*>(&SolverAccess::of(*sim));
      ASSERT_NE(api, nullptr);
      api->set_exec_mode(m);
      api->set_node_lanes(lanes);
      check_mode(m, *api);
      // Uneven chunks exercise the graph decomposition (K-step graphs plus powers of two).
      for (long done = 0; done < steps;) {
        const long n = std::min(steps - done, 37 + done % 300);
        sim->step(n);
        done += n;
      }
      HostState st = sim->state();
      if (!have_ref) {
        ref = st;
        have_ref = true;
        continue;
      }
      EXPECT_TRUE(bitwise_equal(st, ref)) << label << "lanes " << lanes << ": mode " << cuda::exec_mode_name(m)
                                          << " differs from graph-pdl";
    }
    if (lanes == 8) {
      lanes8 = ref;
    } else {
      double worst = 0;
      for (std::size_t j = 0; j < ref.u.size(); ++j) worst = std::max(worst, std::abs(ref.u[j] - lanes8.u[j]));
      std::printf("%slanes %d vs 8: max |u| difference %.3g m after %ld steps\n", label.c_str(), lanes, worst, steps);
      EXPECT_LT(worst, lanes_tol);
    }
  }
}

}  // namespace softtled::test
