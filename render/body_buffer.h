#pragma once
// The body's GL vertex and index buffers: the one hand-off point between whoever computes
// the body (the app asks its simulation) and the renderer. Once per frame the producer
// writes every vertex between map() and unmap():
//   - map(true) returns a device pointer: the GL buffer itself through CUDA-OpenGL interop
//     ("interop", no host copy). If the GL context cannot be registered with CUDA (e.g.
//     Mesa GL beside an NVIDIA GPU), a device staging buffer that unmap() copies to the
//     host and uploads ("staging").
//   - map(false) returns a host array that unmap() uploads with glBufferSubData ("host").
#include <memory>
#include <string>
#include <vector>

#include "render/gl.h"

namespace softtled {

// Vertex layout: position (3) [m], unit normal (3), the colour scalar (|u| [m] or von
// Mises stress [Pa]: what the producer was asked for, ColorMode), contact state (0 free,
// 1 stick, 2 slide), all float.
constexpr int kBodyFloatsPerVertex = 8;
constexpr int kBodyScalarSlot = 6;

class CudaGlBuffer;

class BodyVertexBuffer {
 public:
  // nvert vertices; tri: 3 x ntri vertex indices.
  BodyVertexBuffer(int nvert, const std::vector<int>& tri);
  ~BodyVertexBuffer();
  BodyVertexBuffer(const BodyVertexBuffer&) = delete;
  BodyVertexBuffer& operator=(const BodyVertexBuffer&) = delete;

  // Where this frame's nvert x kBodyFloatsPerVertex floats go: device memory when
  // on_device (throws in a build without CUDA-GL interop), host memory otherwise.
  float* map(bool on_device);
  void unmap();                  // hands the written vertices to GL
  // The largest finite colour scalar of the vertices last written (0 when none): the top
  // of an automatic colour range. Reads the GL buffer back on the interop path.
  float scalar_max() const;
  void draw() const;             // triangles with the currently bound program
  const std::string& path() const { return path_; }  // "interop" | "staging" | "host" | "" (never mapped)
  int nvert() const { return nvert_; }
  int ntri() const { return nindex_ / 3; }
  GLuint vbo() const { return vbo_; }

 private:
  GLuint vao_ = 0, vbo_ = 0, ibo_ = 0;
  int nvert_ = 0, nindex_ = 0;
  std::vector<float> host_;  // nvert x kBodyFloatsPerVertex, the host and staging paths' array
  std::unique_ptr<CudaGlBuffer> cuda_;
  bool mapped_on_device_ = false;
  std::string path_;
};

}  // namespace softtled
