#include "sim/solver/cuda/contact_stage.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace softtled::cuda {

ContactGridSize contact_grid_size(const BodyContactTables& t, const std::vector<double>& X) {
  ContactGridSize g;
  while (g.buckets < 8u * unsigned(std::max(1, t.ntri()))) g.buckets <<= 1;
  const int fullest = fullest_bucket_at_rest(t, X, g.buckets);
  g.bucket_cap = std::max(kContactBucketCap, (2 * fullest + 31) / 32 * 32);
  return g;
}

template <class T>
void DeviceContactStage<T>::upload(const BodyContactTables& t, ContactGridSize grid,
                                   const std::vector<int>& node_new, const std::vector<int>& node_old) {
  const int n = t.nnode;
  std::vector<int> surf(t.surf.size()), tri(t.tri.size()), node_body(n);
  for (std::size_t s = 0; s < surf.size(); ++s) surf[s] = node_new[t.surf[s]];
  for (std::size_t k = 0; k < tri.size(); ++k) tri[k] = node_new[t.tri[k]];
  for (int i = 0; i < n; ++i) node_body[i] = t.node_body[node_old[i]];
  const int nsurf = int(surf.size()), nt = t.ntri();
  const unsigned buckets = grid.buckets;
  const int cap = grid.bucket_cap;
  const std::size_t slots = std::size_t(std::max(1, nsurf)) * kContactCandCap;
  surf_.upload(surf);
  tri_.upload(tri);
  tri_body_.upload(t.tri_body);
  node_body_.upload(node_body);
  surf_tri_start_.upload(t.surf_tri_start);
  surf_tri_.upload(t.surf_tri.empty() ? std::vector<int>{0} : t.surf_tri);
  bucket_count_.resize(buckets);
  bucket_tri_.resize(std::size_t(buckets) * cap);
  tri_box_.resize(6 * std::size_t(std::max(1, nt)));
  ncand_.resize(std::max(1, nsurf));
  cand_.resize(slots);
  pair_state_.resize(slots);
  pair_facing_.resize(slots);
  pair_corr_.resize(kPairCorrValues * slots);
  node_box_.resize(6 * std::size_t(std::max(1, nsurf)));
  count0_.resize(n);
  count1_.resize(n);
  in_count_.resize(n);
  in_list_.resize(std::size_t(n) * kContactInCap);
  overflow_.resize(1);
  rebuild_.upload({1u});  // the first step builds the lists
  for (DeviceBuffer<int>* b : {&count0_, &count1_, &in_count_}) b->fill_zero();
  bucket_count_.fill_zero();
  overflow_.fill_zero();

  BodyContactView<T>& v = view_;
  v.nsurf = nsurf;
  v.ntri = nt;
  v.nbody = t.nbody;
  v.surf = surf_.data();
  v.tri = tri_.data();
  v.tri_body = tri_body_.data();
  v.node_body = node_body_.data();
  v.surf_tri_start = surf_tri_start_.data();
  v.surf_tri = surf_tri_.data();
  if (t.nbody > kBodyContactMaxBodies)
    throw std::logic_error("body contact (GPU): more than " + std::to_string(kBodyContactMaxBodies) + " bodies");
  for (int b = 0; b < t.nbody; ++b) v.body_tol[b] = T(t.body_tol[b]);
  v.inv_h = 1.0 / double(T(t.cell));
  v.mask = buckets - 1;
  v.bucket_count = bucket_count_.data();
  v.bucket_cap = cap;
  v.bucket_tri = bucket_tri_.data();
  v.tri_box = tri_box_.data();
  v.ncand = ncand_.data();
  v.cand = cand_.data();
  v.pair_state = pair_state_.data();
  v.pair_facing = pair_facing_.data();
  v.pair_corr = pair_corr_.data();
  v.count0 = count0_.data();
  v.count1 = count1_.data();
  v.in_count = in_count_.data();
  v.in_list = in_list_.data();
  v.overflow = overflow_.data();
  v.node_box = node_box_.data();
  v.rebuild = rebuild_.data();
}

template <class T>
void DeviceContactStage<T>::set_pairs(bool bodies, bool self, cudaStream_t s) {
  if (ready() && (bodies != view_.bodies || self != view_.self)) {
    static const unsigned kOne = 1;
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(rebuild_.data(), &kOne, sizeof kOne, cudaMemcpyHostToDevice, s));
  }
  view_.bodies = bodies;
  view_.self = self;
}

template <class T>
void DeviceContactStage<T>::download_overflow(unsigned* host, cudaStream_t s) const {
  *host = 0;
  if (ready()) SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(host, overflow_.data(), sizeof *host, cudaMemcpyDeviceToHost, s));
}

template <class T>
std::string DeviceContactStage<T>::overflow_message(unsigned f) const {
  std::string m = "body contact (GPU): ";
  if (f & kContactOverflowCells)
    m += "a triangle swept over more than " + std::to_string(kContactMaxCells) + " grid cells in one step; ";
  if (f & kContactOverflowBucket)
    m += "a grid bucket held more than " + std::to_string(view_.bucket_cap) + " triangles; ";
  if (f & kContactOverflowCand)
    m += "a node had more than " + std::to_string(kContactCandCap) + " candidate triangles; ";
  if (f & kContactOverflowIncoming)
    m += "a node took part in more than " + std::to_string(kContactInCap) + " contacts; ";
  return m + "the state is diverging or the mesh too fine for the contact stage's fixed lists (use --backend cpu)";
}

template class DeviceContactStage<float>;
template class DeviceContactStage<double>;

}  // namespace softtled::cuda
