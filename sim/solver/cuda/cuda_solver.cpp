// CUDA backend: device arrays per body (rest and live, struct-of-arrays), views passed by
// value to the kernels in tled_step.cu, and the step sequence replayed from CUDA graphs.
// Host code only (C++ against the CUDA runtime API); every call's return code is checked.
#include "sim/solver/cuda/cuda_solver.h"

#include <cuda_runtime_api.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>

#include "sim/contact/body_contact_tables.h"
#include "sim/core/env_setting.h"
#include "sim/fem/step_health.h"
#include "sim/solver/cuda/contact_stage.h"
#include "sim/solver/cuda/cuda_check.h"
#include "sim/solver/cuda/device_buffer.h"
#include "sim/solver/cuda/device_info.h"
#include "sim/mesh/mesh_reorder.h"
#include "sim/solver/halo_blocks.h"
#include "sim/solver/obstacle_grids.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/step_params.h"
#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/surface_topology.h"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled {
namespace cuda {

const char* exec_mode_name(ExecMode m) {
  switch (m) {
    case ExecMode::kAuto: return "auto";
    case ExecMode::kMulti: return "multi";
    case ExecMode::kFused: return "fused";
    case ExecMode::kHalo: return "halo";
    case ExecMode::kGraphPdl: return "graph-pdl";
    case ExecMode::kGraph: return "graph";
  }
  return "?";
}

ExecMode parse_exec_mode(const std::string& s) {
  for (ExecMode m : {ExecMode::kAuto, ExecMode::kMulti, ExecMode::kFused, ExecMode::kHalo, ExecMode::kGraphPdl,
                     ExecMode::kGraph})
    if (s == exec_mode_name(m)) return m;
  throw InputError("unknown CUDA execution mode '" + s + "' (use auto, multi, fused, halo, graph-pdl or graph)");
}

Options options_from_env() {
  // Each value checked and named (sim/core/env_setting.h): atoi read "1e9" as 1 and "abc" as 0.
  Options o;
  if (const std::optional<std::string> m = env_setting("SOFTTLED_CUDA_MODE")) {
    try {
      o.mode = parse_exec_mode(*m);
    } catch (const InputError& e) {
      throw InputError(std::string("SOFTTLED_CUDA_MODE: ") + e.what());
    }
  }
  o.reorder = env_switch("SOFTTLED_CUDA_REORDER", o.reorder);
  o.steps_per_graph = env_int("SOFTTLED_CUDA_GRAPH_STEPS", o.steps_per_graph, 1, 1024);
  o.node_lanes = env_int("SOFTTLED_CUDA_NODE_LANES", o.node_lanes, 0, 8);
  if (o.node_lanes != 0 && o.node_lanes != 1 && o.node_lanes != 4 && o.node_lanes != 8)
    throw InputError("SOFTTLED_CUDA_NODE_LANES=" + std::to_string(o.node_lanes) + ": expected 1, 4 or 8 (0: by mesh size)");
  o.fused_block = env_int("SOFTTLED_CUDA_FUSED_BLOCK", o.fused_block, 32, kFusedMaxThreads);
  if (o.fused_block % 32)
    throw InputError("SOFTTLED_CUDA_FUSED_BLOCK=" + std::to_string(o.fused_block) + ": expected a multiple of 32");
  o.halo_elements = env_int("SOFTTLED_CUDA_HALO_ELEMS", o.halo_elements, 0, 1 << 16);
  o.halo_block = env_int("SOFTTLED_CUDA_HALO_BLOCK", o.halo_block, 0, kHaloMaxThreads);
  if (o.halo_block % 32)
    throw InputError("SOFTTLED_CUDA_HALO_BLOCK=" + std::to_string(o.halo_block) +
                     ": expected a multiple of 32 (0: by the block's elements)");
  o.derive_gradients = env_int("SOFTTLED_CUDA_DERIVE_GRADIENTS", o.derive_gradients, -1, 1);
  o.fused_preload = env_int("SOFTTLED_CUDA_FUSED_PRELOAD", o.fused_preload, -1, 1);
  return o;
}

namespace {

// Device copy of one body's rest state (TetMeshView's arrays) and surface tables.
template <class T>
struct DeviceRest {
  DeviceBuffer<T> X0, dhdX, vol, inv_mass;
  // Rest positions in double, 4 per node (derive_dhdX), where the element stage derives
  // dh/dX from them; empty: it reads the table.
  DeviceBuffer<double> X0d;
  DeviceBuffer<int> tet, gather_start, gather_slot;
  DeviceBuffer<std::uint8_t> flags;
  // Per-body laws (element_law.h): each element's and node's body, and the live table
  // (set_dt uploads it); empty where every body has the scene's law.
  DeviceBuffer<std::uint8_t> tet_law, node_law;
  DeviceBuffer<ElementLaw<T>> laws;
  std::vector<ElementLaw<T>> laws_host;  // what laws holds
  DeviceBuffer<int> s_node, s_tri, s_vtri_start, s_vtri;
  DeviceBuffer<int> fblock;  // fused step: first node of each block, + nnode (StepArgs::fblock)
  int nfblock = 0, fsmem_entries = 0;
  // Halo step (halo_blocks.h): built when the halo step is first chosen (ensure_halo);
  // empty before and where one node touches more elements than a block holds.
  DeviceBuffer<int> hnode, helem_start, helem;
  DeviceBuffer<std::uint16_t> hslot;
  int nhblock = 0, hcap = 0, hthreads = 0;
  TetMeshView<T> view;
  SurfaceView surface;
};

// Live state on the device.
template <class T>
struct DeviceLive {
  DeviceBuffer<T> u, du, fcorner, fext;
  DeviceBuffer<T> u2, du2;  // fused step: the other displacement buffer (odd steps write it)
  // beta > 0: u + (beta / dt) du that goes with (u, du) and (u2, du2) (BodyStateView::ub);
  // allocated when beta is first switched on
  DeviceBuffer<T> ub, ub2;
  DeviceBuffer<T> vol_now, p_node;  // T4ANP: ntet current element volumes, nnode nodal pressures
  DeviceBuffer<std::uint8_t> contact;
};

class Event {
 public:
  Event() { SOFTTLED_CUDA_CHECK(cudaEventCreate(&e_)); }
  ~Event() { cudaEventDestroy(e_); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  cudaEvent_t get() const { return e_; }

 private:
  cudaEvent_t e_ = nullptr;
};

double elapsed_us(const Event& a, const Event& b) {
  float ms = 0;
  SOFTTLED_CUDA_CHECK(cudaEventElapsedTime(&ms, a.get(), b.get()));
  return double(ms) * 1e3;
}

template <class T>
class CudaSolver final : public CudaSolverApi {
 public:
  CudaSolver(const TetMesh& mesh, double rho, const std::vector<std::uint8_t>& flags, const Options& opt)
      : opt_(opt), flags_(flags) {
    int dev = 0;
    SOFTTLED_CUDA_CHECK(cudaGetDevice(&dev));
    const DeviceInfo info = device_info(dev);
    nsm_ = info.sm_count;
    device_name_ = info.name;
    SOFTTLED_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));

