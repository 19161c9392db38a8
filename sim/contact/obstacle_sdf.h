#pragma once
// A rigid obstacle of any closed shape (shape = "mesh"): its signed distance, sampled once
// at start-up on a regular grid in the obstacle's own frame (mesh_sdf.h builds it on the
// host), read here by trilinear interpolation. obstacle_shapes.h turns a sample into the
// distance and outward normal the contact projection takes, as for the analytic shapes.
//
// The view is a plain value (a pointer and a few numbers, trivially copyable, no host
// types), so a backend passes it by value inside Obstacle<T> and points `value` at its
// own copy of the grid: host memory on the CPU, device memory for a GPU backend.
//
// Accuracy: the interpolant of a 1-Lipschitz function (an exact distance is one) differs
// from it by at most the weighted mean distance from the point to the cell's corners,
// i.e. at most sqrt(3)/2 cell (the grid holds exact distances within kSdfExactBandCells
// of the surface, so this holds wherever a point's cell lies in that band: every point
// within 2.27 cells; beyond, the nodes are upper bounds of at least the band, mesh_sdf.h); where the distance is linear over a cell (the cell sees
// one flat face only) the interpolant is exact. Its gradient is continuous inside a cell
// and jumps across cell faces, so the normal turns in steps of a cell on a curved surface.
#include "sim/core/sim_hd.h"

namespace softtled {

template <class T>
struct SdfGridView {
  const T* value = nullptr;  // n[0] x n[1] x n[2] signed distances [m] at the nodes, x fastest:
                             // node (i, j, k) at value[i + n[0] * (j + n[1] * k)]
  int n[3] = {0, 0, 0};      // nodes along x, y, z (each >= 2)
  T origin[3] = {T(0), T(0), T(0)};  // node (0, 0, 0) in the obstacle's frame [m]
  T cell = T(0);             // spacing of the nodes along every axis [m]
};

// The interpolant at the point of the grid's box nearest q (q itself when it is inside)
// and its gradient there, and the offset `out` from that point to q (zero inside). Beyond
// the box the caller adds |out| to the value (obstacle_shapes.h: continuous at the box).
template <class T>
struct SdfSample {
  T value;    // trilinear signed distance at the clamped point [m]
  T grad[3];  // its gradient (the trilinear cell's exact derivative)
  T out[3];   // q - clamped point [m]
};

template <class T>
SIM_HD inline SdfSample<T> sdf_sample(const SdfGridView<T>& g, const T q[3]) {
  SdfSample<T> s;
  int i[3];
  T f[3];
  for (int k = 0; k < 3; ++k) {
    const T hi = g.origin[k] + T(g.n[k] - 1) * g.cell;
    // Written so that NaN clamps to the origin (its offset `out` stays NaN, and so does
    // the distance: a NaN node is projected, as by the other shapes).
    const T p = q[k] > g.origin[k] ? (q[k] < hi ? q[k] : hi) : g.origin[k];
    s.out[k] = q[k] - p;
    const T t = (p - g.origin[k]) / g.cell;  // in [0, n - 1]
    int c = int(t);
    c = c < 0 ? 0 : (c > g.n[k] - 2 ? g.n[k] - 2 : c);
    i[k] = c;
    f[k] = t - T(c);
    f[k] = f[k] < T(0) ? T(0) : (f[k] > T(1) ? T(1) : f[k]);
  }
  const int sx = 1, sy = g.n[0], sz = g.n[0] * g.n[1];
  const T* v = g.value + i[0] + sy * i[1] + sz * i[2];
  const T v000 = v[0], v100 = v[sx], v010 = v[sy], v110 = v[sx + sy];
  const T v001 = v[sz], v101 = v[sx + sz], v011 = v[sy + sz], v111 = v[sx + sy + sz];
  // Along x first, then y, then z (the gradient's factors are the same lerps).
  const T a00 = v000 + f[0] * (v100 - v000), a10 = v010 + f[0] * (v110 - v010);
  const T a01 = v001 + f[0] * (v101 - v001), a11 = v011 + f[0] * (v111 - v011);
  const T b0 = a00 + f[1] * (a10 - a00), b1 = a01 + f[1] * (a11 - a01);
  s.value = b0 + f[2] * (b1 - b0);
  const T dx00 = v100 - v000, dx10 = v110 - v010, dx01 = v101 - v001, dx11 = v111 - v011;
  const T dx0 = dx00 + f[1] * (dx10 - dx00), dx1 = dx01 + f[1] * (dx11 - dx01);
  const T inv = T(1) / g.cell;
  s.grad[0] = (dx0 + f[2] * (dx1 - dx0)) * inv;
  s.grad[1] = ((a10 - a00) + f[2] * ((a11 - a01) - (a10 - a00))) * inv;
  s.grad[2] = (b1 - b0) * inv;
  return s;
}

}  // namespace softtled
