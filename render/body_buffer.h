#pragma once
// The body's GL vertex and index buffers: the one hand-off point between the solver and
// the renderer (sim/surface_render.h: 8 floats per boundary node).
//   - solver.render_buffer_on_device(): the CUDA solver writes straight into the GL buffer
//     through CUDA-OpenGL interop (map once per frame, write, unmap; no host copy). If the
//     GL context cannot be registered with CUDA (e.g. Mesa GL beside an NVIDIA GPU), a
//     device staging buffer is copied to the host and uploaded instead ("staging").
//   - otherwise the solver writes into a host array uploaded with glBufferSubData ("host").
#include <memory>
#include <string>
#include <vector>

#include "render/gl.h"
#include "sim/solver/solver.h"
#include "sim/mesh/surface_topology.h"

namespace softtled {

class CudaGlBuffer;

class BodyVertexBuffer {
 public:
  explicit BodyVertexBuffer(const SurfaceTopology& topo);
  ~BodyVertexBuffer();
  BodyVertexBuffer(const BodyVertexBuffer&) = delete;
  BodyVertexBuffer& operator=(const BodyVertexBuffer&) = delete;

  void update(Solver& solver);   // the per-frame hand-off
  void draw() const;             // triangles with the currently bound program
  const std::string& path() const { return path_; }  // "interop" | "staging" | "host" | "" (never updated)
  int nvert() const { return nvert_; }
  int ntri() const { return nindex_ / 3; }
  GLuint vbo() const { return vbo_; }

 private:
  GLuint vao_ = 0, vbo_ = 0, ibo_ = 0;
  int nvert_ = 0, nindex_ = 0;
  std::vector<float> host_;  // 8 x nvert, the host path's staging array
  std::unique_ptr<CudaGlBuffer> cuda_;
  std::string path_;
};

}  // namespace softtled
