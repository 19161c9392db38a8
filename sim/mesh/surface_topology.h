#pragma once
// Host-side tables behind SurfaceView: boundary nodes as render vertices, boundary
// triangles re-indexed to them, and the vertex -> triangle table for normals.
#include <vector>

#include "sim/core/surface_view.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct SurfaceTopology {
  std::vector<int> node, tri, vtri_start, vtri;
  SurfaceView view() const {
    SurfaceView s;
    s.nvert = int(node.size());
    s.ntri = int(tri.size() / 3);
    s.node = node.data();
    s.tri = tri.data();
    s.vtri_start = vtri_start.data();
    s.vtri = vtri.data();
    return s;
  }
};

SurfaceTopology build_surface_topology(const TetMesh& m);

}  // namespace softtled
