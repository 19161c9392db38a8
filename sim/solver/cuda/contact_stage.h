#pragma once
// The GPU contact stage's device data (tled_contact.cu, BodyContactView): the shared
// tables of body_contact_tables.h renumbered to the solver's node order, and the fixed-size
// scratch the kernels fill each step. Plain C++ against the CUDA runtime (host code).
#include <cuda_runtime_api.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sim/contact/body_contact_tables.h"
#include "sim/solver/cuda/device_buffer.h"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {

// The GPU grid's size, from the mesh at rest (host code, computed once at construction so
// the solver need not keep the rest positions until contact first turns on).
struct ContactGridSize {
  unsigned buckets = 1;  // a power of two: 8 per triangle (a triangle's swept box covers ~8 cells)
  int bucket_cap = 0;    // triangles per bucket
};
// Triangles per bucket: twice the fullest bucket at rest (boxes inflated as the kernels'
// are, by the tolerance and half the margin; counted in double, where a float run's cells
// round a little differently: the factor 2 covers that and deformation), at least
// kContactBucketCap, in warps. Every bucket gets that size: one dense spot sizes them all
// (README "Limits"). A one-element plate (2.5 mm triangles, 0.5 mm sides) within a 3.3 mm
// cell overflowed a fixed 128 at its first step and stopped the run as an internal error.
// X: the rest positions (3 per node, the mesh's order).
ContactGridSize contact_grid_size(const BodyContactTables& t, const std::vector<double>& X);

template <class T>
class DeviceContactStage {
 public:
  bool ready() const { return surf_.size() > 0; }
  // The tables on the device (once; the caller has synchronised and dropped its graphs):
  // node_new / node_old the solver's renumbering. The triangles and the surface-node order
  // stay the mesh's: the CPU's key order (body_contact.h).
  void upload(const BodyContactTables& t, ContactGridSize grid, const std::vector<int>& node_new,
              const std::vector<int>& node_old);
  // Which pairs the kernels test; lists kept for other kinds of pairs are rebuilt
  // (a stream-ordered write of the rebuild flag).
  void set_pairs(bool bodies, bool self, cudaStream_t s);
  const BodyContactView<T>& view() const { return view_; }
  // The overflow word into *host, stream-ordered (0 when nothing overflowed or not ready).
  void download_overflow(unsigned* host, cudaStream_t s) const;
  std::string overflow_message(unsigned flags) const;

 private:
  DeviceBuffer<int> surf_, tri_, tri_body_, node_body_, surf_tri_start_, surf_tri_;
  DeviceBuffer<unsigned> bucket_count_, overflow_, rebuild_;
  DeviceBuffer<int> bucket_tri_, ncand_, cand_, count0_, count1_, in_count_, in_list_;
  DeviceBuffer<T> tri_box_, pair_corr_, node_box_;
  DeviceBuffer<std::uint8_t> pair_state_, pair_facing_;
  BodyContactView<T> view_;
};

}  // namespace softtled::cuda
