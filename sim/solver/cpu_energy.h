#pragma once
// Strain energy on the CPU, thread-count invariant: per-element (and, for T4ANP, per-node)
// energies into an array by OpenMP loops, then a sum in an order fixed by the array
// length alone. An OpenMP `reduction(+)` would add the threads' partial sums in an order
// that depends on the thread count, so the CSV's se and the watchdog's energy test would
// change with it (the CUDA backend sums in a fixed block tree for the same reason).
#include <vector>

#include "sim/core/body_view.h"
#include "sim/fem/anp.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/solver.h"

namespace softtled {

constexpr int kSumBlock = 1024;  // values per block of the fixed-order sum

// v[0] + ... + v[n-1]: each block of kSumBlock consecutive values summed in index order (the
// blocks in parallel), then the block sums in index order. The same bits for any thread
// count.
inline double fixed_order_sum(const std::vector<double>& v, int threads) {
  const int n = int(v.size()), nb = (n + kSumBlock - 1) / kSumBlock;
  std::vector<double> part(nb, 0.0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int b = 0; b < nb; ++b) {
    double s = 0;
    const int end = (b + 1) * kSumBlock < n ? (b + 1) * kSumBlock : n;
    for (int j = b * kSumBlock; j < end; ++j) s += v[j];
    part[b] = s;
  }
  double s = 0;
  for (double p : part) s += p;
  return s;
}

// Strain energy of the body at displacement u. T4: sum_e V0_e W(F_e). T4ANP: the energy
// its forces integrate (anp.h), sum_e V0_e W_dev(F_e) + sum_i V0_i kappa/2 (J_i - 1)^2.
// vol, terms: scratch (resized here).
template <class T>
inline double cpu_strain_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, int element, const T* u,
                                std::vector<T>& vol, std::vector<double>& terms, int threads) {
  const int ne = m.ntet, n = m.nnode;
  if (element != kT4ANP) {
    terms.resize(ne);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int e = 0; e < ne; ++e) terms[e] = double(element_strain_energy(m, mat, u, e));
    return fixed_order_sum(terms, threads);
  }
  terms.resize(std::size_t(ne) + n);
  vol.resize(ne);
#pragma omp parallel num_threads(threads)
  {
#pragma omp for schedule(static)
    for (int e = 0; e < ne; ++e) terms[e] = double(anp_element_energy(m, mat, u, vol.data(), e));
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) terms[std::size_t(ne) + i] = double(anp_node_energy(m, mat, vol.data(), i));
  }
  return fixed_order_sum(terms, threads);
}

}  // namespace softtled
