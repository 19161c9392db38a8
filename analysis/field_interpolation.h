#pragma once
// Samples a displacement field of one tet mesh at the rest positions of another (to
// compare solutions on different meshes): linear interpolation inside the containing
// tet; points just outside (surface faceting differs between meshes) use the tet whose
// barycentric coordinates are least negative, clamped.
#include <vector>

#include "sim/mesh/tet_mesh.h"

namespace softtled {

class FieldSampler {
 public:
  explicit FieldSampler(const TetMesh& mesh);
  // u: 3 x nnode SoA on `mesh`; points: 3 x npoints interleaved; returns 3 x npoints SoA.
  std::vector<double> sample(const std::vector<double>& u, const std::vector<double>& points) const;

 private:
  const TetMesh& m_;
  double lo_[3], cell_;
  int dims_[3];
  std::vector<int> cell_start_, cell_tets_;
};

}  // namespace softtled