    perm_ = opt.reorder ? spatial_order(mesh) : identity_order(mesh);
    const TetMesh pm = permute_mesh(mesh, perm_);
    std::vector<std::uint8_t> pflags(flags.size());
    for (std::size_t i = 0; i < flags.size(); ++i) pflags[i] = flags[perm_.node_old[i]];
    const RestArrays<T> r = build_rest_state<T>(pm, rho, pflags);
    n_ = r.nnode;
    ne_ = r.ntet;
    mass_.resize(n_);
    for (int i = 0; i < n_; ++i) mass_[perm_.node_old[i]] = r.mass[i];

    rest_.X0.upload(r.X0);
    rest_.dhdX.upload(r.dhdX);
    // Derived where the table would come from DRAM: it and the corner forces (12 numbers
    // per element each) take more than half the L2. Below that the table is an L2 hit and
    // the nine double divisions per element cost more than they save (bench/NOTES.md).
    const bool table_leaves_l2 = 24.0 * sizeof(T) * ne_ > 0.5 * double(info.l2_bytes);
    // The halo step (auto_mode) pays from the same line in float; in double its duplicated
    // arithmetic costs twice as much (FP64 at half the FP32 rate), so from twice as many
    // elements (H100: float between 177k and 287k tets, double between 287k and 1M).
    halo_pays_ = 24.0 * 4 * ne_ > 0.5 * double(info.l2_bytes) * (sizeof(T) / 4.0);
    if (opt.derive_gradients < 0 ? table_leaves_l2 : opt.derive_gradients != 0) {
      std::vector<double> X0d(4 * std::size_t(n_), 0.0);
      for (int i = 0; i < n_; ++i)
        for (int k = 0; k < 3; ++k) X0d[4 * std::size_t(i) + k] = pm.X[3 * std::size_t(i) + k];
      rest_.X0d.upload(X0d);
    }
    rest_.vol.upload(r.vol);
    rest_.inv_mass.upload(r.inv_mass);
    rest_.tet.upload(r.tet);
    rest_.gather_start.upload(r.gather_start);
    rest_.gather_slot.upload(r.gather_slot);
    rest_.flags.upload(r.flags);
    TetMeshView<T>& v = rest_.view;
    v.ntet = ne_;
    v.nnode = n_;
    v.tet = rest_.tet.data();
    v.X0 = rest_.X0.data();
    v.dhdX = rest_.dhdX.data();
    v.vol = rest_.vol.data();
    v.inv_mass = rest_.inv_mass.data();
    v.gather_start = rest_.gather_start.data();
    v.gather_slot = rest_.gather_slot.data();
    v.flags = rest_.flags.data();
    if (!r.tet_law.empty()) {
      rest_.tet_law.upload(r.tet_law);
      rest_.node_law.upload(r.node_law);
      rest_.laws.resize(std::size_t(mesh.nbody()));
      v.tet_law = rest_.tet_law.data();
      v.node_law = rest_.node_law.data();
      v.laws = rest_.laws.data();
    }
    build_fused_blocks(r.gather_start);

    // Render vertices keep the original mesh's order (the renderer indexes them with the
    // same SurfaceTopology); only the node each one reads is renumbered.
    SurfaceTopology st = build_surface_topology(mesh);
    for (int& i : st.node) i = perm_.node_new[i];
    rest_.s_node.upload(st.node);
    rest_.s_tri.upload(st.tri);
    rest_.s_vtri_start.upload(st.vtri_start);
    rest_.s_vtri.upload(st.vtri);
    SurfaceView& sv = rest_.surface;
    sv.nvert = int(st.node.size());
    sv.ntri = int(st.tri.size() / 3);
    sv.node = rest_.s_node.data();
    sv.tri = rest_.s_tri.data();
    sv.vtri_start = rest_.s_vtri_start.data();
    sv.vtri = rest_.s_vtri.data();

    live_.u.resize(3 * std::size_t(n_));
    live_.du.resize(3 * std::size_t(n_));
    live_.u2.resize(3 * std::size_t(n_));
    live_.du2.resize(3 * std::size_t(n_));
    live_.u2.fill_zero();
    live_.du2.fill_zero();
    live_.fcorner.resize(12 * std::size_t(ne_));
    live_.contact.resize(std::size_t(n_));
    live_.vol_now.resize(std::size_t(std::max(ne_, 1)));
    live_.p_node.resize(std::size_t(std::max(n_, 1)));
    live_.vol_now.fill_zero();
    live_.p_node.fill_zero();
    live_.u.fill_zero();
    live_.du.fill_zero();
    live_.fcorner.fill_zero();
    live_.contact.fill_zero();
    energy_.resize(std::size_t(std::max(ne_ + n_, 1)));  // T4ANP: ntet + nnode terms
    energy_vol_.resize(std::size_t(std::max(ne_, 1)));
    partials_.resize(kSumBlocks);
    energy_sum_.resize(1);
    health_.resize(1);
    health_.fill_zero();

    contact_tables_ = build_body_contact_tables(mesh);
    contact_grid_ = contact_grid_size(contact_tables_, mesh.X);

    set_exec_mode(opt.mode);
    set_node_lanes(opt.node_lanes);
    SOFTTLED_CUDA_CHECK(cudaDeviceSynchronize());
  }

  ~CudaSolver() override {
    clear_graphs();
    if (stream_) cudaStreamDestroy(stream_);
  }

  std::string backend() const override { return "cuda"; }
  Precision precision() const override { return sizeof(T) == 4 ? Precision::kFloat : Precision::kDouble; }
  std::string device_name() const override { return device_name_; }
  int render_vertex_count() const override { return rest_.surface.nvert; }

  void set_params(const PhysicsParams& p) override {
    set_dt(p);
    clear_graphs();  // the parameters are baked into the captured kernel nodes
  }

  // The step graphs are kept per dt (GraphKey): the adaptive step moves between a few
  // ladder rungs, and recapturing and instantiating a graph costs more than the dozens of
  // steps between two changes (~0.1 ms).
  void set_dt(const PhysicsParams& p) override {
    const T old_beta_dt = cfg_.step.beta_dt;
    params_ = p;
    cfg_ = step_config_from<T>(p);
    upload_laws();
    hold_grids(p);
    point_at_grids(cfg_.step);
    if (cfg_.step.beta_dt != old_beta_dt) refresh_ub();
    if (contact_on()) {
      if (!contact_.ready()) {
        SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
        clear_graphs();  // the first tables: new pointers in the kernel arguments
        contact_.upload(contact_tables_, contact_grid_, perm_.node_new, perm_.node_old);
      }
      contact_.set_pairs(params_.body_contact && contact_tables_.nbody >= 2, params_.self_contact, stream_);
    }
  }

