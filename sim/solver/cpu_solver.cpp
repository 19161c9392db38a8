// CPU backend: OpenMP loops over the element and node stages. By default the SIMD stages
// (cpu_simd.h: element blocks, Highway vectors, the target chosen at run time); with
// SOFTTLED_CPU_SIMD=0 in the environment or set_cpu_simd(false) the scalar loops of
// cpu_step.h over the same SIM_HD functions the CUDA backend launches (the reference the
// SIMD path is tested against). Each loop iteration writes only its own elements' corners
// or its own nodes, and the gather sums in a fixed order, so results are bitwise
// identical for any thread count.
#include <omp.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cctype>
#include <cerrno>
#include <limits>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <stdexcept>

#include "sim/contact/body_contact_cpu.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/stiffness_probe.h"
#include "sim/fem/surface_render.h"
#include "sim/fem/tet_forces.h"
#include "sim/io/output_file.h"
#include "sim/mesh/surface_topology.h"
#include "sim/solver/cpu_blocks.h"
#include "sim/solver/cpu_energy.h"
#include "sim/solver/cpu_simd.h"
#include "sim/solver/cpu_step.h"
#include "sim/solver/obstacle_grids.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/solver.h"
#include "sim/solver/step_params.h"
#include "sim/core/env_setting.h"

namespace softtled {
namespace {

// libgomp ends the process (exit 1, "Thread creation failed") when it cannot start a team's
// threads, e.g. 1,000 threads' stacks under an address-space limit. Starting as many threads
// here first, with the stack libgomp would give them (OMP_STACKSIZE, else the default),
// turns that into an error naming the setting. Only above the most threads already shown
// to start: libgomp keeps its idle team, so a later solver with as many threads costs
// nothing (a second Python Simulation of 80 threads was refused while the first's team held
// its stacks).
// OMP_STACKSIZE as libgomp reads it (libgomp's env.c, parse_stacksize): spaces, a number
// strtoul reads, spaces, an optional unit B, K, M or G (K by default), spaces, the end; 0
// where libgomp ignores the value ("Invalid value"), as for one beyond size_t (a probe's
// "1e30G" had been an out-of-range conversion: undefined behaviour).
std::size_t omp_stack_bytes() {
  const char* v = std::getenv("OMP_STACKSIZE");
  if (!v) return 0;
  while (std::isspace(static_cast<unsigned char>(*v))) ++v;
  if (!*v) return 0;
  errno = 0;
  char* end = nullptr;
  const unsigned long n = std::strtoul(v, &end, 10);
  if (errno || end == v) return 0;
  while (std::isspace(static_cast<unsigned char>(*end))) ++end;
  int shift = 10;
  if (*end) {
    const char u = char(std::tolower(static_cast<unsigned char>(*end)));
    shift = u == 'b' ? 0 : u == 'k' ? 10 : u == 'm' ? 20 : u == 'g' ? 30 : -1;
    if (shift < 0) return 0;
    for (++end; std::isspace(static_cast<unsigned char>(*end));) ++end;
    if (*end) return 0;
  }
  if (n > (std::numeric_limits<std::size_t>::max() >> shift)) return 0;
  return std::size_t(n) << shift;
}

extern "C" void* idle_thread(void*) { return nullptr; }

void check_threads_can_start(int threads) {
  static int shown = 1;  // the most threads started so far
  if (threads <= shown) return;
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  // (A size the system refuses, e.g. below PTHREAD_STACK_MIN, leaves the default: libgomp
  // warns and goes on with it too.)
  if (const std::size_t stack = omp_stack_bytes()) pthread_attr_setstacksize(&attr, stack);
  std::vector<pthread_t> team;
  int err = 0;
  for (int i = 1; i < threads && !err; ++i) {
    pthread_t t;
    err = pthread_create(&t, &attr, idle_thread, nullptr);
    if (!err) team.push_back(t);
  }
  for (pthread_t t : team) pthread_join(t, nullptr);
  pthread_attr_destroy(&attr);
  if (err)
    throw ResourceError(std::to_string(threads) + " CPU threads (solver.threads, --threads): could not start " +
                        std::to_string(threads - 1) + " more threads (" + std::strerror(err) + " after " +
                        std::to_string(team.size()) +
                        (omp_stack_bytes() ? ", each with OMP_STACKSIZE=" + quoted(std::getenv("OMP_STACKSIZE")) : "") +
                        "); use fewer (0: the automatic choice)" + (omp_stack_bytes() ? " or a smaller stack" : ""));
  shown = threads;
}

template <class T>
class CpuSolver final : public Solver {
 public:
  CpuSolver(const TetMesh& mesh, double rho, const std::vector<std::uint8_t>& flags, int threads)
      : rest_(build_rest_state<T>(mesh, rho, flags)), surf_(build_surface_topology(mesh)),
        bodies_(mesh, rest_.inv_mass) {
    set_cpu_threads(threads);
    const int n = rest_.nnode;
    u_.assign(3 * n, T(0));
    du_.assign(3 * n, T(0));
    fcorner_.assign(12 * rest_.ntet, T(0));
    vol_now_.assign(rest_.ntet, T(0));
    p_node_.assign(n, T(0));
    contact_.assign(n, 0);
    mesh_ = rest_.view();
    bodies_count_ = mesh.nbody();
    blocks_ = build_cpu_blocks(mesh_);
    fblk_.assign(blocks_.force_size(), T(0));
    vol_blk_.assign(blocks_.padded(), T(0));  // fblk_'s last value stays 0 (cpu_blocks.h)
    F_blk_.assign(blocks_.padded() * kBlockFFields, T(0));
    set_cpu_simd(env_switch("SOFTTLED_CPU_SIMD", true));
  }

