#pragma once
// Render hand-off: the solver writes one vertex per boundary node straight into the
// renderer's vertex buffer (a mapped GL buffer on the GPU, host memory on the CPU).
// Vertex layout, 8 floats: position (3) [m], unit normal (3), the colour scalar, contact
// state. The colour scalar is the one the caller asks for (RenderScalar): |u| [m], or the
// node's von Mises stress [Pa] (von_mises.h: the mean of the Cauchy von Mises stress of the
// elements around the node, each with its own E).
// Normals are the area-weighted sum of the current normals of the adjacent boundary
// triangles, and the von Mises value the mean over the adjacent elements, each vertex
// recomputing its own faces and elements: no atomics, no second pass.
#include <cmath>
#include <cstdint>

#include "sim/core/body_view.h"
#include "sim/core/surface_view.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/von_mises.h"

namespace softtled {

constexpr int kRenderFloatsPerVertex = 8;

// What slot 6 of a render vertex holds.
enum class RenderScalar : int {
  kDisplacement = 0,  // |u| [m]
  kVonMises = 1,      // node_von_mises [Pa]
};

template <class T>
SIM_HD inline void node_position(const TetMeshView<T>& m, const T* u, int i, float x[3]) {
  const int n = m.nnode;
  for (int k = 0; k < 3; ++k) x[k] = float(m.X0[k * n + i] + u[k * n + i]);
}

// mat: the solver's material (its live parameters; each element's own E comes from the
// rest state, element_E_scale), read for RenderScalar::kVonMises only.
template <class T>
SIM_HD inline void write_render_vertex(const TetMeshView<T>& m, const SurfaceView& s, const T* u,
                                       const std::uint8_t* contact, RenderScalar scalar, const NeoHookean<T>& mat,
                                       float* dst, int v) {
  const int i = s.node[v];
  float x[3];
  node_position(m, u, i, x);
  float nrm[3] = {0.f, 0.f, 0.f};
  for (int j = s.vtri_start[v]; j < s.vtri_start[v + 1]; ++j) {
    const int t = s.vtri[j];
    float a[3], b[3], c[3];
    node_position(m, u, s.node[s.tri[3 * t]], a);
    node_position(m, u, s.node[s.tri[3 * t + 1]], b);
    node_position(m, u, s.node[s.tri[3 * t + 2]], c);
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    nrm[0] += e1[1] * e2[2] - e1[2] * e2[1];
    nrm[1] += e1[2] * e2[0] - e1[0] * e2[2];
    nrm[2] += e1[0] * e2[1] - e1[1] * e2[0];
  }
  const float len = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  const float inv = len > 0.f ? 1.f / len : 0.f;
  float* o = dst + kRenderFloatsPerVertex * v;
  o[0] = x[0];
  o[1] = x[1];
  o[2] = x[2];
  o[3] = nrm[0] * inv;
  o[4] = nrm[1] * inv;
  o[5] = nrm[2] * inv;
  if (scalar == RenderScalar::kVonMises) {
    o[6] = float(node_von_mises(m, mat, u, i));
  } else {
    const int n = m.nnode;
    const float ux = float(u[i]), uy = float(u[n + i]), uz = float(u[2 * n + i]);
    o[6] = sqrtf(ux * ux + uy * uy + uz * uz);
  }
  o[7] = float(contact[i]);
}

}  // namespace softtled
