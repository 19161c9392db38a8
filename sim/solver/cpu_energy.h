#pragma once
// Strain energy on the CPU, thread-count invariant: per-element (and, for T4ANP, per-node)
// energies into an array by an OpenMP loop, then a sum in an order fixed by the array
// length alone. An OpenMP `reduction(+)` would add the threads' partial sums in an order
// that depends on the thread count, so the CSV's se and the watchdog's energy test would
// change with it (the CUDA backend sums in a fixed block tree for the same reason).
#include <vector>

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

}  // namespace softtled