  std::string backend() const override {
    return "cpu (" + std::to_string(threads_) + " thread" + (threads_ > 1 ? "s, " : ", ") +
           (simd_ ? cpu_simd_target() : "scalar") + ")";
  }
  // Per-body laws (element_law.h) run the scalar loops: the SIMD element stage holds one
  // material for a whole block of elements.
  void set_cpu_simd(bool on) override { simd_ = on && !mesh_.tet_law; }
  bool cpu_simd() const override { return simd_; }
  void set_cpu_threads(int threads) override {
    const int n = threads > 0 ? threads : auto_cpu_threads(rest_.ntet);
    check_threads_can_start(n);
    threads_ = n;
  }
  Precision precision() const override { return sizeof(T) == 4 ? Precision::kFloat : Precision::kDouble; }

  void set_params(const PhysicsParams& p) override {
    const T old_beta_dt = cfg_.step.beta_dt;
    params_ = p;
    cfg_ = step_config_from<T>(p);
    if (cfg_.laws.size() != (mesh_.tet_law ? std::size_t(bodies_count_) : 0))
      throw std::invalid_argument("set_params: body_laws must hold one law per body where the mesh has per-body laws, else none");
    mesh_.laws = cfg_.laws.empty() ? nullptr : cfg_.laws.data();
    hold_grids(p);
    point_at_grids(cfg_.step);
    if (cfg_.step.beta_dt != old_beta_dt || (cfg_.step.beta_dt > 0) != !ub_.empty()) refresh_ub();
  }

  void step(long nsteps) override {
    const TetMeshView<T> m = mesh_;
    const BodyStateView<T> b = view();
    const StepConfig<T> c = cfg_;
    const AnpScratch<T> anp{vol_now_.data(), p_node_.data()};
    const T* ue = element_displacement(b);
    // The first step after a change of dt spans the midpoint step (change_step).
    StepParams<T> first = c.step;
    if (dt_mid_ > 0) {
      first = step_params_from<T>(params_, dt_mid_);
      point_at_grids(first);
    }
    if (nsteps > 0) dt_mid_ = 0;
    // Body-body and self-contact (body_contact_cpu.h): one thread, after the node stage's barrier.
    const bool bodies = params_.body_contact || params_.self_contact;
    const bool pb = params_.body_contact, ps = params_.self_contact;
    CpuBodyContact<T>& bc = bodies_;
    if (simd_) {
      const CpuBlocks<T>& k = blocks_;
      const SimdAnpScratch<T> sa = simd_scratch();
      BodyStateView<T> bb = b;
      bb.fcorner = fblk_.data();
      if (bodies) {  // a loop of its own: the one-body loop below stays as it was
#pragma omp parallel num_threads(threads_)
        for (long s = 0; s < nsteps; ++s) {
          cpu_simd_element_stage(m, k, c.mat, c.element, ue, sa, bb.fcorner);
          cpu_simd_node_stage(m, k, bb, s == 0 ? first : c.step);
#pragma omp single
          bc.apply(m.X0, bb.u, bb.du, bb.ub, c.step.beta_dt, bb.contact, c.step.contact.mode, c.step.contact.mu, pb, ps);
        }
        return;
      }
#pragma omp parallel num_threads(threads_)
      for (long s = 0; s < nsteps; ++s) {
        cpu_simd_element_stage(m, k, c.mat, c.element, ue, sa, bb.fcorner);
        cpu_simd_node_stage(m, k, bb, s == 0 ? first : c.step);
      }
      return;
    }
    if (bodies) {
#pragma omp parallel num_threads(threads_)
      for (long s = 0; s < nsteps; ++s) {
        cpu_element_stage(m, c.mat, c.element, ue, anp, b.fcorner);
        cpu_node_stage(m, b, s == 0 ? first : c.step);
#pragma omp single
        bc.apply(m.X0, b.u, b.du, b.ub, c.step.beta_dt, b.contact, c.step.contact.mode, c.step.contact.mu, pb, ps);
      }
      return;
    }
#pragma omp parallel num_threads(threads_)
    for (long s = 0; s < nsteps; ++s) {
      cpu_element_stage(m, c.mat, c.element, ue, anp, b.fcorner);
      cpu_node_stage(m, b, s == 0 ? first : c.step);
    }
  }

