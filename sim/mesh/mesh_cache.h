#pragma once
// TetGen results cached on disk by content hash (surface coordinates and triangles plus
// the switches), so re-opening a scene does not re-mesh. TetGen is deterministic, so a
// cached mesh is the mesh TetGen would produce. An entry is used only when it verifies:
// regular file, sizes matching the file, a checksum of the payload, valid tets using every
// node, the surface's volume, every surface vertex a node and no node outside the surface's
// bounding box, and a manifold boundary; otherwise the surface is meshed again and the
// entry overwritten.
#include <string>

#include "sim/mesh/tetgen_mesher.h"

namespace softtled {

// $SOFTTLED_CACHE_DIR, else $XDG_CACHE_HOME/softtled (an absolute path), else
// ~/.cache/softtled, else .softtled-cache; empty variables count as unset.
std::string default_mesh_cache_dir();

// The entry for this surface and these options (throws InputError for bad options).
std::string mesh_cache_path(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir);

// Like tetrahedralize_surface (the same checks and budget), reading and writing `dir`
// (created if missing; any cache I/O problem or unverified entry falls back to meshing).
// *hit tells whether the cache answered.
TetMesh cached_tetrahedralize(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir,
                              bool* hit = nullptr);

}  // namespace softtled
