#include "sim/core/input_error.h"
#include "sim/core/stop_request.h"
#include "sim/solver/stable_step.h"

#include <cmath>
#include <vector>

#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/host_forces.h"
#include "sim/solver/solver.h"

namespace softtled {

double rest_eigen_scale(const TetMesh& m, double nu, int model, const std::vector<BodyLaw>& laws, int iterations) {
  // With E = rho = 1 the eigenvalue itself is the scale.
  const RestArrays<double> r = build_rest_state<double>(m, 1.0, std::vector<std::uint8_t>(m.nnode(), 0));
  const auto mat = neo_hookean_from_E_nu<double>(1.0, nu, model);
  std::vector<ElementLaw<double>> table;  // the T4 stiffness of each body's own nu and model
  for (const BodyLaw& l : laws) table.push_back({neo_hookean_from_E_nu<double>(1.0, l.nu, l.model), kT4});
  const int n = m.nnode();
  const double h = 1e-7 * measure_quality(m).min_Le;  // linearisation amplitude [m]
  std::vector<double> x(3 * n), u(3 * n), fp(3 * n), fm(3 * n);
  // Deterministic, non-smooth start vector so the highest mode has a component.
  unsigned s = 12345u;
  for (double& xi : x) {
    s = s * 1664525u + 1013904223u;
    xi = double(s >> 8) / double(1u << 24) - 0.5;
  }
  auto forces = [&](double sign, std::vector<double>& f) {
    for (int i = 0; i < 3 * n; ++i) u[i] = sign * h * x[i];
    host_internal_forces(r, mat, kT4, u, f, table);
  };
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    // Two force evaluations of the whole mesh per iteration: seconds on a 1M-tet mesh,
    // where a Ctrl-C waited for all of them (4.8 s). The CLI reports the stop.
    if (stop_request_pending()) throw InputError("stopped while estimating the stable step");
    double nx = 0;
    for (double xi : x) nx = std::max(nx, std::fabs(xi));
    for (double& xi : x) xi /= nx;  // max-norm 1, so h sets the amplitude
    forces(+1, fp);
    forces(-1, fm);
    double num = 0, den = 0;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const double w = (fp[k * n + i] - fm[k * n + i]) / (2 * h) * r.inv_mass[i];  // M^-1 K x
        num += w * w;
        den += x[k * n + i] * x[k * n + i];
        x[k * n + i] = w;
      }
    lambda = std::sqrt(num / den);
  }
  return lambda;
}

double rayleigh_stable_step(double dt_cr, double beta) {
  if (!(beta > 0)) return dt_cr;
  const double xi = beta / dt_cr;
  return dt_cr * (std::sqrt(1 + xi * xi) - xi);
}

}  // namespace softtled
