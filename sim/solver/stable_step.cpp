#include "sim/solver/stable_step.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/core/input_error.h"
#include "sim/core/stop_request.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/host_forces.h"
#include "sim/solver/solver.h"

namespace softtled {

namespace {
// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal a and
// off-diagonal b, by bisection on Sturm counts (Golub & Van Loan, Matrix Computations,
// sec. 8.4.1): below(x) is the number of eigenvalues below x, the negative pivots of
// T - x I; the largest eigenvalue is where it reaches k.
double tridiagonal_max_eigenvalue(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t k = a.size();
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < k; ++i) {  // Gershgorin discs
    const double r = (i > 0 ? std::fabs(b[i - 1]) : 0.0) + (i + 1 < k ? std::fabs(b[i]) : 0.0);
    lo = std::min(lo, a[i] - r), hi = std::max(hi, a[i] + r);
  }
  auto below = [&](double x) {
    std::size_t count = 0;
    double d = 1;
    for (std::size_t i = 0; i < k; ++i) {
      d = a[i] - x - (i > 0 ? b[i - 1] * b[i - 1] / d : 0.0);
      if (d == 0) d = -1e-300;  // (x on an eigenvalue of a leading block: count it below)
      if (d < 0) ++count;
    }
    return count;
  };
  for (int it = 0; it < 200 && hi - lo > 1e-14 * std::max(std::fabs(lo), std::fabs(hi)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (below(mid) == k ? hi : lo) = mid;
  }
  return hi;
}
}  // namespace

double rest_eigen_scale(const TetMesh& m, double nu, int model, const std::vector<BodyLaw>& laws, int iterations) {
  // With E = rho = 1 the eigenvalue itself is the scale.
  const RestArrays<double> r = build_rest_state<double>(m, 1.0, std::vector<std::uint8_t>(m.nnode(), 0));
  const auto mat = neo_hookean_from_E_nu<double>(1.0, nu, model);
  std::vector<ElementLaw<double>> table;  // the T4 stiffness of each body's own nu and model
  for (const BodyLaw& l : laws) table.push_back({neo_hookean_from_E_nu<double>(1.0, l.nu, l.model), kT4});
  const int n = m.nnode();
  const double h = 1e-7 * measure_quality(m).min_Le;  // linearisation amplitude [m]
  // Lanczos on the symmetric B = M^-1/2 K M^-1/2, which has the eigenvalues of M^-1 K;
  // K y = (f(h y) - f(-h y)) / 2h, y scaled to max-norm 1 so h sets the amplitude. Its
  // largest Ritz value approaches omega_max^2 from below much faster than the power
  // iteration did: that one was 0.4-0.9 % short of a dense solve after 60 products on the
  // shipped tori (a probe's find), on the unsafe side of the step.
  std::vector<double> v(3 * n), v_prev(3 * n, 0.0), w(3 * n), y(3 * n), u(3 * n), fp(3 * n), fm(3 * n), isqm(n);
  for (int i = 0; i < n; ++i) isqm[i] = std::sqrt(r.inv_mass[i]);
  unsigned s = 12345u;  // deterministic, non-smooth start so the highest mode has a component
  double norm = 0;
  for (double& vi : v) {
    s = s * 1664525u + 1013904223u;
    vi = double(s >> 8) / double(1u << 24) - 0.5;
    norm += vi * vi;
  }
  for (double& vi : v) vi /= std::sqrt(norm);
  std::vector<double> alpha, beta;
  double beta_prev = 0, alpha_max = 0;
  for (int it = 0; it < iterations; ++it) {
    // Two force evaluations of the whole mesh per product: seconds on a 1M-tet mesh,
    // where a Ctrl-C waited for all of them (4.8 s). The CLI reports the stop.
    if (stop_request_pending()) throw InputError("stopped while estimating the stable step");
    double ymax = 0;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) ymax = std::max(ymax, std::fabs(y[k * n + i] = isqm[i] * v[k * n + i]));
    if (!(ymax > 0)) break;
    for (int q = 0; q < 3 * n; ++q) u[q] = h * y[q] / ymax;
    host_internal_forces(r, mat, kT4, u, fp, table);
    for (int q = 0; q < 3 * n; ++q) u[q] = -u[q];
    host_internal_forces(r, mat, kT4, u, fm, table);
    double a = 0;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const int q = k * n + i;
        w[q] = isqm[i] * (fp[q] - fm[q]) / (2 * h) * ymax;  // B v
        a += w[q] * v[q];
      }
    double bnorm = 0;
    for (int q = 0; q < 3 * n; ++q) {
      w[q] -= a * v[q] + beta_prev * v_prev[q];
      bnorm += w[q] * w[q];
    }
    alpha.push_back(a);
    alpha_max = std::max(alpha_max, std::fabs(a));
    const double b = std::sqrt(bnorm);
    if (!(b > 1e-12 * alpha_max)) break;  // an invariant subspace: its Ritz values are exact
    beta.push_back(b);
    for (int q = 0; q < 3 * n; ++q) v_prev[q] = v[q], v[q] = w[q] / b;
    beta_prev = b;
  }
  beta.resize(alpha.empty() ? 0 : alpha.size() - 1);
  return alpha.empty() ? 0.0 : tridiagonal_max_eigenvalue(alpha, beta);
}

double rayleigh_stable_step(double dt_cr, double beta) {
  if (!(beta > 0)) return dt_cr;
  const double xi = beta / dt_cr;
  return dt_cr * (std::sqrt(1 + xi * xi) - xi);
}

}  // namespace softtled
