#pragma once
// Procedural closed surfaces: the paper's torus and boxes/beams for tests.
#include "sim/mesh/surface_mesh.h"

namespace softtled {

// Generators refuse more triangles than this before allocating (the tet-count estimate
// for 1 M surface triangles is already the default mesh budget of 5 M tets).
constexpr long kMaxGeneratedTriangles = 1'000'000;

// Torus with its axis along z, centred at the origin: major radius R (centre of the tube),
// tube radius r, nu segments around the axis and nv around the tube, each quad split into
// two triangles. The paper's torus: R = 7.5 mm, r = 2.5 mm, 91 x 19 -> 1729 points,
// 3458 facets.
SurfaceMesh make_torus(double R, double r, int nu, int nv);

// Axis-aligned box centred at the origin with sides (lx, ly, lz), each face a grid of
// (nx, ny, nz) divisions along its two directions.
SurfaceMesh make_box(double lx, double ly, double lz, int nx, int ny, int nz);

// Sphere of radius r centred at the origin: an icosahedron subdivided `levels` times,
// vertices pushed to the sphere (20 * 4^levels triangles).
SurfaceMesh make_sphere(double r, int levels);

}  // namespace softtled
