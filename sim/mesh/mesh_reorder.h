#pragma once
// Spatially coherent numbering for the GPU: nodes in Morton (Z-curve) order of their rest
// positions, elements in Morton order of their centroids. Neighbouring threads then touch
// neighbouring memory in the element stage's reads of u and the node stage's gather of
// corner forces, which is what keeps a large mesh near the DRAM roofline. The CUDA
// solver permutes internally and hands the caller everything in the original numbering.
#include <vector>

#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct MeshPermutation {
  std::vector<int> node_new;  // nnode: old node -> new node
  std::vector<int> node_old;  // nnode: new node -> old node
  std::vector<int> tet_old;   // ntet: new element -> old element
};

MeshPermutation spatial_order(const TetMesh& m);
MeshPermutation identity_order(const TetMesh& m);

// The same mesh renumbered; corner order inside each element (its orientation) is kept.
TetMesh permute_mesh(const TetMesh& m, const MeshPermutation& p);

}  // namespace softtled