  // One stage of step() (solver.h, the bench hatch), with its arguments built as step() builds them.
  bool run_cpu_stage(CpuStage stage) override {
    const TetMeshView<T> m = mesh_;
    const BodyStateView<T> b = view();
    const StepConfig<T>& c = cfg_;  // no copy of the law table inside the bench's timed loop
    StepParams<T> p = c.step;
    if (stage == CpuStage::kNodeFree) {
      p.contact.nplanes = 0;
      p.contact.nobstacles = 0;
    }
    const T* ue = element_displacement(b);
    const bool element = stage == CpuStage::kElement;
    if (simd_) {
      const CpuBlocks<T>& k = blocks_;
      const SimdAnpScratch<T> sa = simd_scratch();
      BodyStateView<T> bb = b;
      bb.fcorner = fblk_.data();
#pragma omp parallel num_threads(threads_)
      if (element)
        cpu_simd_element_stage(m, k, c.mat, c.element, ue, sa, bb.fcorner);
      else
        cpu_simd_node_stage(m, k, bb, p);
      return true;
    }
    const AnpScratch<T> anp{vol_now_.data(), p_node_.data()};
#pragma omp parallel num_threads(threads_)
    if (element)
      cpu_element_stage(m, c.mat, c.element, ue, anp, b.fcorner);
    else
      cpu_node_stage(m, b, p);
    return true;
  }

  void change_step(double scale, double dt_mid) override {
    for (T& v : du_) v *= T(scale);
    refresh_ub();
    dt_mid_ = dt_mid;
  }

