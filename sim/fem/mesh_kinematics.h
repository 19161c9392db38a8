#pragma once
// F and J of one element of a TetMesh from a host displacement field, in double: for code
// that holds the mesh and a HostState rather than the solver's rest state (the VTU export,
// the host watchdog, tests). The value functions of tet_kinematics.h on the element's
// rest corners and corner displacements.
#include <vector>

#include "sim/core/mat3.h"
#include "sim/fem/tet_kinematics.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// u: 3 x nnode struct-of-arrays (component k of node i at [k * nnode + i]); null: rest.
inline Mat3<double> mesh_element_F(const TetMesh& m, const std::vector<double>* u, int e) {
  const int n = m.nnode();
  const int* t = &m.tet[4 * e];
  double X[4][3], ue[4][3];
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k) {
      X[a][k] = m.X[3 * t[a] + k];
      ue[a][k] = u ? (*u)[std::size_t(k) * n + t[a]] : 0.0;
    }
  return deformation_gradient_from_rest(X, ue);
}

inline double mesh_element_J(const TetMesh& m, const std::vector<double>& u, int e) {
  return volume_ratio(mesh_element_F(m, &u, e));
}

}  // namespace softtled
