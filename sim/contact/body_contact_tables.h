#pragma once
// What body-body and self-contact (body_contact.h) need of the mesh, built once at start-up
// and shared by both backends (the CUDA one renumbers the nodes as it uploads them), so
// both test the same triangles with the same tolerance and grid cell.
#include <vector>

#include "sim/contact/body_contact.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct BodyContactTables {
  int nnode = 0, nbody = 1;
  std::vector<int> node_body;   // nnode (all 0 for one body)
  std::vector<int> surf;        // surface nodes, sorted
  std::vector<int> tri;         // 3 x ntri boundary triangles (outward), the mesh's order
  std::vector<int> tri_body;    // ntri
  // Per surface node (CSR over surf): the boundary triangles it is a corner of, ascending
  // (the faces around it, body_contact.h: opposed).
  std::vector<int> surf_tri_start, surf_tri;
  // Contact thickness, per body: a node up to a pair's tolerance (pair_tolerance: the
  // smaller of its two bodies') behind a triangle is pushed back (an earlier step's
  // residual penetration); deeper means it is on the other side of a thin part, or not this
  // triangle's. A tenth of the body's mean boundary edge (residual penetrations measured at
  // ~0.1 um in the shipped scenes).
  std::vector<double> body_tol;
  // Grid cell: between the mean and the longest boundary edge (fewest entries scanned on
  // the coarse tori).
  double cell = 1;
  int ntri() const { return static_cast<int>(tri_body.size()); }
};

BodyContactTables build_body_contact_tables(const TetMesh& m);

// The most triangles one bucket of a hash grid of `buckets` (a power of two) buckets holds
// with the mesh at rest (X: 3 per node, interleaved), each triangle's box inflated by its
// body's triangle_inflation_of and entered once per bucket, every triangle in (the GPU
// grid's rule, tled_contact.cu contact_grid_kernel). What the GPU's bucket lists are sized
// from.
int fullest_bucket_at_rest(const BodyContactTables& t, const std::vector<double>& X, unsigned buckets);

// The cross products of the boundary triangles around surface node surf[s] (x: positions,
// 3 per node, interleaved), in the tables' order, into out (body_contact.h, faces_some).
template <class T>
void crosses_around(const BodyContactTables& t, std::size_t s, const T* x, std::vector<T>& out) {
  out.clear();
  for (int q = t.surf_tri_start[s]; q < t.surf_tri_start[s + 1]; ++q) {
    const int* v = &t.tri[3 * t.surf_tri[q]];
    T c[3];
    triangle_cross(&x[3 * v[0]], &x[3 * v[1]], &x[3 * v[2]], c);
    out.insert(out.end(), c, c + 3);
  }
}

}  // namespace softtled
