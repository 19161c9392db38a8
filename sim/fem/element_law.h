#pragma once
// Per-body material laws: a body's own [body.material] nu, model or element (E and rho
// need no table: they enter through the rest state's volumes and masses, tet_mesh.h).
// Where some body has a law of its own the rest state carries each element's and each
// node's body (TetMeshView::tet_law / node_law) and the live table TetMeshView::laws holds
// one ElementLaw per body, resolved from the live parameters (step_params.h). Where none
// has, those are null and every loop reads the scene's one law, as before: the arrays
// and the table cost nothing there.
//
// The loop bodies of the element and node stages (tet_forces.h, anp.h, von_mises.h) and
// the fused CUDA step ask here for the law of the element or node at hand, so every
// backend gives each body its own material with the same value functions.
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/neo_hookean.h"

namespace softtled {

// kT4: linear tet; kT4ANP: average nodal pressure tet (anp.h).
enum ElementType : int { kT4 = 0, kT4ANP = 1 };

// One body's law: its Neo-Hookean material (E of the scene: the body's own E scales its
// volumes) and its element (ElementType).
template <class T>
struct ElementLaw {
  NeoHookean<T> mat;
  int element = 0;
};

// Element e's body's entry in m.laws (0 where no body has a law of its own).
template <class T>
SIM_HD inline int element_law_index(const TetMeshView<T>& m, int e) {
  return m.tet_law ? m.tet_law[e] : 0;
}

// The material of element e (mat: the scene's law, what a mesh without a table uses).
// Hot loops branch on m.tet_law themselves and pass mat on its own path: a reference
// that may be either (this function's) makes the GPU read the scene's law through a
// generic pointer instead of the kernel's parameters (+3 % on the two-kernel step).
template <class T>
SIM_HD inline const NeoHookean<T>& element_material(const TetMeshView<T>& m, const NeoHookean<T>& mat, int e) {
  return m.tet_law ? m.laws[m.tet_law[e]].mat : mat;
}
// The material of node i (T4ANP: the nodal pressure's bulk modulus).
template <class T>
SIM_HD inline const NeoHookean<T>& node_material(const TetMeshView<T>& m, const NeoHookean<T>& mat, int i) {
  return m.node_law ? m.laws[m.node_law[i]].mat : mat;
}
// Whether an element of law `law` (element_law_index) / node i takes its volumetric
// response from the nodes (T4ANP) in a step that runs the T4ANP stages: with a table, a T4
// body's elements keep their own.
template <class T>
SIM_HD inline bool law_uses_anp(const TetMeshView<T>& m, int law) {
  return !m.tet_law || m.laws[law].element == kT4ANP;
}
template <class T>
SIM_HD inline bool node_uses_anp(const TetMeshView<T>& m, int i) {
  return !m.node_law || m.laws[m.node_law[i]].element == kT4ANP;
}

}  // namespace softtled
