#pragma once
// Plain view of a body's boundary as render vertices: one vertex per boundary node, the
// boundary triangles re-indexed to them, and each vertex's triangles (for normals).
// Built by mesh/surface_topology.h, read by fem/surface_render.h.

namespace softtled {

struct SurfaceView {
  int nvert = 0;                    // boundary nodes
  int ntri = 0;                     // boundary triangles
  const int* node = nullptr;        // nvert: mesh node of each render vertex
  const int* tri = nullptr;         // 3 x ntri interleaved, render-vertex indices, outward CCW
  const int* vtri_start = nullptr;  // nvert + 1: CSR offsets into vtri
  const int* vtri = nullptr;        // 3 x ntri: triangles touching each vertex
};

}  // namespace softtled
