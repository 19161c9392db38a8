// `softtled run`: headless simulation of a scene with CSV output.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "app/commands.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"
#include "sim/io/vtu_writer.h"

namespace softtled {

namespace {
// One row per output time (README, "Command line"). ke is computed from the integrator's
// half-step velocity du/dt, the mean velocity over the last step (t - dt, t), not the
// velocity at t: in free fall it lags by g dt / 2 (Diagnostics::ke).
void write_csv_header(std::ostream& o, int ntracked) {
  o << "t,cx,cy,cz,min_gap,ke,se,pe,n_contact,n_stick,max_u";
  for (int j = 0; j < ntracked; ++j) o << ",n" << j << "_ux,n" << j << "_uy,n" << j << "_uz";
  o << '\n';
}
void write_csv_row(std::ostream& o, const Diagnostics& d) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g", d.t, d.centroid[0], d.centroid[1],
                d.centroid[2], d.min_gap, d.ke, d.se, d.pe, d.n_contact, d.n_stick, d.max_u);
  o << buf;
  for (double v : d.tracked) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    o << buf;
  }
  o << '\n';
}
}  // namespace

Command add_run_command(CLI::App& app) {
  struct Opts {
    std::string scene, csv, vtu, backend = "auto";
    int every = 1;
    std::vector<std::string> set;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("run", "run a scene headless and print a summary");
  c->add_option("--scene", o->scene, "scene file (TOML)")->required();
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  c->add_option("--csv", o->csv, "write one row per output time");
  c->add_option("--backend", o->backend, "cpu, cuda or auto");
  c->add_option("--vtu", o->vtu, "write a ParaView series (DIR/frame_*.vtu + DIR/series.pvd)");
  c->add_option("--every", o->every, "with --vtu: one frame per N output times")->check(CLI::PositiveNumber);
  return [o]() {
    const Scene s = load_scene(o->scene, o->set);
    Simulation sim(s, o->backend);
    const TimeStepInfo& ts = sim.time_step();
    std::fprintf(stderr,
                 "mesh: %d nodes, %d tets, %zu surface nodes; c = %.3g m/s, Le_min = %.4g mm\n"
                 "dt_cr = %.4g us (Le/c = %.4g us, 2/omega_max = %.4g us), dt = %.4g us = %.2f dt_cr; backend %s, %s\n",
                 sim.mesh().nnode(), sim.mesh().ntet(), sim.mesh().surface_nodes.size(), ts.c, ts.min_Le * 1e3,
                 ts.dt_cr * 1e6, ts.dt_le * 1e6, ts.dt_eigen * 1e6, ts.dt * 1e6, ts.dt / ts.dt_cr,
                 sim.backend().c_str(), precision_name(s.precision));
    std::ofstream csv;
    if (!o->csv.empty()) {
      csv.open(o->csv);
      if (!csv) throw InputError(o->csv + ": cannot write");
      write_csv_header(csv, int(sim.tracked_nodes().size()));
    }
    std::unique_ptr<VtuSeries> vtu;
    int out_index = 0;
    auto write_frame = [&] {
      if (!vtu || out_index++ % o->every) return;
      vtu->add(sim.time(), sim.mesh(), sim.state(), sim.time_step().dt,
               neo_hookean_from_E_nu<double>(sim.params().E, sim.params().nu, sim.params().material_model));
    };
    if (!o->vtu.empty()) vtu = std::make_unique<VtuSeries>(o->vtu);
    write_frame();
    const bool tty = isatty(2);
    const double dt = ts.dt;
    // A changing step (time.dt = "adaptive") advances by output times, not step counts.
    const bool adaptive = sim.params().dt_adaptive;
    const long total = adaptive ? std::max(1L, std::lround(std::ceil(s.duration / s.output_every - 1e-9)))
                                : std::lround(s.duration / dt);
    const long every = adaptive ? 1 : std::max(1L, std::lround(s.output_every / dt));
    const auto t0 = std::chrono::steady_clock::now();
    Diagnostics d = sim.diagnostics();
    if (csv) write_csv_row(csv, d);
    double min_gap = d.min_gap, max_ke = d.ke;
    int max_contact = 0;
    for (long done = 0; done < total;) {
      const long n = std::min(every, total - done);
      try {
        if (adaptive)
          sim.advance_to(std::min(s.duration, double(done + n) * s.output_every));
        else
          sim.advance(n, n);
      } catch (const SimulationDiverged& e) {
        if (tty) std::fprintf(stderr, "\n");
        std::fprintf(stderr, "softtled: %s\n", e.what());
        if (csv) write_csv_row(csv, sim.diagnostics());  // the rolled-back, last healthy state
        return 4;
      }
      done += n;
      d = sim.diagnostics();
      write_frame();
      if (csv) write_csv_row(csv, d);
      min_gap = std::min(min_gap, d.min_gap);
      max_ke = std::max(max_ke, d.ke);
      max_contact = std::max(max_contact, d.n_contact);
      if (tty) std::fprintf(stderr, "\r t = %.4f s  (%3.0f%%)", d.t, 100.0 * done / total);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (tty) std::fprintf(stderr, "\n");
    const long steps = sim.total_steps();
    if (adaptive)
      std::printf("simulated %.4g s in %ld steps of %.4g us mean (%.4g-%.4g us): %.3g s wall, %.1f us/step, "
                  "real-time factor %.3g; %ld omega_max estimates, %.1f %% of the wall time\n",
                  d.t, steps, d.t / std::max(1L, steps) * 1e6, sim.dt_min_used() * 1e6, sim.dt_max_used() * 1e6, wall,
                  wall / std::max(1L, steps) * 1e6, d.t / wall, sim.estimates(), 100 * sim.estimate_seconds() / wall);
    else
      std::printf("simulated %.4g s in %ld steps of %.4g us: %.3g s wall, %.1f us/step, real-time factor %.3g\n", d.t,
                  total, dt * 1e6, wall, wall / std::max(1L, total) * 1e6, d.t / wall);
    std::printf("final centroid (%.3f, %.3f, %.3f) mm, min gap over run %.4f mm, max contacts %d, max KE %.3g J, final KE %.3g J\n",
                d.centroid[0] * 1e3, d.centroid[1] * 1e3, d.centroid[2] * 1e3, min_gap * 1e3, max_contact, max_ke, d.ke);
    return 0;
  };
}

}  // namespace softtled