  // Synchronous: the estimate is made here, end_omega_max hands it over.
  void begin_omega_max(int iterations, double a, bool restart) override {
    const auto t0 = std::chrono::steady_clock::now();
    omega_.omega = power_iteration(iterations, a, restart);
    omega_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  OmegaEstimate end_omega_max() override { return omega_; }

  void get_state(HostState& s) const override {
    s.u.assign(u_.begin(), u_.end());
    s.du.assign(du_.begin(), du_.end());
    s.contact = contact_;
  }

  void set_state(const HostState& s) override {
    if (s.u.size() != u_.size() || s.du.size() != du_.size()) throw std::invalid_argument("set_state: size");
    std::transform(s.u.begin(), s.u.end(), u_.begin(), [](double v) { return T(v); });
    std::transform(s.du.begin(), s.du.end(), du_.begin(), [](double v) { return T(v); });
    if (s.contact.size() == contact_.size()) contact_ = s.contact;
    refresh_ub();
    dt_mid_ = 0;
  }

  double strain_energy() const override {
    return cpu_strain_energy(mesh_, cfg_.mat, cfg_.element, u_.data(), energy_vol_, energy_, threads_);
  }

  void set_external_forces(const std::vector<double>& f) override {
    if (f.empty()) {
      fext_.clear();
      return;
    }
    if (f.size() != u_.size()) throw std::invalid_argument("set_external_forces: size");
    fext_.assign(f.begin(), f.end());
  }

  const std::vector<double>& lumped_mass() const override { return rest_.mass; }
  const std::vector<std::uint8_t>& node_flags() const override { return rest_.flags; }

  bool render_buffer_on_device() const override { return false; }
  void write_render_vertices(float* dst, RenderScalar scalar) override {
    const SurfaceView sv = surf_.view();
    const NeoHookean<T> mat = cfg_.mat;
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (int v = 0; v < sv.nvert; ++v) write_render_vertex(mesh_, sv, u_.data(), contact_.data(), scalar, mat, dst, v);
  }

 private:
  // Mesh obstacles (obstacle_sdf.h): the step reads each grid in T from host memory this
  // solver holds; in double that is the grid's own values (params_ holds the grid).
  void hold_grids(const PhysicsParams& p) {
    grids_.hold(p, [](const SdfGrid& g) {
      if constexpr (std::is_same_v<T, double>) return g.value.data();
      else return std::vector<T>(g.value.begin(), g.value.end());
    });
  }
  void point_at_grids(StepParams<T>& s) const {
    grids_.point(params_, s, [](const auto& b) -> const T* {
      if constexpr (std::is_same_v<T, double>) return b;
      else return b.data();
    });
  }

  // The power iteration of stiffness_probe.h on this backend's own element stage and gather.
  double power_iteration(int iterations, double a, bool restart) {
    const int n = rest_.nnode;
    const std::size_t n3 = 3 * std::size_t(n);
    if (probe_v_.size() != n3 || restart) {
      probe_v_.resize(n3);
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < n; ++i)
          probe_v_[k * n + i] = rest_.inv_mass[i] > 0 ? T(probe_start(unsigned(k * n + i))) : T(0);
    }
    probe_f0_.resize(n3);
    probe_w_.resize(n3);
    probe_up_.resize(n3);
    internal_forces(u_.data(), probe_f0_.data());
    const T ta = T(a), inv_a = T(1) / ta;
    double lambda = 0;
    for (int it = 0; it < iterations; ++it) {
      for (std::size_t j = 0; j < n3; ++j) probe_displacement(u_[j], probe_v_[j], ta, probe_up_[j], probe_v_[j]);
      internal_forces(probe_up_.data(), probe_w_.data());
      double num = 0, den = 0, wmax = 0;  // fixed order: the same bits for any thread count
      for (int i = 0; i < n; ++i) {
        T f1[3], f0[3], w[3];
        for (int k = 0; k < 3; ++k) {
          f1[k] = probe_w_[k * n + i];
          f0[k] = probe_f0_[k * n + i];
        }
        probe_response(f1, f0, rest_.inv_mass[i], inv_a, w);
        for (int k = 0; k < 3; ++k) {
          probe_w_[k * n + i] = w[k];
          const double v = double(probe_v_[k * n + i]);
          num += rest_.mass[i] * double(w[k]) * double(w[k]);
          den += rest_.mass[i] * v * v;
          wmax = std::max(wmax, std::fabs(double(w[k])));
        }
      }
      if (!(den > 0) || !(wmax > 0)) return 0;
      lambda = std::sqrt(num / den);
      const T s = T(1.0 / wmax);
      for (std::size_t j = 0; j < n3; ++j) probe_v_[j] = probe_w_[j] * s;
    }
    return std::sqrt(lambda);
  }

  // Summed internal force per node (3 x nnode) at displacement u: the step's element
  // stage and gather. Uses fcorner_ and the T4ANP scratch, which the next step rewrites.
  void internal_forces(const T* u, T* f) {
    const TetMeshView<T> m = mesh_;
    const StepConfig<T> c = cfg_;
    const AnpScratch<T> anp{vol_now_.data(), p_node_.data()};
    T* fc = simd_ ? fblk_.data() : fcorner_.data();
    const int n = m.nnode;
    const bool simd = simd_;
    const CpuBlocks<T>& blk = blocks_;
    const SimdAnpScratch<T> sa = simd_scratch();
#pragma omp parallel num_threads(threads_)
    {
      if (simd)
        cpu_simd_element_stage(m, blk, c.mat, c.element, u, sa, fc);
      else
        cpu_element_stage(m, c.mat, c.element, u, anp, fc);
#pragma omp for schedule(static)
      for (int i = 0; i < n; ++i) {
        T fi[3];
        if (simd)
          cpu_simd_gather(m, blk, fc, i, fi);
        else
          gather_node_force(m.gather_start, m.gather_slot, fc, i, fi);
        for (int k = 0; k < 3; ++k) f[k * n + i] = fi[k];
      }
    }
  }

  SimdAnpScratch<T> simd_scratch() { return {vol_blk_.data(), p_node_.data(), F_blk_.data()}; }

  // ub = u + (beta / dt) du from the live state (rayleigh_displacement, as the node stage
  // writes it), or no ub when beta = 0: after a new state, beta or dt.
  void refresh_ub() {
    const T r = cfg_.step.beta_dt;
    if (!(r > 0)) {
      ub_.clear();
      return;
    }
    ub_.resize(u_.size());
    for (std::size_t k = 0; k < u_.size(); ++k) ub_[k] = rayleigh_displacement(u_[k], du_[k], r);
  }

