#pragma once
// Surface loaders: OBJ, OFF, STL (ASCII and binary), chosen by file extension. Every
// malformed input throws InputError naming the file and the problem; the result is
// checked closed and manifold before it is returned.
//
// Polygon faces (OBJ "f" with more than 3 vertices, OFF faces) are triangulated by ear
// clipping in the polygon's best-fit plane, so concave faces keep their shape. OFF files
// may carry the optional header prefixes ST, C, N (texture, per-vertex colour, normals),
// per-face colour columns, comments, and the counts line with or without the edge count.
#include <cstdint>
#include <string>
#include <vector>

#include "sim/mesh/surface_mesh.h"

namespace softtled {

// Surface files larger than this are refused before they are read (a binary STL of
// 512 MiB holds 10 M triangles, twice what the default tet budget can mesh).
constexpr std::uint64_t kDefaultMaxSurfaceBytes = 512ull << 20;
// Polygon faces with more vertices than this are refused.
constexpr int kMaxPolygonVertices = 1000;

SurfaceMesh load_surface(const std::string& path, std::uint64_t max_bytes = kDefaultMaxSurfaceBytes);

// Reads a whole input file: regular files only (a directory, FIFO or device is refused
// before it is opened, so a FIFO cannot block), at most max_bytes. Errors name the path
// and carry the OS reason: "PATH: cannot open file: No such file or directory",
// "PATH: not a regular file (a directory)", "PATH: N bytes, above the limit of M bytes".
// check_only: only the stat checks (exists, regular file); returns "".
std::string read_input_file(const std::string& path, std::uint64_t max_bytes, bool check_only = false);
// InputError "NAME: N bytes, above the limit of M bytes for input files" when size > max_bytes
// (read_input_file's own check; also for input given as text, e.g. a scene from Python).
void check_input_size(const std::string& name, std::uint64_t size, std::uint64_t max_bytes);
// Whether the text starts with a UTF-8 byte order mark (which editors on Windows write);
// every text reader skips it.
bool has_bom(const std::string& d);
// The extension of the path's last component, lower case, without the dot ("" for none:
// "scenes.v2/ring" has none).
std::string lower_ext(const std::string& path);

// Appends the triangles of a simple polygon (indices into xyz, 3 x npoint) to `out`, by
// ear clipping in the polygon's best-fit plane (Newell normal), keeping its orientation.
// Returns false when the polygon has no such triangulation (it crosses itself, or it is
// degenerate: collinear or repeating vertices).
bool triangulate_polygon(const std::vector<double>& xyz, const std::vector<int>& poly, std::vector<int>& out);

// Parsers on an in-memory buffer (the fuzzers call these); `name` appears in messages.
SurfaceMesh parse_obj(const std::string& data, const std::string& name);
SurfaceMesh parse_off(const std::string& data, const std::string& name);
SurfaceMesh parse_stl(const std::string& data, const std::string& name);

// Throws InputError (with the OS reason) when the file cannot be written completely.
void write_obj(const SurfaceMesh& s, const std::string& path);

}  // namespace softtled
