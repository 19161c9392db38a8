// `softtled bench`: time per explicit step in the form of the paper's Table II (Li, Guo et
// al., section IV.D: 8000 iterations, columns M, f, u, u', total), for the CPU or the
// CUDA backend, and a sweep over refined tori against the device's copy bandwidth.
//
// Measured: warm-up, then `samples` chunks of steps, each timed (device events on the
// GPU, wall clock on the CPU); median, min, max, p10, p90 of us/step. The scene runs as
// in a real simulation (the torus falls and hits the floor), so contact costs what it
// costs. Per-stage times replay one kernel (or one OpenMP loop) alone many times.
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "commands.h"
#include "sim/io/output_file.h"
#include "sim/solver/cpu_simd.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"
#include "sim/scene/solver_access.h"
#include "sim/mesh/surface_mesh.h"
#include "sim/fem/surface_render.h"
#include "sim/fem/tet_forces.h"
#if defined(SOFTTLED_HAVE_CUDA)
#include "sim/solver/cuda/cuda_solver.h"
#include "sim/solver/cuda/device_info.h"
#endif

namespace softtled {
namespace {

using Clock = std::chrono::steady_clock;

struct Stats {
  double median = 0, min = 0, max = 0, p10 = 0, p90 = 0;
};

Stats stats_of(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto q = [&](double f) { return v[std::min(v.size() - 1, std::size_t(std::lround(f * double(v.size() - 1))))]; };
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.min = v.front();
  s.max = v.back();
  s.p10 = q(0.1);
  s.p90 = q(0.9);
  return s;
}

struct StageRow {
  double forces = 0, update = 0, contact = 0, render = 0;  // us per call
  bool valid = false;
};

struct Result {
  std::string label, backend, device, precision, mode;
  int ntet = 0, nnode = 0, nsurf = 0, threads = 0;
  double dt = 0;
  long steps = 0;
  int samples = 0;
  Stats us;                 // per step
  double wall_us = 0;       // host wall clock over all timed steps, per step
  double bytes = 0;         // per step, compulsory (see step_bytes)
  StageRow stages;
  std::vector<std::pair<std::string, Stats>> modes;  // CUDA execution modes compared
  // One live omega_max estimate (time.dt = "adaptive"): its own execution time (device
  // time on a GPU: what it costs a run, which overlaps the host's wait with later steps),
  // and the host's wall time when it waits for the result at once.
  Stats estimate_us, estimate_wall_us;
};

// Bytes one step must move through DRAM (each array read or written once). The two-kernel
// step: the element stage reads tet, dhdX, vol and u, writes the corner forces; the node
// stage reads the gather table and the corner forces, flags, 1/m, u, du (X0 for contact
// nodes), writes u, du and the contact state. kDerived: the element stage derives dhdX
// from the rest positions in double instead (derive_dhdX). kHalo (tled_halo_step.cu):
// no corner forces in memory; each element's rest data and block index once (a border
// element's second reading, by the neighbouring block, counted as an L2 hit), and a
// 16-bit slot per gather entry instead of the 4-byte gather table.
enum class StepLayout { kTwoKernel, kDerived, kHalo };
double step_bytes(long ntet, long nnode, long ncontact, int real, StepLayout layout) {
  const double T = real;
  const double nodes = (nnode + 1) * 4.0 + nnode * (1 + T + 4 * 3 * T + 1) + ncontact * 3 * T;
  switch (layout) {
    case StepLayout::kDerived:
      return ntet * (4 * 4 + T + 12 * T) + nnode * (3 * T + 4 * 8.0) + ntet * (4 * 4.0 + 12 * T) + nodes;
    case StepLayout::kHalo:
      return ntet * (4 + 4 * 4 + 12 * T + T) + nnode * 3 * T + ntet * 4 * 2.0 + nodes;
    case StepLayout::kTwoKernel: break;
  }
  return ntet * (4 * 4 + 12 * T + T + 12 * T) + nnode * 3 * T + ntet * (4 * 4.0 + 12 * T) + nodes;
}

// The CPU backend's stages, each timed alone (one OpenMP region per call), run by the
// solver itself (Solver::run_cpu_stage): the loops its step runs (SIMD, or scalar where
// it runs those: --cpu-path scalar, or a body with its own law) on its rest state,
// per-body laws, parameters and obstacle grids, starting from the live state the timed
// steps left, which is put back afterwards.
StageRow cpu_stages(Simulation& sim, Solver& solver, int reps) {
  HostState keep;
  solver.get_state(keep);
  auto time_loop = [&](auto&& body) {
    std::vector<double> us;
    // A signal ends the stage timing too (its numbers are dropped with the rest): with
    // many more threads than cores it took 83 s to answer SIGTERM here.
    for (int rep = 0; rep < 5 && !stop_requested(); ++rep) {
      solver.set_state(keep);
      const auto t0 = Clock::now();
      for (int k = 0; k < reps && !stop_requested(); ++k) body();
      us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / reps);
    }
    return stats_of(us).median;
  };
  auto stage = [&](Solver::CpuStage st) { return time_loop([&] { solver.run_cpu_stage(st); }); };
  StageRow s;
  // The element stage first: the node stages gather the corner forces it leaves.
  s.forces = stage(Solver::CpuStage::kElement);
  s.update = stage(Solver::CpuStage::kNodeFree);
  s.contact = std::max(0.0, stage(Solver::CpuStage::kNode) - s.update);
  std::vector<float> buf(std::size_t(kRenderFloatsPerVertex) * sim.mesh().surface_nodes.size() + 8);
  s.render = time_loop([&] { sim.write_render_vertices(buf.data(), RenderScalar::kDisplacement); });  // the |u| map
  solver.set_state(keep);
  s.valid = true;
  return s;
}

struct Opts {
  std::string scene, backend = "auto", json, precision = "float", mode = "auto", cpu_path = "simd";
  std::vector<std::string> set;
  long steps = 8000;
  int samples = 15, threads = 0, stage_reps = 200;
  bool sweep = false, compare_modes = true;
};

// solver.threads (--threads sets it), 0: the backend's automatic choice.
int cpu_threads_for(const Simulation& sim, int requested) {
  return requested > 0 ? requested : auto_cpu_threads(sim.mesh().ntet());
}

// n steps timed by `timed` (us), in pieces of about half a second (from us_per_step, an
// estimate, then from each piece, growing at most 8x), so that a signal stops a long sample
// (--steps reaches 1e9: hours) within one piece; a sample shorter than that (the usual
// ~25 ms) is one piece, timed as one call. Returns the time of the pieces run.
double timed_in_pieces(long n, const std::function<double(long)>& timed, double us_per_step) {
  constexpr double kPieceUs = 5e5;
  auto steps_for = [&](double per_step) {
    return per_step > 0 ? std::max(1.0, std::min(kPieceUs / per_step, 1e12)) : 1.0;  // 0 or NaN: one step
  };
  double us = 0;
  for (long done = 0, piece = std::lround(steps_for(us_per_step)); done < n && !stop_requested();) {
    const long k = std::min(piece, n - done);
    const double t = timed(k);
    us += t;
    done += k;
    piece = std::min(8 * k, std::lround(steps_for(t / double(k))));
  }
  return us;
}

// steps < 0: adapt the chunk so each sample takes about 25 ms.
Result measure(const Scene& sc, const std::string& label, const Opts& o, long steps, bool full) {
  Result r;
  r.label = label;
  Simulation sim(sc, o.backend);
  Solver& solver = SolverAccess::of(sim);
  r.backend = o.backend;
  r.precision = precision_name(sc.precision);
  r.ntet = sim.mesh().ntet();
  r.nnode = sim.mesh().nnode();
  r.nsurf = int(sim.mesh().surface_nodes.size());
  r.dt = sim.time_step().dt;
  r.device = "CPU";
  long ncontact = 0;
  for (auto f : sim.node_flags()) ncontact += (f & kNodeContact) ? 1 : 0;
  const int real = sc.precision == Precision::kFloat ? 4 : 8;
  r.bytes = step_bytes(r.ntet, r.nnode, ncontact, real, StepLayout::kTwoKernel);

#if defined(SOFTTLED_HAVE_CUDA)
  auto* gpu = dynamic_cast<cuda::CudaSolverApi*>(&solver);
#else
  void* gpu = nullptr;
#endif
  std::function<void()> sync = [] {};
  std::function<double(long)> timed = [&](long n) {
    const auto t0 = Clock::now();
    sim.step(n);
    return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
  };
#if defined(SOFTTLED_HAVE_CUDA)
  if (gpu) {
    if (o.mode != "auto") gpu->set_exec_mode(cuda::parse_exec_mode(o.mode));
    r.device = gpu->device_name();
    r.mode = std::string(cuda::exec_mode_name(gpu->exec_mode())) + ", " + std::to_string(gpu->node_lanes()) + " lanes/node";
    const cuda::ExecMode em = gpu->exec_mode();
    if (gpu->derives_gradients() && sc.element == kT4 && (em == cuda::ExecMode::kGraphPdl || em == cuda::ExecMode::kGraph)) {
      r.mode += ", dh/dX derived";
      r.bytes = step_bytes(r.ntet, r.nnode, ncontact, real, StepLayout::kDerived);
    }
    if (const std::string h = gpu->halo_layout(); !h.empty()) {
      r.mode += ", " + h;
      r.bytes = step_bytes(r.ntet, r.nnode, ncontact, real, StepLayout::kHalo);
    }
    sync = [gpu] { gpu->synchronize(); };
    timed = [gpu](long n) { return gpu->time_steps_us(n); };
  }
#endif
  if (!gpu) {
    r.threads = cpu_threads_for(sim, sc.threads);
    solver.set_cpu_threads(r.threads);
    solver.set_cpu_simd(o.cpu_path == "simd");
    // The path the step runs: a body with its own law runs the scalar loops (cpu_solver.cpp).
    r.mode = "openmp x" + std::to_string(r.threads) + ", " +
             (solver.cpu_simd() ? cpu_simd_target() : o.cpu_path == "simd" ? "scalar (per-body laws)" : "scalar");
  }

  // Warm-up (module load, graph instantiation, caches), then the chunk size.
  sim.step(3);
  sync();
  // Exactly `steps` timed steps when given (checked >= samples up front): the first
  // steps % samples samples take one step more than the others.
  long chunk = 0, extra = 0;
  double est = 0;  // us per step, for the samples' pieces
  if (steps > 0) {
    chunk = steps / o.samples;
    extra = steps % o.samples;
    const auto t0 = Clock::now();
    const long warm = std::min(chunk, 500L);
    for (long k = 0; k < warm && !stop_requested(); k += 50) sim.step(std::min(50L, warm - k));
    sync();
    est = std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / double(warm);
  } else {
    est = std::max(1e-3, timed(20) / 20);
    chunk = std::max(1L, std::lround(25000.0 / est));
  }
  sync();
  std::vector<double> per_step;
  const auto w0 = Clock::now();
  for (int s = 0; s < o.samples && !stop_requested(); ++s) {
    const long n = chunk + (s < extra ? 1 : 0);
    per_step.push_back(timed_in_pieces(n, timed, est) / double(n));
  }
  sync();
  r.steps = chunk * o.samples + extra;
  r.samples = o.samples;
  if (stop_requested()) return r;  // the caller reports the stop; nothing is written
  r.wall_us = std::chrono::duration<double, std::micro>(Clock::now() - w0).count() / double(r.steps);
  r.us = stats_of(per_step);
  std::fprintf(stderr, "  %-5s %8d tets: %.3f us/step median (%s, %s)\n", label.c_str(), r.ntet, r.us.median, r.device.c_str(),
               r.mode.c_str());
  // The bench steps without the watchdog: a step it was allowed to take above dt_cr
  // (time.allow_unstable) timed a blown-up state with exit 0 and nothing said.
  {
    const HostState& st = sim.state();
    if (!std::all_of(st.u.begin(), st.u.end(), [](double v) { return std::isfinite(v); }))
      std::fprintf(stderr,
                   "warning: %s: the state is not finite after the timed steps (dt = %.4g s, dt_cr = %.4g s): the figures "
                   "time a diverged run\n",
                   label.c_str(), sim.time_step().dt, sim.time_step().dt_cr);
  }

  if (full) {
    // The adaptive step's estimate as Simulation::adapt_step runs it (AdaptiveStep::kIterations
    // products, warm, the result waited for), on the state the timed steps left.
    const double a = (sc.precision == Precision::kFloat ? 1e-3 : 1e-6) * sim.time_step().min_Le;
    solver.estimate_omega_max(AdaptiveStep::kIterations, a, true);  // graphs, warm vector
    std::vector<double> wall, own;
    for (int s = 0; s < o.samples && !stop_requested(); ++s) {
      sync();
      const auto t0 = Clock::now();
      solver.begin_omega_max(AdaptiveStep::kIterations, a);
      own.push_back(1e6 * solver.end_omega_max().seconds);
      wall.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    r.estimate_us = stats_of(own);
    r.estimate_wall_us = stats_of(wall);
  }

#if defined(SOFTTLED_HAVE_CUDA)
  if (gpu) {
    {
      const int reps = full ? o.stage_reps : std::clamp(int(200.0 * 7000 / std::max(1, r.ntet)), 10, 200);
      const cuda::StageTimes t = gpu->time_stages(reps);
      r.stages.forces = t.forces_us;
      r.stages.update = t.update_only_us;
      r.stages.contact = std::max(0.0, t.update_contact_us - t.update_only_us);
      r.stages.render = t.render_us;
      r.stages.valid = true;
    }
    const int cmp_samples = std::max(3, o.samples / 2);
    auto timed_samples = [&](cuda::CudaSolverApi* api) {
      api->step(std::min(chunk, 200L));
      api->synchronize();
      std::vector<double> v;
      const std::function<double(long)> t = [api](long n) { return api->time_steps_us(n); };
      for (int s = 0; s < cmp_samples && !stop_requested(); ++s)
        v.push_back(timed_in_pieces(chunk, t, r.us.median) / double(chunk));
      return stats_of(v);
    };
    if (o.compare_modes) {
      const cuda::ExecMode keep = gpu->exec_mode();
      const int keep_lanes = gpu->node_lanes();
      const std::string lanes_tag = ",lanes=" + std::to_string(keep_lanes);
      // The product's three steps (what auto picks between), the opt-in multi-step launch
      // and graph-pdl's fallback.
      for (cuda::ExecMode m : {cuda::ExecMode::kMulti, cuda::ExecMode::kFused, cuda::ExecMode::kHalo,
                               cuda::ExecMode::kGraphPdl, cuda::ExecMode::kGraph}) {
        sim.reset();
        gpu->set_exec_mode(m);
        r.modes.emplace_back(cuda::exec_mode_name(m) + lanes_tag, timed_samples(gpu));
      }
      gpu->set_exec_mode(keep);
      for (int lanes : {1, 4, 8}) {
        if (lanes == keep_lanes) continue;
        sim.reset();
        gpu->set_node_lanes(lanes);
        r.modes.emplace_back(std::string(cuda::exec_mode_name(keep)) + ",lanes=" + std::to_string(lanes), timed_samples(gpu));
      }
      gpu->set_node_lanes(keep_lanes);
    }
    if (!full) {
      // The same mesh without the Morton renumbering (TetGen's numbering), same mode.
      cuda::Options opt = cuda::options_from_env();
      opt.reorder = false;
      opt.mode = gpu->exec_mode();
      opt.node_lanes = gpu->node_lanes();
      auto plain = make_cuda_solver(sim.mesh(), sc.rho, sim.node_flags(), sc.precision, opt);
      plain->set_params(sim.params());
      sim.reset();
      HostState st = sim.state();
      plain->set_state(st);
      r.modes.emplace_back(std::string(cuda::exec_mode_name(opt.mode)) + ",lanes=" + std::to_string(opt.node_lanes) + ",tetgen-order",
                           timed_samples(dynamic_cast<cuda::CudaSolverApi*>(plain.get())));
    }
    return r;
  }
#endif
  if (!full) return r;
  if (!gpu) {
    const int reps = std::max(1, int(std::min<long>(o.stage_reps, 200000 / std::max(1, r.ntet / 100 + 1))));
    r.stages = cpu_stages(sim, solver, reps);
  }
  return r;
}

std::string json_stats(const Stats& s) {
  char b[256];
  std::snprintf(b, sizeof b, "{\"median\": %.5g, \"min\": %.5g, \"max\": %.5g, \"p10\": %.5g, \"p90\": %.5g}", s.median, s.min,
                s.max, s.p10, s.p90);
  return b;
}

std::string json_result(const Result& r, double copy_gbs) {
  std::ostringstream j;
  char b[512];
  j << "{\"label\": " << json_string(r.label) << ", \"backend\": " << json_string(r.backend)
    << ", \"device\": " << json_string(r.device) << ", \"precision\": " << json_string(r.precision)
    << ", \"mode\": " << json_string(r.mode);
  std::snprintf(b, sizeof b,
                ", \"tets\": %d, \"nodes\": %d, \"surface_nodes\": %d, \"dt_us\": %.6g, \"steps\": %ld, \"samples\": %d, "
                "\"us_per_step\": ",
                r.ntet, r.nnode, r.nsurf, r.dt * 1e6, r.steps, r.samples);
  j << b << json_stats(r.us);
  std::snprintf(b, sizeof b,
                ", \"wall_us_per_step\": %.5g, \"steps_per_s\": %.6g, \"real_time_factor\": %.5g, \"bytes_per_step\": %.6g, "
                "\"achieved_GBps\": %.5g",
                r.wall_us, 1e6 / r.us.median, r.dt * 1e6 / r.us.median, r.bytes, r.bytes / r.us.median * 1e-3);
  j << b;
  if (copy_gbs > 0) {
    std::snprintf(b, sizeof b, ", \"copy_GBps\": %.5g, \"roofline_fraction\": %.4g", copy_gbs,
                  r.bytes / r.us.median * 1e-3 / copy_gbs);
    j << b;
  }
  if (r.stages.valid) {
    std::snprintf(b, sizeof b,
                  ", \"stages_us\": {\"forces\": %.5g, \"update\": %.5g, \"contact\": %.5g, \"render_write\": %.5g}",
                  r.stages.forces, r.stages.update, r.stages.contact, r.stages.render);
    j << b;
  }
  if (!r.modes.empty()) {
    j << ", \"modes_us_per_step\": {";
    for (std::size_t i = 0; i < r.modes.size(); ++i)
      j << (i ? ", " : "") << json_string(r.modes[i].first) << ": " << json_stats(r.modes[i].second);
    j << "}";
  }
  j << "}";
  return j.str();
}

}  // namespace

Command add_bench_command(CLI::App& app) {
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("bench", "time the explicit step (paper's Table II); --sweep over refined tori");
  CLI::Option* scene_opt = c->add_option("--scene", o->scene, "scene file (TOML)")->required();
  c->add_option("--backend", o->backend, "cpu, cuda or auto (cuda when a device is usable)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))->capture_default_str();
  c->add_option("--steps", o->steps, "timed steps for the scene (paper: 8000)")->check(int_range(1, 1000000000))->capture_default_str();
  CLI::Option* json_opt = c->add_option("--json", o->json, "write the results as JSON");
  c->add_flag("--sweep", o->sweep, "also time refined tori of about 7k, 28k, 100k and 1M tets");
  c->add_flag("--no-compare{false}", o->compare_modes, "CUDA: time only the chosen mode, not the others and other lane counts");
  CLI::Option* prec_opt =
      c->add_option("--precision", o->precision,
                    "float or double: the precision timed, float unless given (the paper's GPU precision), "
                    "whatever the scene's solver.precision says")
          ->check(CLI::IsMember({"float", "double"}))
          ->capture_default_str();
  c->add_option("--mode", o->mode, "CUDA execution: auto, multi, fused, halo, graph-pdl, graph")
      ->check(CLI::IsMember({"auto", "multi", "fused", "halo", "graph-pdl", "graph"}))->capture_default_str();
  CLI::Option* threads_opt =
      c->add_option("--threads", o->threads, "CPU threads (0: the backend's automatic choice; default: the scene's solver.threads)")
          ->check(int_range(0, 1024));
  c->add_option("--cpu-path", o->cpu_path, "CPU stages: simd (the product) or scalar (the reference they are tested against)")
      ->check(CLI::IsMember({"simd", "scalar"}))->capture_default_str();
  c->add_option("--samples", o->samples, "timed chunks per measurement")->check(int_range(3, 1000))->capture_default_str();
  c->add_option("--stage-reps", o->stage_reps, "launches per stage timing")->check(int_range(1, 100000))->capture_default_str();
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  return [o, c, scene_opt, json_opt, prec_opt, threads_opt]() {
    if (scene_opt->count() && o->scene.empty()) throw InputError("--scene: empty path");
    if (json_opt->count() && o->json.empty()) throw InputError("--json: empty path");
    if (!o->json.empty()) check_output_file(o->json, "--json");  // before minutes of timing
    // Exactly --steps timed steps, split over --samples timed chunks of one step at least.
    if (o->steps < o->samples)
      throw InputError("--steps " + std::to_string(o->steps) + ": fewer than --samples " + std::to_string(o->samples) +
                       " (each sample times at least one step); give --steps >= --samples");
    o->backend = resolve_backend(o->backend);
    if (o->backend == "cpu")  // CUDA's execution modes: nothing to choose or compare on the CPU
      for (const char* flag : {"--mode", "--no-compare"})
        if (c->count(flag)) throw InputError(std::string(flag) + " is for the CUDA backend (here: cpu)");
    std::vector<std::string> set = o->set;
    auto in_set = [&set](const char* key) {
      return std::any_of(set.begin(), set.end(), [key](const std::string& kv) { return kv.rfind(key, 0) == 0; });
    };
    // --precision (default float) unless --set gives solver.precision; both: which one?
    const bool set_precision = in_set("solver.precision=");
    if (set_precision && prec_opt->count())
      throw InputError("--precision and --set solver.precision both given: give one");
    if (!set_precision) set.push_back("solver.precision=" + o->precision);
    // --threads is solver.threads (no default of its own: else the scene's); both: which one?
    if (threads_opt->count()) {
      if (in_set("solver.threads=")) throw InputError("--threads and --set solver.threads both given: give one");
      set.push_back("solver.threads=" + std::to_string(o->threads));
    }
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    const Scene sc = load_scene(o->scene, set);
    if (!o->json.empty()) check_not_scene_input(sc, "--scene", {o->json, "--json", true});
    install_stop_signals();  // SIGINT/SIGTERM/SIGHUP: stop within a piece of a sample (timed_in_pieces), write nothing
    auto stopped = [&]() {
      std::fprintf(stderr, "softtled: stopped by signal %d before the benchmark finished; wrote nothing\n", stop_signal());
      return exit_code_for_signal(stop_signal());
    };
#if !defined(SOFTTLED_HAVE_CUDA)
    if (o->backend == "cuda") throw InputError("backend 'cuda': this build has no CUDA backend");
#endif
    double copy_gbs = 0;
#if defined(SOFTTLED_HAVE_CUDA)
    if (o->backend == "cuda") {
      std::string why;
      if (cuda::device_count(&why) <= 0) throw InputError("backend 'cuda': " + why);
      const cuda::DeviceInfo d = cuda::device_info();
      std::printf("device: %s, %d SMs, %.0f MB L2, CUDA driver %d runtime %d\n", d.name.c_str(), d.sm_count,
                  double(d.l2_bytes) / 1e6, d.driver_version, d.runtime_version);
      copy_gbs = cuda::measure_copy_bandwidth_gbs();
      std::printf("measured copy bandwidth: %.0f GB/s (1 GiB float4 copy, read + write)\n", copy_gbs);
      flush_stdout();  // progress survives a killed run
    }
#endif
    // The sweep's refined tori, read now: a scene whose body is no torus (body.segments
    // refused) is refused before anything is timed, not after the scene's own sample.
    struct Level {
      std::string label;
      Scene scene;
    };
    std::vector<Level> levels;
    if (o->sweep) {
      const std::vector<std::pair<const char*, std::vector<std::string>>> refined = {
          {"28k", {"body.segments=[120,25]", "mesh.max_volume=0.15"}},
          {"100k", {"body.segments=[182,38]", "mesh.max_volume=0.028"}},
          {"1M", {"body.segments=[360,72]", "mesh.max_volume=0.0018"}},
      };
      for (const auto& [label, extra] : refined) {
        std::vector<std::string> s2 = set;
        s2.insert(s2.end(), extra.begin(), extra.end());
        levels.push_back({label, load_scene(o->scene, s2)});
      }
    }
    const Result main = measure(sc, "scene", *o, o->steps, true);
    if (stop_requested()) return stopped();
    const double paper_iters = 8000;
    std::printf("\n%s: %d tets, %d nodes, dt = %.4g us, %s, %s, %s\n", o->scene.c_str(), main.ntet, main.nnode, main.dt * 1e6,
                main.device.c_str(), main.precision.c_str(), main.mode.c_str());
    std::printf("  us/step: median %.3f  min %.3f  max %.3f  p10 %.3f  p90 %.3f  (%d samples x %ld steps); wall %.3f us/step\n",
                main.us.median, main.us.min, main.us.max, main.us.p10, main.us.p90, main.samples,
                main.steps / main.samples, main.wall_us);
    if (main.steps % main.samples)
      std::printf("  (%ld steps timed in all: %ld samples of %ld steps, the others %ld)\n", main.steps,
                  main.steps % main.samples, main.steps / main.samples + 1, main.steps / main.samples);
    std::printf("  steps/s: %.4g   real-time factor at dt: %.4g   (8000 steps: %.1f ms)\n", 1e6 / main.us.median,
                main.dt * 1e6 / main.us.median, main.us.median * paper_iters * 1e-3);
    if (main.stages.valid) {
      std::printf("  per stage (us/call; ms per 8000 in brackets), as Table II: M precomputed | f %.3f [%.1f] | u %.3f [%.1f] | "
                  "u' contact %.3f [%.1f] | render write %.3f [%.1f]\n",
                  main.stages.forces, main.stages.forces * 8, main.stages.update, main.stages.update * 8, main.stages.contact,
                  main.stages.contact * 8, main.stages.render, main.stages.render * 8);
    }
    std::printf("  omega_max estimate (%d products): %.1f us median (min %.1f) = %.1f steps, %.1f %% of the step time "
                "at one per %d steps; waited for at once: %.1f us wall\n",
                AdaptiveStep::kIterations, main.estimate_us.median, main.estimate_us.min,
                main.estimate_us.median / main.us.median, 100 * main.estimate_us.median / (AdaptiveStep::kEvery * main.us.median),
                AdaptiveStep::kEvery, main.estimate_wall_us.median);
    for (const auto& m : main.modes)
      std::printf("  mode %-26s median %.3f us/step (min %.3f, max %.3f)\n", m.first.c_str(), m.second.median, m.second.min,
                  m.second.max);
    flush_stdout();

    std::vector<Result> rows;
    if (o->sweep) {
      std::fprintf(stderr, "sweep (meshing the refined tori takes a while)\n");
      // The first row is the scene's own mesh, named for its size ("7k": the paper's torus).
      const double k = std::round(main.ntet / 1e3);
      rows.push_back(measure(sc, k >= 1 ? std::to_string(long(k)) + "k" : std::to_string(main.ntet), *o, -1, false));
      if (stop_requested()) return stopped();
      for (const Level& l : levels) {
        rows.push_back(measure(l.scene, l.label, *o, -1, false));
        if (stop_requested()) return stopped();
      }
      std::printf("\nsweep (%s, %s): bytes each step must move vs %s\n", o->backend.c_str(), precision_name(sc.precision),
                  copy_gbs > 0 ? "the measured copy bandwidth" : "(no device bandwidth on the CPU)");
      std::printf("  %-5s %9s %8s %11s %10s %10s %10s %9s %9s\n", "mesh", "tets", "nodes", "us/step", "steps/s", "MB/step",
                  "GB/s", "roofline", "RT factor");
      for (const Result& r : rows) {
        const double gbs = r.bytes / r.us.median * 1e-3;
        char roof[32] = "-";
        if (copy_gbs > 0) std::snprintf(roof, sizeof roof, "%.0f%%", 100 * gbs / copy_gbs);
        std::printf("  %-5s %9d %8d %11.3f %10.4g %10.3f %10.1f %9s %9.3g\n", r.label.c_str(), r.ntet, r.nnode, r.us.median,
                    1e6 / r.us.median, r.bytes * 1e-6, gbs, roof, r.dt * 1e6 / r.us.median);
      }
      for (const Result& r : rows)
        if (r.stages.valid)
          std::printf("  %-5s stages us/call: forces %.3f, update %.3f, contact %.3f, render write %.3f\n", r.label.c_str(),
                      r.stages.forces, r.stages.update, r.stages.contact, r.stages.render);
      for (const Result& r : rows)
        for (const auto& m : r.modes)
          std::printf("  %-5s mode %-34s median %10.3f us/step (min %.3f, max %.3f)\n", r.label.c_str(), m.first.c_str(),
                      m.second.median, m.second.min, m.second.max);
      flush_stdout();
    }
    if (!o->json.empty()) {
      std::ostringstream f;
      f << "{\"scene\": " << json_string(o->scene) << ", \"copy_GBps\": " << copy_gbs
        << ",\n \"result\": " << json_result(main, copy_gbs);
      if (!rows.empty()) {
        f << ",\n \"sweep\": [";
        for (std::size_t i = 0; i < rows.size(); ++i) f << (i ? ",\n  " : "\n  ") << json_result(rows[i], copy_gbs);
        f << "]";
      }
      f << "}\n";
      write_file_atomic(o->json, f.str());  // checked: ResourceError naming the file
    }
    return 0;
  };
}

}  // namespace softtled
