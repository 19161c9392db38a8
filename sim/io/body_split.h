#pragma once
// One body of a mesh of several (concat_bodies) as a mesh and a state of its own, nodes and
// elements renumbered from 0: what the per-body outputs (VTU files, mesh statistics) write.
// Relies on concat_bodies' layout: each body's nodes and elements are contiguous, in body order.
#include "sim/mesh/tet_mesh.h"
#include "sim/solver/solver.h"

namespace softtled {

// Body b's nodes [node_begin, node_end) and elements [tet_begin, tet_end) in the whole
// mesh; a one-body mesh has one body, 0, spanning everything.
struct BodyRange {
  int node_begin = 0, node_end = 0, tet_begin = 0, tet_end = 0;
  int nnode() const { return node_end - node_begin; }
  int ntet() const { return tet_end - tet_begin; }
};
BodyRange body_range(const TetMesh& m, int b);

// Body b alone: X, tet, boundary_tri, surface_nodes, and its rho_scale / E_scale slices
// (still relative to the scene's [material]); node_body and tet_body empty.
TetMesh body_mesh(const TetMesh& m, int b);
// Body b's part of a state of the whole mesh (u, du: 3 x nnode, component-major).
HostState body_state(const TetMesh& m, const HostState& s, int b);

}  // namespace softtled
