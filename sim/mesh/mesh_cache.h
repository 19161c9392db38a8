#pragma once
// TetGen results cached on disk by content hash (surface coordinates and triangles plus
// the switches), so re-opening a scene does not re-mesh. TetGen is deterministic, so a
// cached mesh is the mesh TetGen would produce.
#include <string>

#include "sim/mesh/tetgen_mesher.h"

namespace softtled {

// $SOFTTLED_CACHE_DIR, else $XDG_CACHE_HOME/softtled, else ~/.cache/softtled.
std::string default_mesh_cache_dir();

// Like tetrahedralize_surface, reading and writing `dir` (created if missing; any cache
// I/O problem falls back to meshing). *hit tells whether the cache answered.
TetMesh cached_tetrahedralize(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir,
                              bool* hit = nullptr);

}  // namespace softtled
