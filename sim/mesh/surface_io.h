#pragma once
// Surface loaders: OBJ, OFF, STL (ASCII and binary), chosen by file extension. Every
// malformed input throws InputError naming the file and the problem; the result is
// checked closed and manifold before it is returned.
#include <string>

#include "sim/mesh/surface_mesh.h"

namespace softtled {

SurfaceMesh load_surface(const std::string& path);

// Parsers on an in-memory buffer (the fuzzers call these); `name` appears in messages.
SurfaceMesh parse_obj(const std::string& data, const std::string& name);
SurfaceMesh parse_off(const std::string& data, const std::string& name);
SurfaceMesh parse_stl(const std::string& data, const std::string& name);

void write_obj(const SurfaceMesh& s, const std::string& path);

}  // namespace softtled