  // The live law table (element_law.h) where the mesh has per-body laws: stream-ordered
  // before the steps that read it, and only when it changed.
  void upload_laws() {
    if (cfg_.laws.size() != rest_.laws.size())
      throw std::invalid_argument("set_params: body_laws must hold one law per body where the mesh has per-body laws, else none");
    if (cfg_.laws.empty()) return;
    bool same = rest_.laws_host.size() == cfg_.laws.size();
    for (std::size_t b = 0; same && b < cfg_.laws.size(); ++b)
      same = std::memcmp(&rest_.laws_host[b], &cfg_.laws[b], sizeof(ElementLaw<T>)) == 0;
    if (same) return;
    rest_.laws_host = cfg_.laws;
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(rest_.laws.data(), rest_.laws_host.data(), sizeof(ElementLaw<T>) * cfg_.laws.size(),
                                        cudaMemcpyHostToDevice, stream_));
  }

  // mode_ is kHalo only with the halo tables built: everything that reads them asks for kHalo.
  void set_exec_mode(ExecMode m) override {
    if (m == ExecMode::kAuto) m = auto_mode();
    if (m == ExecMode::kHalo) ensure_halo();
    if (m != mode_) clear_graphs();
    mode_ = m;
  }
  // What runs: multi reports fused where it falls back (use_multi).
  ExecMode exec_mode() const override {
    if (mode_ == ExecMode::kHalo && rest_.nhblock == 0) return ExecMode::kFused;
    return mode_ == ExecMode::kMulti && !use_multi(args(cfg_.step)) ? ExecMode::kFused : run_mode();
  }

  void set_node_lanes(int lanes) override {
    if (lanes == 0) lanes = auto_lanes();
    if (lanes != 1 && lanes != 4 && lanes != 8) throw InputError("node lanes must be 1, 4 or 8");
    if (lanes != lanes_) clear_graphs();
    lanes_ = lanes;
  }
  int node_lanes() const override { return lanes_; }
  bool derives_gradients() const override { return !rest_.X0d.empty(); }
  std::string halo_layout() const override {
    if (!halo_step()) return "";
    char buf[128];
    std::snprintf(buf, sizeof buf, "%d blocks of <= %d elements x %d threads, %.2fx the elements", rest_.nhblock,
                  rest_.hcap, rest_.hthreads, halo_duplication_);
    return buf;
  }

  void step(long nsteps) override {
    if (nsteps <= 0) return;
    if (dt_mid_ > 0) {  // the first step after a change of dt: its own coefficients, launched directly
      StepParams<T> first = step_params_from<T>(params_, dt_mid_);
      point_at_grids(first);
      dt_mid_ = 0;
      enqueue_one_step(args(first));
      if (--nsteps == 0) return;
    }
    const StepArgs<T> a = args(cfg_.step);
    if (use_multi(a)) {  // no graphs: one launch per kMaxMultiSteps steps
      enqueue_multi(a, nsteps);
      return;
    }
    if (nsteps == 1 && graphs_.empty()) {
      // One step right after set_params: a moving obstacle or plane is posed before every
      // step (Simulation::move_planes), so a one-step graph captured now would be thrown
      // away by the next set_params. Launched directly instead: the same kernels.
      enqueue_one_step(a);
      return;
    }
    // Binary decomposition: whole K-step graphs, then graphs of 2^j < K steps.
    const int K = std::max(1, opt_.steps_per_graph);
    long left = nsteps;
    for (; left >= K; left -= K) SOFTTLED_CUDA_CHECK(cudaGraphLaunch(graph(K), stream_));
    for (int j = 30; j >= 0; --j)
      if (left & (1L << j)) SOFTTLED_CUDA_CHECK(cudaGraphLaunch(graph(1 << j), stream_));
    SOFTTLED_CUDA_CHECK(cudaGetLastError());
  }

  void synchronize() override { SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

  double time_steps_us(long n) override {
    Event a, b;
    SOFTTLED_CUDA_CHECK(cudaEventRecord(a.get(), stream_));
    step(n);
    SOFTTLED_CUDA_CHECK(cudaEventRecord(b.get(), stream_));
    SOFTTLED_CUDA_CHECK(cudaEventSynchronize(b.get()));
    return elapsed_us(a, b);
  }

  StageTimes time_stages(int reps) override {
    reps = std::max(1, reps);
    synchronize();
    // Keep the live state: the stages run out of order here.
    DeviceBuffer<T> u0(live_.u.size()), du0(live_.du.size());
    DeviceBuffer<std::uint8_t> c0(live_.contact.size());
    DeviceBuffer<float> render(std::size_t(kRenderFloatsPerVertex) * std::max(1, rest_.surface.nvert));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(u0.data(), live_.u.data(), u0.bytes(), cudaMemcpyDeviceToDevice, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(du0.data(), live_.du.data(), du0.bytes(), cudaMemcpyDeviceToDevice, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(c0.data(), live_.contact.data(), c0.bytes(), cudaMemcpyDeviceToDevice, stream_));

    const bool pdl = run_mode() == ExecMode::kGraphPdl || fused_step();
    const StepArgs<T> a = args(cfg_.step);
    StepParams<T> free_p = cfg_.step;
    free_p.contact.nplanes = 0;
    free_p.contact.nobstacles = 0;
    const StepArgs<T> a_free = args(free_p);
    const LaunchShape sn = node_shape(pdl);
    const LaunchShape sr = shape_for(rest_.surface.nvert, nsm_, false);
    StageTimes t;
    t.reps = reps;
    // Element stage: element_corner_forces, or the three T4ANP kernels together.
    t.forces_us = time_graph(reps, [&] { return launch_element_stage(a, pdl); }) / reps;
    t.update_contact_us = time_graph(reps, [&] { return launch_node_update<T>(stream_, sn, a); }) / reps;
    t.update_only_us = time_graph(reps, [&] { return launch_node_update<T>(stream_, sn, a_free); }) / reps;
    if (rest_.surface.nvert > 0)
      t.render_us = time_graph(reps, [&] {
                      return launch_render_vertices<T>(stream_, sr, rest_.view, rest_.surface, live_.u.data(),
                                                       live_.contact.data(), RenderScalar::kDisplacement, cfg_.mat,
                                                       render.data());
                    }) / reps;

    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.u.data(), u0.data(), u0.bytes(), cudaMemcpyDeviceToDevice, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.du.data(), du0.data(), du0.bytes(), cudaMemcpyDeviceToDevice, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.contact.data(), c0.data(), c0.bytes(), cudaMemcpyDeviceToDevice, stream_));
    refresh_ub();
    synchronize();
    return t;
  }

  void get_state(HostState& s) const override {
    std::vector<T> u, du;
    std::vector<std::uint8_t> c;
    download(live_.u, u);
    download(live_.du, du);
    download(live_.contact, c);
    unsigned overflow = 0;
    contact_.download_overflow(&overflow, stream_);
    SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
    to_host_state(u.data(), du.data(), c.data(), overflow, s);
  }