  BodyStateView<T> view() {
    BodyStateView<T> b;
    b.u = u_.data();
    b.du = du_.data();
    b.fcorner = fcorner_.data();
    b.contact = contact_.data();
    b.fext = fext_.empty() ? nullptr : fext_.data();
    b.ub = ub_.empty() ? nullptr : ub_.data();
    return b;
  }

  int threads_ = 1;
  bool simd_ = true;  // the SIMD stages (cpu_simd.h), else the scalar ones (cpu_step.h)
  RestArrays<T> rest_;
  SurfaceTopology surf_;
  CpuBodyContact<T> bodies_;  // body-body and self-contact
  TetMeshView<T> mesh_;
  int bodies_count_ = 1;
  std::vector<T> u_, du_, fcorner_, fext_;
  std::vector<T> ub_;  // 3 x nnode, u + (beta / dt) du while beta > 0, else empty
  // power_iteration: the warm vector v (max-norm 1), f(u), M^-1 K v, u + a v (3 x nnode)
  std::vector<T> probe_v_, probe_f0_, probe_w_, probe_up_;
  OmegaEstimate omega_;  // begin_omega_max's result
  PhysicsParams params_;
  double dt_mid_ = 0;  // > 0: the next step's midpoint step (change_step)
  std::vector<T> vol_now_, p_node_;  // T4ANP: current element volumes, nodal pressures
  CpuBlocks<T> blocks_;              // the rest state in element blocks (SIMD stages)
  std::vector<T> fblk_;              // blocked corner forces (CpuBlocks::force_size)
  std::vector<T> vol_blk_, F_blk_;   // SIMD T4ANP: element volumes (padded), F per block
  mutable std::vector<double> energy_;  // strain_energy's per-element (and per-node) terms
  mutable std::vector<T> energy_vol_;   // strain_energy's T4ANP element volumes
  std::vector<std::uint8_t> contact_;
  StepConfig<T> cfg_;
  // each mesh obstacle's values in T (hold_grids): in double a pointer to the grid's own
  ObstacleGrids<T, std::conditional_t<std::is_same_v<T, double>, const double*, std::vector<T>>> grids_;
};

}  // namespace

// The CPUs this process may run on (taskset, a container's limit); false when unknown.
static bool allowed_cpus(cpu_set_t& set) {
  CPU_ZERO(&set);
  return sched_getaffinity(0, sizeof set, &set) == 0;
}

static int physical_cores() {
  // Distinct (package, core) pairs among the CPUs this process may run on: SMT siblings
  // share a core's SIMD units, so a second thread per core only adds barrier time.
  cpu_set_t set;
  if (!allowed_cpus(set)) return omp_get_num_procs();
  std::set<std::pair<int, int>> cores;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &set)) continue;
    int id[2] = {-1, -1};
    const char* names[2] = {"physical_package_id", "core_id"};
    for (int k = 0; k < 2; ++k) {
      std::ifstream f("/sys/devices/system/cpu/cpu" + std::to_string(cpu) + "/topology/" + names[k]);
      if (!(f >> id[k])) return std::max(1, CPU_COUNT(&set));
    }
    cores.insert({id[0], id[1]});
  }
  return std::max<int>(1, int(cores.size()));
}

int auto_cpu_threads(int ntet) {
  static const int cores = physical_cores();
  // omp_get_max_threads(): OMP_NUM_THREADS, when set, caps it (callgrind runs use 1).
  const int cap = std::min(cores, omp_get_max_threads());
  return std::clamp(ntet / kTetsPerThread, 1, std::max(1, cap));
}

std::string cpu_threads_warning(int threads) {
  cpu_set_t set;
  const int hw = allowed_cpus(set) ? CPU_COUNT(&set) : omp_get_num_procs();
  if (threads <= 0 || hw <= 0 || threads <= hw) return "";
  return std::to_string(threads) + " CPU threads on the " + std::to_string(hw) +
         " CPUs this process may use: the extra threads wait for time slices at every barrier of the step, which makes it "
         "many times slower (use 0, the automatic choice, or at most " + std::to_string(hw) + ")";
}

std::unique_ptr<Solver> make_cpu_solver(const TetMesh& mesh, double rho,
                                        const std::vector<std::uint8_t>& flags, Precision prec,
                                        int threads) {
  if (prec == Precision::kFloat) return std::make_unique<CpuSolver<float>>(mesh, rho, flags, threads);
  return std::make_unique<CpuSolver<double>>(mesh, rho, flags, threads);
}

}  // namespace softtled
