#pragma once
// The CPU backend's step, one function per stage: OpenMP loops over the shared SIM_HD
// functions. Each loop is an orphaned `omp for` (OpenMP 5.2, sec. 11.5: a worksharing
// construct binds to the innermost enclosing parallel region), so CpuSolver::step calls
// the stages inside one parallel region for many steps, and the bench times each stage
// alone inside a region of its own. Called outside any parallel region they run serially.
// Each iteration writes only its own element's corners or its own node, and the gather
// sums in a fixed order: bitwise identical results for any thread count.
#include "sim/core/body_view.h"
#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/solver.h"

namespace softtled {

// Scratch arrays of the T4ANP element stage.
template <class T>
struct AnpScratch {
  T* vol_now = nullptr;  // ntet, V0_e J_e of the current step
  T* p_node = nullptr;   // nnode, nodal pressure kappa (J_i - 1)
};

// Element stage: corner forces into fcorner. element: ElementType (T4: one loop; T4ANP:
// element volumes, nodal pressures, corner forces). u: the displacement the forces are
// taken at (b.u, or b.ub with stiffness-proportional damping: element_displacement).
template <class T>
inline void cpu_element_stage(const TetMeshView<T>& m, const NeoHookean<T>& mat, int element, const T* u,
                              const AnpScratch<T>& anp, T* fcorner) {
  const int ne = m.ntet, n = m.nnode;
  if (element == kT4ANP) {
#pragma omp for schedule(static)
    for (int e = 0; e < ne; ++e) anp_element_volume(m, u, anp.vol_now, e);
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) anp_node_pressure(m, mat, anp.vol_now, anp.p_node, i);
#pragma omp for schedule(static)
    for (int e = 0; e < ne; ++e) anp_corner_forces(m, mat, u, anp.p_node, fcorner, e);
    return;
  }
#pragma omp for schedule(static)
  for (int e = 0; e < ne; ++e) element_corner_forces(m, mat, u, fcorner, e);
}

// What the element stage reads: u, or u + (beta / dt) du where beta > 0 (b.ub).
template <class T>
inline const T* element_displacement(const BodyStateView<T>& b) {
  return b.ub ? b.ub : b.u;
}

// Node stage: gather, central difference and contact, in place on b (and b.ub when set).
template <class T>
inline void cpu_node_stage(const TetMeshView<T>& m, const BodyStateView<T>& b, const StepParams<T>& p) {
  const int n = m.nnode;
#pragma omp for schedule(static)
  for (int i = 0; i < n; ++i) {
    T f[3];
    gather_node_force(m.gather_start, m.gather_slot, b.fcorner, i, f);
    update_node(m, p, f, b.u, b.du, b.fext, b.u, b.du, b.contact, i, b.ub);
  }
}

}  // namespace softtled