  // Snapshots (solver.h): the strain energy's kernels with the state check, then one kernel
  // writing state, energy, record and overflow word into pinned buffers (launch_snapshot:
  // PDL launches), queued behind the steps, with an event that end_snapshot waits for; the
  // next steps queued after them cannot touch the state before the snapshot kernel is done
  // (stream order).
  bool async_snapshots() const override { return true; }
  void begin_snapshot(int slot) override {
    Snapshot& sn = snaps_.at(std::size_t(slot));
    const std::size_t n3 = 3 * std::size_t(n_);
    if (!sn.u) {  // first use
      sn.u = std::make_unique<PinnedBuffer<T>>(n3);
      sn.du = std::make_unique<PinnedBuffer<T>>(n3);
      sn.contact = std::make_unique<PinnedBuffer<std::uint8_t>>(std::size_t(std::max(n_, 1)));
    }
    const SnapshotTarget<T> dst{sn.u->data(),      sn.du->data(),     sn.contact->data(),
                                sn.energy.data(), sn.health.data(), sn.overflow.data()};
    SOFTTLED_CUDA_CHECK(launch_snapshot<T>(stream_, nsm_, rest_.view, cfg_.mat, cfg_.element == kT4ANP,
                                           live_.u.data(), live_.du.data(), live_.contact.data(),
                                           du2_bound(cfg_.step.dt), health_.data(),
                                           contact_.ready() ? contact_.view().overflow : nullptr, energy_vol_.data(),
                                           energy_.data(), partials_.data(), dst));
    SOFTTLED_CUDA_CHECK(cudaEventRecord(sn.done.get(), stream_));
  }
  void end_snapshot(int slot, HostState& s, double& strain_energy, StepHealth& health) override {
    Snapshot& sn = snaps_.at(std::size_t(slot));
    SOFTTLED_CUDA_CHECK(cudaEventSynchronize(sn.done.get()));
    strain_energy = sn.energy[0];
    health = step_health(sn.health[0]);
    to_host_state(sn.u->data(), sn.du->data(), sn.contact->data(), sn.overflow[0], s);
  }

  // The device watchdog (step_health.h): the bound goes into the step kernels' arguments.
  void set_node_energy_bound(double e) override {
    if (e == node_energy_) return;
    node_energy_ = e;
    clear_graphs();  // baked into the captured kernel nodes
  }
  StepHealth take_health() override {
    enqueue_take_health(health_host_.data());
    SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
    return step_health(health_host_[0]);
  }

  // Device arrays (solver order, T) to a HostState (mesh order, double); a contact-stage
  // overflow seen with them is an error.
  void to_host_state(const T* u, const T* du, const std::uint8_t* c, unsigned overflow, HostState& s) const {
    if (overflow) throw std::runtime_error(contact_.overflow_message(overflow));
    const std::size_t n3 = 3 * std::size_t(n_);
    s.u.resize(n3);
    s.du.resize(n3);
    s.contact.resize(std::size_t(n_));
    for (int i = 0; i < n_; ++i) {
      const int o = perm_.node_old[i];
      for (int k = 0; k < 3; ++k) {
        s.u[std::size_t(k) * n_ + o] = double(u[std::size_t(k) * n_ + i]);
        s.du[std::size_t(k) * n_ + o] = double(du[std::size_t(k) * n_ + i]);
      }
      s.contact[o] = c[i];
    }
  }

