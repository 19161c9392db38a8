#include "sim/solver/rest_state.h"

#include <stdexcept>

#include "sim/fem/tet_kinematics.h"
#include "sim/mesh/surface_mesh.h"

namespace softtled {

template <class T>
RestArrays<T> build_rest_state(const TetMesh& m, double rho, const std::vector<std::uint8_t>& flags) {
  RestArrays<T> r;
  const int ne = m.ntet(), n = m.nnode();
  if (int(flags.size()) != n) throw std::logic_error("build_rest_state: flags size");
  r.ntet = ne;
  r.nnode = n;
  r.X0.resize(3 * n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) r.X0[k * n + i] = T(m.X[3 * i + k]);
  r.tet.resize(4 * ne);
  r.dhdX.resize(12 * ne);
  r.vol.resize(ne);
  r.mass.assign(n, 0.0);
  for (int e = 0; e < ne; ++e) {
    const int* t = &m.tet[4 * e];
    for (int a = 0; a < 4; ++a) r.tet[a * ne + e] = t[a];
    double X[4][3], g[12];
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) X[a][k] = m.X[3 * t[a] + k];
    // In double on the mesh's positions, then rounded: derive_dhdX (tet_forces.h) repeats
    // exactly this on the GPU, where reading the table costs more than computing it.
    const double det = shape_gradients(X, g);
    if (!(det > 0)) throw InputError("element " + std::to_string(e) + " has non-positive rest volume");
    for (int c = 0; c < 12; ++c) r.dhdX[c * ne + e] = T(g[c]);
    const double V0 = det / 6.0;
    if (m.E_scale.empty()) {  // one material: exactly the one-body rest state
      r.vol[e] = T(V0);
      for (int a = 0; a < 4; ++a) r.mass[t[a]] += rho * V0 / 4.0;
    } else {  // per-body material (tet_mesh.h): stiffness through the volume, density per element
      r.vol[e] = T(V0 * m.E_scale[e]);
      for (int a = 0; a < 4; ++a) r.mass[t[a]] += rho * m.rho_scale[e] * V0 / 4.0;
    }
  }
  r.flags = flags;
  if (m.per_body_law) {
    r.tet_law.assign(m.tet_body.begin(), m.tet_body.end());
    r.node_law.assign(m.node_body.begin(), m.node_body.end());
  }
  r.inv_mass.resize(n);
  for (int i = 0; i < n; ++i) {
    if (!(r.mass[i] > 0)) throw InputError("node " + std::to_string(i) + " belongs to no element");
    r.inv_mass[i] = (flags[i] & kNodeFixed) ? T(0) : T(1.0 / r.mass[i]);
  }
  // Gather table: for each node the corner slots a * ne + e, in increasing element order,
  // so every run sums the same numbers in the same order.
  r.gather_start.assign(n + 1, 0);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < 4; ++a) ++r.gather_start[m.tet[4 * e + a] + 1];
  for (int i = 0; i < n; ++i) r.gather_start[i + 1] += r.gather_start[i];
  r.gather_slot.resize(4 * ne);
  std::vector<int> fill(r.gather_start.begin(), r.gather_start.end() - 1);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < 4; ++a) r.gather_slot[fill[m.tet[4 * e + a]]++] = a * ne + e;
  return r;
}

template RestArrays<float> build_rest_state<float>(const TetMesh&, double, const std::vector<std::uint8_t>&);
template RestArrays<double> build_rest_state<double>(const TetMesh&, double, const std::vector<std::uint8_t>&);

}  // namespace softtled