  void set_state(const HostState& s) override {
    const std::size_t n3 = 3 * std::size_t(n_);
    if (s.u.size() != n3 || s.du.size() != n3) throw std::invalid_argument("set_state: size");
    std::vector<T> u(n3), du(n3);
    for (int i = 0; i < n_; ++i) {
      const int o = perm_.node_old[i];
      for (int k = 0; k < 3; ++k) {
        u[std::size_t(k) * n_ + i] = T(s.u[std::size_t(k) * n_ + o]);
        du[std::size_t(k) * n_ + i] = T(s.du[std::size_t(k) * n_ + o]);
      }
    }
    upload(u, live_.u);
    upload(du, live_.du);
    if (s.contact.size() == std::size_t(n_)) {
      std::vector<std::uint8_t> c(n_);
      for (int i = 0; i < n_; ++i) c[i] = s.contact[perm_.node_old[i]];
      upload(c, live_.contact);
      SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
    }
    refresh_ub();
    dt_mid_ = 0;
    SOFTTLED_CUDA_CHECK(cudaMemsetAsync(health_.data(), 0, sizeof(DeviceHealth), stream_));  // a fresh state
    SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));  // the host vectors die here
  }

  void change_step(double scale, double dt_mid) override {
    const int n3 = 3 * n_;
    SOFTTLED_CUDA_CHECK(launch_scale<T>(stream_, shape_for(n3, nsm_, false), n3, T(scale), live_.du.data()));
    refresh_ub();
    dt_mid_ = dt_mid;
  }

  // The CPU backend's power iteration as kernels (tled_probe.cu): the step's element stage
  // on u + a v, then one kernel for the gather, the product and its deterministic sums;
  // one graph and an asynchronous download, which end_omega_max waits for.
  void begin_omega_max(int iterations, double a, bool restart) override {
    const int n3 = 3 * n_;
    // Without PDL: with it (each probe kernel waiting before its live reads) the lane
    // gathers returned racy estimates on the H100, and the estimate was no faster (39.5 vs
    // 38.8 us device time).
    const bool pdl = false;
    const LaunchShape s3 = shape_for(n3, nsm_, pdl);
    if (probe_.v.size() != std::size_t(n3)) {
      probe_.v.resize(n3);
      probe_.f0.resize(n3);
      probe_.w.resize(n3);
      probe_.up.resize(n3);
      probe_.partials.resize(3 * std::size_t(probe_blocks(n_)));
      probe_.sums.resize(3);
      probe_.ticket.resize(1);
      SOFTTLED_CUDA_CHECK(cudaMemsetAsync(probe_.ticket.data(), 0, sizeof(unsigned), stream_));
      std::vector<int> old(perm_.node_old.begin(), perm_.node_old.end());
      probe_.node_old.upload(old);
      std::vector<double> m(n_);
      for (int i = 0; i < n_; ++i) m[i] = mass_[perm_.node_old[i]];
      probe_.mass.upload(m);
      restart = true;
    }
    if (restart) {
      SOFTTLED_CUDA_CHECK(launch_probe_start<T>(stream_, shape_for(n3, nsm_, false), n_, rest_.view.inv_mass,
                                                probe_.node_old.data(), probe_.v.data()));
      SOFTTLED_CUDA_CHECK(cudaMemsetAsync(probe_.sums.data(), 0, 3 * sizeof(double), stream_));  // keep v
    }
    // One graph per iteration count (a launch per kernel cost ~0.15 ms of host time).
    if (a != probe_a_) {
      destroy_probe_graphs();
      probe_a_ = a;
    }
    auto it = probe_graphs_.find(iterations);
    if (it == probe_graphs_.end()) {
      StepArgs<T> at = args(cfg_.step);
      at.b.ub = nullptr;  // forces at the displacement itself
      const T ta = T(a), inv_a = T(1) / ta;
      it = probe_graphs_.emplace(iterations, capture([&] {
                          at.b.u = live_.u.data();  // f0 = f(u)
                          SOFTTLED_CUDA_CHECK(launch_element_stage(at, pdl));
                          SOFTTLED_CUDA_CHECK(
                              launch_probe_f0<T>(stream_, rest_.view, live_.fcorner.data(), probe_.f0.data()));
                          at.b.u = probe_.up.data();
                          for (int k = 0; k < iterations; ++k) {
                            SOFTTLED_CUDA_CHECK(launch_probe_displace<T>(stream_, s3, n3, live_.u.data(),
                                                                         probe_.w.data(), probe_.sums.data(),
                                                                         probe_.v.data(), ta, probe_.up.data()));
                            SOFTTLED_CUDA_CHECK(launch_element_stage(at, pdl));
                            SOFTTLED_CUDA_CHECK(launch_probe_product<T>(
                                stream_, rest_.view, live_.fcorner.data(), probe_.f0.data(), probe_.v.data(),
                                probe_.mass.data(), inv_a, probe_.w.data(), probe_.partials.data(),
                                probe_.ticket.data(), probe_.sums.data()));
                          }
                        })).first;
    }
    SOFTTLED_CUDA_CHECK(cudaEventRecord(probe_.begin.get(), stream_));
    SOFTTLED_CUDA_CHECK(cudaGraphLaunch(it->second, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(probe_.result.data(), probe_.sums.data(), probe_.result.bytes(),
                                        cudaMemcpyDeviceToHost, stream_));
    SOFTTLED_CUDA_CHECK(cudaEventRecord(probe_.end.get(), stream_));
  }

  OmegaEstimate end_omega_max() override {
    SOFTTLED_CUDA_CHECK(cudaEventSynchronize(probe_.end.get()));
    OmegaEstimate r;
    r.seconds = 1e-6 * elapsed_us(probe_.begin, probe_.end);
    const double* h = probe_.result.data();
    if (h[1] > 0 && h[2] > 0) r.omega = std::sqrt(std::sqrt(h[0] / h[1]));
    return r;
  }

  double strain_energy() const override {
    if (ne_ == 0) return 0;
    enqueue_strain_energy(energy_sum_.data());
    double e = 0;
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(&e, energy_sum_.data(), sizeof(double), cudaMemcpyDeviceToHost, stream_));
    SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
    return e;
  }

  void set_external_forces(const std::vector<double>& f) override {
    const bool was = fext_active_;
    if (f.empty()) {
      fext_active_ = false;
    } else {
      const std::size_t n3 = 3 * std::size_t(n_);
      if (f.size() != n3) throw std::invalid_argument("set_external_forces: size");
      std::vector<T> h(n3);
      for (int i = 0; i < n_; ++i)
        for (int k = 0; k < 3; ++k) h[std::size_t(k) * n_ + i] = T(f[std::size_t(k) * n_ + perm_.node_old[i]]);
      if (live_.fext.size() != n3) {
        SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));  // queued steps may still read the old buffer
        live_.fext.resize(n3);
        clear_graphs();
      }
      upload(h, live_.fext);  // stream-ordered after the steps already queued
      SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
      fext_active_ = true;
    }
    if (was != fext_active_) clear_graphs();  // the pointer in the kernel arguments changes
  }

  const std::vector<double>& lumped_mass() const override { return mass_; }
  const std::vector<std::uint8_t>& node_flags() const override { return flags_; }

  bool render_buffer_on_device() const override { return true; }
  DeviceStateView device_state() const override {
    DeviceStateView v;
    v.u = live_.u.data();  // step(n) always leaves the state here (copy_back_fused)
    v.du = live_.du.data();
    v.nnode = n_;
    v.value_bytes = int(sizeof(T));
    v.rows = &perm_.node_old;
    v.stream = stream_;
    return v;
  }
  void write_render_vertices(float* dst, RenderScalar scalar) override {
    if (rest_.surface.nvert == 0) return;
    const LaunchShape ls = shape_for(rest_.surface.nvert, nsm_, false);
    SOFTTLED_CUDA_CHECK(launch_render_vertices<T>(stream_, ls, rest_.view, rest_.surface, live_.u.data(),
                                                  live_.contact.data(), scalar, cfg_.mat, dst));
    // The caller unmaps the GL buffer next: the vertices must be complete.
    SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
  }

 private:
  bool beta_on() const { return cfg_.step.beta_dt > T(0); }

  // The live state's strain energy into *sum (device), in stream order (no wait).
  void enqueue_strain_energy(double* sum) const {
    if (ne_ == 0) {
      SOFTTLED_CUDA_CHECK(cudaMemsetAsync(sum, 0, sizeof(double), stream_));
      return;
    }
    const bool anp = cfg_.element == kT4ANP;
    SOFTTLED_CUDA_CHECK(launch_strain_energy_terms<T>(stream_, shape_for(ne_, nsm_, false), shape_for(n_, nsm_, false),
                                                      rest_.view, cfg_.mat, anp, live_.u.data(), energy_vol_.data(),
                                                      energy_.data()));
    SOFTTLED_CUDA_CHECK(launch_sum(stream_, energy_.data(), anp ? ne_ + n_ : ne_, partials_.data(), sum));
  }

  // The speed test's bound for steps of length dt (StepArgs::du2_bound).
  T du2_bound(T dt) const { return speed_du2_bound<T>(node_energy_, double(dt)); }

  // The device watchdog's record into *dst (pinned), in stream order: first the state
  // check of the live state (launch_state_check), then the copy, then the record cleared
  // for the next interval.
  void enqueue_take_health(DeviceHealth* dst) {
    enqueue_state_check();
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(dst, health_.data(), sizeof(DeviceHealth), cudaMemcpyDeviceToHost, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemsetAsync(health_.data(), 0, sizeof(DeviceHealth), stream_));
  }
  void enqueue_state_check() {
    const LaunchShape ls = shape_for(std::max(ne_, n_), nsm_, false);
    SOFTTLED_CUDA_CHECK(launch_state_check<T>(stream_, ls, rest_.view, cfg_.mat, live_.u.data(), live_.du.data(),
                                              du2_bound(cfg_.step.dt), health_.data()));
  }
  // A record in the mesh's numbering.
  StepHealth step_health(const DeviceHealth& r) const {
    StepHealth h;
    h.checked = true;
    h.bits = r.bits;
    if (r.node_c) h.node = perm_.node_old.at(std::size_t(~r.node_c));
    if (r.element_c) h.element = perm_.tet_old.at(std::size_t(~r.element_c));
    return h;
  }

  // Mesh obstacles (obstacle_sdf.h): each grid's values in T on the device; the kernels
  // take the views by value with these pointers.
  void hold_grids(const PhysicsParams& p) {
    grids_.hold(p, [&](const SdfGrid& g) {
      DeviceBuffer<T> d;
      d.upload(std::vector<T>(g.value.begin(), g.value.end()));
      return d;
    });
  }
  void point_at_grids(StepParams<T>& s) const {
    grids_.point(params_, s, [](const DeviceBuffer<T>& b) { return b.data(); });
  }

  // Body-body contact needs two bodies; self-contact one.
  bool contact_on() const { return (params_.body_contact && contact_tables_.nbody >= 2) || params_.self_contact; }

  // The contact stage after a node stage that wrote (u, du, ub).
  void enqueue_contact(T* u, T* du, T* ub) {
    if (!contact_on()) return;
    SOFTTLED_CUDA_CHECK(launch_body_contact<T>(stream_, nsm_, rest_.view, contact_.view(), u, du, ub, cfg_.step.beta_dt,
                                               live_.contact.data(), cfg_.step.contact.mode, cfg_.step.contact.mu));
  }

  // ub = u + (beta / dt) du of the live state (the value function the node stage uses),
  // after a new state, beta or dt; nothing while beta = 0.
  void refresh_ub() {
    if (!beta_on()) return;
    const std::size_t n3 = 3 * std::size_t(n_);
    if (live_.ub.size() != n3) {
      SOFTTLED_CUDA_CHECK(cudaStreamSynchronize(stream_));
      clear_graphs();  // new pointers
      live_.ub.resize(n3);
      live_.ub2.resize(n3);
      live_.ub2.fill_zero();
    }
    SOFTTLED_CUDA_CHECK(launch_rayleigh_displacement<T>(stream_, shape_for(int(n3), nsm_, false), int(n3),
                                                        live_.u.data(), live_.du.data(), cfg_.step.beta_dt,
                                                        live_.ub.data()));
  }

  // Chosen from the bench (bench/NOTES.md, "The auto rule"): the fused one-kernel step
  // while its 4x element arithmetic is free (up to 256 tets per SM), PDL graphs above; 8
  // lanes per node on small meshes (max node degree ~60 on the torus), 4 on large ones
  // (fewer idle lanes, better coalescing per warp). T4ANP's fused step is two kernels
  // (tled_step.cu).
  // On meshes past halo_pays_'s line (the constructor's), the halo step: there the corner
  // forces' round trip through DRAM costs more than computing the border elements twice.
  ExecMode auto_mode() {
    if (ne_ <= 256 * nsm_) return ExecMode::kFused;
    if (halo_pays_) ensure_halo();  // whether the mesh has a layout at all
    return halo_pays_ && rest_.nhblock > 0 ? ExecMode::kHalo : ExecMode::kGraphPdl;
  }
  ExecMode run_mode() const { return mode_; }
  // multi runs the fused step's phases, and falls back to fused graphs where it cannot run.
  bool fused_step() const {
    return mode_ == ExecMode::kFused || mode_ == ExecMode::kMulti || mode_ == ExecMode::kHalo;
  }
  bool halo_step() const { return mode_ == ExecMode::kHalo && rest_.nhblock > 0; }

  // Multi-step launches (launch_multi_step): not with a contact stage (it runs between
  // steps), nor when the blocks cannot all be resident (the cooperative launch's rule;
  // checked once per kernel variant).
  bool use_multi(const StepArgs<T>& a) const {
    if (mode_ != ExecMode::kMulti || contact_on() || a.m.laws) return false;  // per-body laws: fused
    const int key = a.lanes * 2 + (a.anp ? 1 : 0);
    auto it = multi_fits_.find(key);
    if (it == multi_fits_.end()) {
      const cudaError_t e =
          launch_multi_step<T>(stream_, fused_block(), nsm_, a, state_buffers(a), 1, true);
      if (e != cudaSuccess && e != cudaErrorCooperativeLaunchTooLarge) SOFTTLED_CUDA_CHECK(e);
      it = multi_fits_.emplace(key, e == cudaSuccess).first;
    }
    return it->second;
  }
  // One step launched directly (no graph), in the mode's own kernels; the state ends in (u, du).
  void enqueue_one_step(const StepArgs<T>& a) {
    if (use_multi(a)) {
      enqueue_multi(a, 1);
    } else if (fused_step()) {
      enqueue_fused_step(a, 0, false);
      copy_back_fused(a);
    } else {
      enqueue_step(a, false);
    }
  }
  // The double-buffered state of the fused and multi-step kernels: (u, du, ub) and
  // (u2, du2, ub2); ub null while beta = 0.
  MultiStepBuffers<T> state_buffers(const StepArgs<T>& a) const {
    const bool beta = a.b.ub != nullptr;
    T* ub[2] = {const_cast<T*>(live_.ub.data()), const_cast<T*>(live_.ub2.data())};
    return {{const_cast<T*>(live_.u.data()), const_cast<T*>(live_.u2.data())},
            {const_cast<T*>(live_.du.data()), const_cast<T*>(live_.du2.data())},
            {beta ? ub[0] : nullptr, beta ? ub[1] : nullptr}};
  }
  // n steps in launches of at most kMaxMultiSteps (even, so only the last can end in
  // buffer 1), then the state back in (u, du).
  void enqueue_multi(const StepArgs<T>& a, long n) {
    const MultiStepBuffers<T> buf = state_buffers(a);
    int last = 0;
    for (long left = n; left > 0; left -= last) {
      last = int(std::min<long>(left, kMaxMultiSteps));
      SOFTTLED_CUDA_CHECK(launch_multi_step<T>(stream_, fused_block(), nsm_, a, buf, last));
    }
    if (last & 1) copy_back_fused(a);
  }

  // Fused step: nodes in order, packed into blocks of at most fused_block() gather entries
  // (a node with more entries gets a block of its own; the kernel loops over them).
  int fused_block() const {
    const int b = opt_.fused_block;
    return b >= 32 && b <= kFusedMaxThreads && b % 32 == 0 ? b : 256;
  }
  void build_fused_blocks(const std::vector<int>& gather_start) {
    const int cap = fused_block();
    std::vector<int> start;
    int most = 0;
    for (int i = 0; i < n_;) {
      const int i0 = i;
      ++i;  // at least one node per block
      while (i < n_ && gather_start[i + 1] - gather_start[i0] <= cap) ++i;
      start.push_back(i0);
      most = std::max(most, gather_start[i] - gather_start[i0]);
    }
    start.push_back(n_);
    rest_.nfblock = int(start.size()) - 1;
    rest_.fsmem_entries = std::max(most, 1);
    rest_.fblock.upload(start);
  }
  // The halo tables, once, on first use: ~15 bytes per element of device memory that the
  // other modes never read. The gather table comes back from the device: kept on the host
  // it would take about 17 bytes per element for good.
  void ensure_halo() {
    if (halo_built_) return;
    std::vector<int> gather_start, gather_slot;
    rest_.gather_start.download(gather_start);
    rest_.gather_slot.download(gather_slot);
    build_halo(gather_start, gather_slot);
    // The uploads are on the legacy stream, which stream_ (non-blocking) does not wait for.
    SOFTTLED_CUDA_CHECK(cudaDeviceSynchronize());
    halo_built_ = true;  // also with no layout (nhblock = 0): there would be none next time either
  }
  // Halo step: the largest block (elements, a power of two, at most 2048: two blocks per
  // multiprocessor in float) that still gives every multiprocessor a block.
  void build_halo(const std::vector<int>& gather_start, const std::vector<int>& gather_slot) {
    const int most = int(std::min<std::size_t>(16384, 200 * 1024 / (12 * sizeof(T))));
    HaloBlocks h;
    if (opt_.halo_elements > 0) {
      int cap = 32;
      while (cap * 2 <= std::min(opt_.halo_elements, most)) cap *= 2;
      h = build_halo_blocks(n_, ne_, gather_start, gather_slot, cap);
    } else {
      h = choose_halo_blocks(n_, ne_, gather_start, gather_slot, nsm_, 2048);
    }
    if (h.nblock() <= 0) return;
    rest_.hnode.upload(h.node_start);
    rest_.helem_start.upload(h.elem_start);
    rest_.helem.upload(h.elem);
    rest_.hslot.upload(h.slot);
    rest_.nhblock = h.nblock();
    rest_.hcap = h.cap;
    const int tb = opt_.halo_block;
    rest_.hthreads = tb >= 32 && tb <= kHaloMaxThreads && tb % 32 == 0 ? tb : std::min(h.cap, kHaloMaxThreads);
    halo_duplication_ = h.duplication(ne_);
  }
  int auto_lanes() const { return small_mesh() ? 8 : 4; }

  // A step that is one small wave (about one element per thread of a 128-thread block per
  // SM) is bound by launch and memory latency: prefetching the node stage's rest data
  // before the PDL wait hides part of that; on larger meshes the extra instructions cost
  // more.
  bool small_mesh() const { return ne_ <= 128 * nsm_; }
  LaunchShape element_shape(bool pdl) const { return shape_for(ne_, nsm_, pdl); }  // (loads its rest data itself)
  LaunchShape node_shape(bool pdl) const { return shape_for(lanes_ * n_, nsm_, pdl, small_mesh()); }
  LaunchShape pressure_shape(bool pdl) const { return node_shape(pdl); }  // T4ANP nodal pressure: same lanes

  StepArgs<T> args(const StepParams<T>& p) const {
    StepArgs<T> a;
    a.m = rest_.view;
    a.b.u = const_cast<T*>(live_.u.data());
    a.b.du = const_cast<T*>(live_.du.data());
    a.b.fcorner = const_cast<T*>(live_.fcorner.data());
    a.b.contact = const_cast<std::uint8_t*>(live_.contact.data());
    a.b.fext = fext_active_ ? live_.fext.data() : nullptr;
    a.b.ub = beta_on() ? const_cast<T*>(live_.ub.data()) : nullptr;
    a.mat = cfg_.mat;
    a.p = p;
    a.lanes = lanes_;
    a.anp = cfg_.element == kT4ANP;
    a.vol_now = const_cast<T*>(live_.vol_now.data());
    a.p_node = const_cast<T*>(live_.p_node.data());
    a.X0d = rest_.X0d.data();  // null where the table is read
    a.fblock = rest_.fblock.data();
    a.nfblock = rest_.nfblock;
    a.fsmem_entries = rest_.fsmem_entries;
    a.hnode = rest_.hnode.data();
    a.helem_start = rest_.helem_start.data();
    a.helem = rest_.helem.data();
    a.hslot = rest_.hslot.data();
    a.nhblock = rest_.nhblock;
    a.hcap = rest_.hcap;
    a.health = const_cast<DeviceHealth*>(health_.data());
    a.du2_bound = du2_bound(p.dt);
    return a;
  }

  // Fused step s of a graph (kFused): even steps read (u, du) and write (u2, du2), odd
  // steps the other way round.
  void enqueue_fused_step(const StepArgs<T>& a, int s, bool pdl) {
    const MultiStepBuffers<T> b = state_buffers(a);
    const int p = s & 1;
    if (halo_step())
      SOFTTLED_CUDA_CHECK(launch_halo_step<T>(stream_, rest_.hthreads, pdl, a, b.u[p], b.du[p], b.u[1 - p], b.du[1 - p],
                                              b.ub[p] ? b.ub[p] : b.u[p], b.ub[1 - p]));
    else
      SOFTTLED_CUDA_CHECK(launch_fused_step<T>(stream_, fused_block(), pdl, opt_.fused_preload, a, b.u[p], b.du[p],
                                               b.u[1 - p], b.du[1 - p], b.ub[p] ? b.ub[p] : b.u[p], b.ub[1 - p]));
    enqueue_contact(b.u[1 - p], b.du[1 - p], b.ub[1 - p]);
  }

  // After an odd number of fused steps: the state from (u2, du2, ub2) back to (u, du, ub).
  void copy_back_fused(const StepArgs<T>& a) {
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.u.data(), live_.u2.data(), live_.u.bytes(), cudaMemcpyDeviceToDevice, stream_));
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.du.data(), live_.du2.data(), live_.du.bytes(), cudaMemcpyDeviceToDevice, stream_));
    if (a.b.ub)
      SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(live_.ub.data(), live_.ub2.data(), live_.ub.bytes(), cudaMemcpyDeviceToDevice, stream_));
  }

  // Element stage: one kernel for T4, three for T4ANP (anp.h).
  cudaError_t launch_element_stage(const StepArgs<T>& a, bool pdl) {
    if (a.anp) return launch_anp_stages<T>(stream_, element_shape(pdl), pressure_shape(pdl), a);
    return launch_element_forces<T>(stream_, element_shape(pdl), a);
  }

  void enqueue_step(const StepArgs<T>& a, bool pdl) {
    SOFTTLED_CUDA_CHECK(launch_element_stage(a, pdl));
    SOFTTLED_CUDA_CHECK(launch_node_update<T>(stream_, node_shape(pdl), a));
    enqueue_contact(a.b.u, a.b.du, a.b.ub);
  }

  // Captures `body` (which enqueues kernels on stream_) into an executable graph.
  template <class F>
  cudaGraphExec_t capture(F&& body) {
    SOFTTLED_CUDA_CHECK(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeThreadLocal));
    try {
      body();
    } catch (...) {
      cudaGraph_t g = nullptr;
      cudaStreamEndCapture(stream_, &g);
      if (g) cudaGraphDestroy(g);
      throw;
    }
    cudaGraph_t g = nullptr;
    SOFTTLED_CUDA_CHECK(cudaStreamEndCapture(stream_, &g));
    cudaGraphExec_t exec = nullptr;
    const cudaError_t e = cudaGraphInstantiate(&exec, g, 0);
    cudaGraphDestroy(g);
    SOFTTLED_CUDA_CHECK(e);
    SOFTTLED_CUDA_CHECK(cudaGraphUpload(exec, stream_));
    return exec;
  }

  cudaGraphExec_t graph(int k) {
    const GraphKey key{double(cfg_.step.dt), k};
    auto it = graphs_.find(key);
    if (it != graphs_.end()) return it->second;
    if (graphs_.size() >= kMaxGraphs) clear_graphs();
    const StepArgs<T> a = args(cfg_.step);
    const bool fused = fused_step();
    const bool pdl = run_mode() == ExecMode::kGraphPdl || (fused && fused_pdl_);
    cudaGraphExec_t exec = nullptr;
    try {
      exec = capture([&] {
        if (!fused) {
          for (int s = 0; s < k; ++s) enqueue_step(a, pdl);
          return;
        }
        for (int s = 0; s < k; ++s) enqueue_fused_step(a, s, pdl);
        if (k & 1) copy_back_fused(a);  // every graph starts and ends with the state in (u, du)
      });
    } catch (const CudaError& e) {
      if (!pdl) throw;
      if (fused) {
        std::fprintf(stderr, "cuda: fused graph with programmatic dependent launch failed (%s); without it\n", e.what());
        clear_graphs();
        fused_pdl_ = false;
        return graph(k);
      }
      // A driver that cannot capture programmatic launches: graphs without PDL (kGraph).
      std::fprintf(stderr, "cuda: graphs with programmatic dependent launch failed (%s); using graphs without it\n", e.what());
      clear_graphs();
      mode_ = ExecMode::kGraph;
      return graph(k);
    }
    graphs_[key] = exec;
    return exec;
  }

  void clear_graphs() {
    if ((!graphs_.empty() || !probe_graphs_.empty()) && stream_) cudaStreamSynchronize(stream_);
    for (auto& g : graphs_) cudaGraphExecDestroy(g.second);
    graphs_.clear();
    destroy_probe_graphs();
  }
  void destroy_probe_graphs() {
    for (auto& g : probe_graphs_) cudaGraphExecDestroy(g.second);
    probe_graphs_.clear();
  }

  // Median device time of a graph of `reps` launches of one kernel, in microseconds.
  template <class L>
  double time_graph(int reps, L&& launch_one) {
    cudaGraphExec_t exec = capture([&] {
      for (int r = 0; r < reps; ++r) SOFTTLED_CUDA_CHECK(launch_one());
    });
    std::vector<double> us;
    Event a, b;
    try {
      SOFTTLED_CUDA_CHECK(cudaGraphLaunch(exec, stream_));  // warm-up
      for (int i = 0; i < 7; ++i) {
        SOFTTLED_CUDA_CHECK(cudaEventRecord(a.get(), stream_));
        SOFTTLED_CUDA_CHECK(cudaGraphLaunch(exec, stream_));
        SOFTTLED_CUDA_CHECK(cudaEventRecord(b.get(), stream_));
        SOFTTLED_CUDA_CHECK(cudaEventSynchronize(b.get()));
        us.push_back(elapsed_us(a, b));
      }
    } catch (...) {
      cudaGraphExecDestroy(exec);
      throw;
    }
    cudaGraphExecDestroy(exec);
    std::sort(us.begin(), us.end());
    return us[us.size() / 2];
  }

  template <class U>
  void upload(const std::vector<U>& h, DeviceBuffer<U>& d) const {
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(d.data(), h.data(), h.size() * sizeof(U), cudaMemcpyHostToDevice, stream_));
  }
  template <class U>
  void download(const DeviceBuffer<U>& d, std::vector<U>& h) const {
    h.resize(d.size());
    SOFTTLED_CUDA_CHECK(cudaMemcpyAsync(h.data(), d.data(), d.bytes(), cudaMemcpyDeviceToHost, stream_));
  }

  Options opt_;
  int nsm_ = 1;
  std::string device_name_;
  cudaStream_t stream_ = nullptr;
  MeshPermutation perm_;
  int n_ = 0, ne_ = 0;
  std::vector<double> mass_;  // original node order
  std::vector<std::uint8_t> flags_;  // original node order
  DeviceRest<T> rest_;
  DeviceLive<T> live_;
  BodyContactTables contact_tables_;  // original numbering
  ObstacleGrids<T, DeviceBuffer<T>> grids_;  // mesh obstacles' distance values (hold_grids)
  DeviceContactStage<T> contact_;  // allocated when a contact stage is first switched on
  ContactGridSize contact_grid_;    // the contact grid's buckets and their size, from the mesh at rest
  mutable DeviceBuffer<double> energy_, partials_, energy_sum_;
  mutable DeviceBuffer<T> energy_vol_;  // strain_energy's T4ANP element volumes
  // Snapshot slots (begin_snapshot): pinned copies of u, du, contact; the strain energy
  // on the device and, pinned, its copy and the contact stage's overflow bits.
  struct Snapshot {
    std::unique_ptr<PinnedBuffer<T>> u, du;
    std::unique_ptr<PinnedBuffer<std::uint8_t>> contact;
    PinnedBuffer<double> energy{1};
    PinnedBuffer<unsigned> overflow{1};
    PinnedBuffer<DeviceHealth> health{1};
    Event done;
  };
  std::array<Snapshot, Solver::kSnapshotSlots> snaps_;
  bool fext_active_ = false;
  // The device watchdog's record (DeviceHealth), its pinned copy for take_health, and the
  // speed test's energy bound (set_node_energy_bound).
  DeviceBuffer<DeviceHealth> health_;
  PinnedBuffer<DeviceHealth> health_host_{1};
  double node_energy_ = std::numeric_limits<double>::infinity();
  StepConfig<T> cfg_;
  PhysicsParams params_;
  double dt_mid_ = 0;  // > 0: the next step's midpoint step (change_step)
  // begin_omega_max: warm vector v, f(u), M^-1 K v, u + a v (3 x nnode, T), the
  // product's per-block partials and sums (num, den, max |w|) with the last-block ticket,
  // masses in double and the original node order (start vector)
  struct Probe {
    DeviceBuffer<T> v, f0, w, up;
    DeviceBuffer<double> partials, sums, mass;
    DeviceBuffer<unsigned> ticket;
    DeviceBuffer<int> node_old;
    PinnedBuffer<double> result{3};  // sums, downloaded
    Event begin, end;                 // around the estimate in the stream (its device time)
  } probe_;
  ExecMode mode_ = ExecMode::kAuto;
  int lanes_ = 1;
  bool fused_pdl_ = true;
  double halo_duplication_ = 0;  // elements the halo step computes per mesh element
  bool halo_pays_ = false;  // auto_mode: the mesh is large enough for the halo step
  bool halo_built_ = false;  // ensure_halo has run (nhblock = 0 after it: no layout)
  // Step graphs of k steps at one dt (set_dt keeps them), at most kMaxGraphs of them.
  using GraphKey = std::pair<double, int>;
  static constexpr std::size_t kMaxGraphs = 96;
  std::map<GraphKey, cudaGraphExec_t> graphs_;
  // begin_omega_max's kernels per iteration count, for the amplitude probe_a_.
  std::map<int, cudaGraphExec_t> probe_graphs_;
  // Whether the multi-step kernel fits, per (lanes, T4ANP) variant (use_multi).
  mutable std::map<int, bool> multi_fits_;
  // Steps per multi-step launch: even; a few ms of device time on the torus, so a
  // long run still returns to the host (and a display GPU's watchdog) between launches.
  static constexpr int kMaxMultiSteps = 2048;
  double probe_a_ = 0;
};

}  // namespace
}  // namespace cuda

std::unique_ptr<Solver> make_cuda_solver(const TetMesh& mesh, double rho, const std::vector<std::uint8_t>& flags,
                                         Precision prec, const cuda::Options& opt) {
  std::string why;
  if (cuda::device_count(&why) <= 0) throw InputError("backend 'cuda': " + why);
  if (prec == Precision::kFloat) return std::make_unique<cuda::CudaSolver<float>>(mesh, rho, flags, opt);
  return std::make_unique<cuda::CudaSolver<double>>(mesh, rho, flags, opt);
}

}  // namespace softtled
