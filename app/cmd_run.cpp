// `softtled run`: headless simulation of a scene with CSV output.
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "sim/core/input_error.h"
#include "sim/io/output_file.h"
#include "sim/io/vtu_writer.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

namespace {

// One row per output time (README, "Command line"). ke is computed from the integrator's
// half-step velocity du/dt, the mean velocity over the last step (t - dt, t), not the
// velocity at t: in free fall it lags by g dt / 2 (Diagnostics::ke).
std::string csv_header(int ntracked, int nbody) {
  std::string h = "t,cx,cy,cz,min_gap,ke,se,pe,n_contact,n_stick,max_u";
  for (int b = 0; b < nbody && nbody >= 2; ++b)
    h += ",b" + std::to_string(b) + "_cx,b" + std::to_string(b) + "_cy,b" + std::to_string(b) + "_cz";
  for (int j = 0; j < ntracked; ++j)
    h += ",n" + std::to_string(j) + "_ux,n" + std::to_string(j) + "_uy,n" + std::to_string(j) + "_uz";
  return h + '\n';
}
// t with time_decimals(dt) decimals: consecutive rows stay distinct at any dt.
std::string csv_row(const Diagnostics& d, int t_decimals) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%.*f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g", t_decimals, d.t, d.centroid[0],
                d.centroid[1], d.centroid[2], d.min_gap, d.ke, d.se, d.pe, d.n_contact, d.n_stick, d.max_u);
  std::string row = buf;
  for (double v : d.body_centroid) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    row += buf;
  }
  for (double v : d.tracked) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    row += buf;
  }
  return row + '\n';
}

// Steps per advance() call at most: the watchdog checks at least this often even when
// time.output_every spans millions of steps (a signal is answered between steps, by the
// stop check, within Simulation::kStopCheckSteps).
constexpr long kMaxChunkSteps = 20000;
// At most this many CSV rows / VTU frames (time.duration / time.output_every).
constexpr double kMaxOutputRows = 1e8;
}  // namespace

Command add_run_command(CLI::App& app) {
  struct Opts {
    std::string scene, csv, vtu, backend = "auto";
    long every = 1;
    bool sync_checks = false;
    std::vector<std::string> set;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("run", "run a scene headless and print a summary");
  CLI::Option* scene_opt = c->add_option("--scene", o->scene, "scene file (TOML)")->required();
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  CLI::Option* csv_opt = c->add_option("--csv", o->csv, "write one row per output time to this file ('-': standard output; the summary then goes to stderr)");
  c->add_option("--backend", o->backend, "cpu, cuda or auto")->check(CLI::IsMember({"cpu", "cuda", "auto"}))->capture_default_str();
  CLI::Option* vtu_opt = c->add_option("--vtu", o->vtu, "write a ParaView series (DIR/frame_*.vtu + DIR/series.pvd)");
  c->add_option("--every", o->every, "with --vtu: one frame per N output times")->check(int_range(1, 1000000000))->capture_default_str();
  c->add_flag("--sync-checks", o->sync_checks,
              "on a GPU, step each output interval only after the last one is checked and written (the same "
              "numbers, slower; by default the device steps the next interval meanwhile)");
  return [o, c, scene_opt, csv_opt, vtu_opt]() {
    // Every output path is checked before anything is read, meshed or truncated; an empty
    // one given is an error, not "no output".
    if (scene_opt->count() && o->scene.empty()) throw InputError("--scene: empty path");
    if (csv_opt->count() && o->csv.empty()) throw InputError("--csv: empty path");
    if (vtu_opt->count() && o->vtu.empty()) throw InputError("--vtu: empty path");
    if (o->vtu.empty() && c->count("--every")) throw InputError("--every thins --vtu frames: give --vtu DIR too");
    if (!o->csv.empty()) check_output_file(o->csv, "--csv", true, true);
    if (!o->vtu.empty()) check_series_dir(o->vtu, "--vtu");
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    const Scene s = load_scene(o->scene, o->set);
    {  // no output onto an input or another output
      std::vector<PathUse> paths = scene_inputs(s, "--scene");
      if (!o->csv.empty()) paths.push_back({o->csv, "--csv", true, false, true});
      if (!o->vtu.empty()) paths.push_back({o->vtu, "--vtu", true, true});
      check_distinct_paths(paths);
    }
    install_stop_signals();
    const std::unique_ptr<Simulation> sim_owner = make_simulation(s, o->backend);
    if (stop_requested()) {  // during meshing: the outputs of an earlier run stay as they are
      std::fprintf(stderr, "softtled: stopped by signal %d before the run started; wrote nothing\n", stop_signal());
      return exit_code_for_signal(stop_signal());
    }
    Simulation& sim = *sim_owner;
    const TimeStepInfo& ts = sim.time_step();
    const double dt = ts.dt;
    const long total = checked_step_count(s.duration, dt, s.source + ": time.duration");
    if (s.duration / std::max(s.output_every, dt) > kMaxOutputRows)
      throw InputError(s.source + ": time.output_every: " + std::to_string(s.duration / std::max(s.output_every, dt)) +
                       " output rows for time.duration " + std::to_string(s.duration) + " s, above the limit of 1e8");
    // A VTU series is a frame per output time (or per --every): a probe's 1e-300 s output
    // interval over 5000 s wrote 355 MB in 12 s towards ~4.6 TB with no word of it. Warned
    // from 10 GB, by a lower bound of a frame's size (100 B per node, 25 per tet: frames on
    // disk measured 184 B per node with their tets, and more for tiny meshes).
    if (!o->vtu.empty()) {
      const double frames = s.duration / std::max(s.output_every, dt) / double(o->every) + 1;
      const double bytes = frames * (100.0 * sim.mesh().nnode() + 25.0 * sim.mesh().ntet());
      if (bytes > 1e10)
        std::fprintf(stderr,
                     "warning: --vtu %s: %.3g frames of at least %.3g MB, %.3g GB or more in all; raise time.output_every or "
                     "give --every N\n",
                     o->vtu.c_str(), frames, bytes / frames / 1e6, bytes / 1e9);
    }
    char damping_bound[64] = "";  // named where it is the bound that holds (Simulation::set_params)
    if (ts.dt_cr == ts.dt_alpha) std::snprintf(damping_bound, sizeof damping_bound, ", 2/alpha = %.4g us", ts.dt_alpha * 1e6);
    // The adaptive step's dt_cr is the live estimate (the element's own operator, T4ANP's
    // averaged pressure included), not one of the rest bounds beside it (of the T4
    // stiffness): named so, or a T4ANP run read "dt_cr = 182.7 us (Le/c = 22.49 us,
    // 2/omega_max = 83.17 us)".
    const char* bound_names = s.dt_adaptive ? "live 2/omega_max; at rest, T4: Le/c = %.4g us, 2/omega_max = %.4g us%s"
                                            : "Le/c = %.4g us, 2/omega_max = %.4g us%s";
    char bounds[200];
    std::snprintf(bounds, sizeof bounds, bound_names, ts.dt_le * 1e6, ts.dt_eigen * 1e6, damping_bound);
    std::fprintf(stderr,
                 "mesh: %d nodes, %d tets, %zu surface nodes; c = %.3g m/s, Le_min = %.4g mm\n"
                 "dt_cr = %.4g us (%s), dt = %.4g us = %.2f dt_cr; backend %s, %s\n",
                 sim.mesh().nnode(), sim.mesh().ntet(), sim.mesh().surface_nodes.size(), ts.c, ts.min_Le * 1e3,
                 ts.dt_cr * 1e6, bounds,
                 ts.dt * 1e6, ts.dt / ts.dt_cr,
                 sim.backend().c_str(), precision_name(s.precision));
    const int t_dec = time_decimals(dt);
    std::unique_ptr<OutputFile> csv;
    long rows = 0;
    std::string last_row_t;  // the time column of the last row written
    auto write_row = [&](const Diagnostics& d) {
      if (!csv) return;
      const std::string row = csv_row(d, t_dec);
      csv->write(row);
      csv->flush();  // a stop or a full disk leaves only whole rows, and is seen at once
      last_row_t = row.substr(0, row.find(','));
      ++rows;
    };
    std::unique_ptr<VtuSeries> vtu;
    long out_index = 0;
    // dt: the step st.du spans (its velocity is du / dt). A pipelined adaptive run's live
    // step has moved on by the time a checkpoint is written: its frames' velocities were
    // off by 9-30 % while the CSV's ke was right.
    auto write_frame = [&](double t, const HostState& st, double dt_of_state) {
      if (!vtu || out_index++ % o->every) return;
      vtu->add(t, sim.mesh(), st, dt_of_state, sim.materials());
    };
    if (!o->vtu.empty()) vtu = std::make_unique<VtuSeries>(o->vtu);
    // Whichever output can fail first without destroying the other goes first. A regular
    // CSV is emptied when opened, so the first frame comes before it (a frame that cannot be
    // written leaves an earlier CSV as it was); a FIFO, a device or stdout destroys nothing
    // when opened but can fail or wait there (a FIFO's reader), so it comes before the frame,
    // which replaces an earlier series.
    struct stat cs;
    const bool csv_first = !o->csv.empty() && (o->csv == "-" || (::stat(o->csv.c_str(), &cs) == 0 && !S_ISREG(cs.st_mode)));
    auto open_csv = [&] {
      if (o->csv.empty()) return;
      csv = std::make_unique<OutputFile>(o->csv);
      csv->write(csv_header(int(sim.tracked_nodes().size()), sim.mesh().nbody()));
      csv->flush();  // whatever fails next (the first frame), the output holds its header
    };
    if (csv_first) open_csv();
    write_frame(sim.time(), sim.state(), sim.params().dt);
    if (!csv_first) open_csv();
    FILE* summary = csv && csv->is_stdout() ? stderr : stdout;
    auto written = [&]() {
      std::string w;
      if (csv) w += std::to_string(rows) + " CSV rows to " + (csv->is_stdout() ? std::string("stdout") : o->csv);
      if (vtu) w += std::string(w.empty() ? "" : ", ") + std::to_string(vtu->size()) + " frames to " + o->vtu + "/series.pvd";
      return w.empty() ? std::string("no output files") : w;
    };
    const bool tty = isatty(2);
    // A changing step (time.dt = "adaptive") advances by output times, not step counts.
    // Either way an output time is never closer than one step to the one before (the row
    // bound above counts so): an adaptive run asked for rows every 1e-11 s spun through
    // empty intervals for ever. out_dt is the output interval in seconds.
    const bool adaptive = sim.params().dt_adaptive;
    const double out_dt = std::max(s.output_every, dt);
    const long intervals = adaptive ? std::max(1L, std::lround(std::ceil(s.duration / out_dt - 1e-9))) : total;
    // Where output time k (1, 2, ...) ends, in the loops' units (steps, or output times
    // with the adaptive step). A fixed step puts time k on the step nearest k out_dt, so
    // rows stay on the output grid (a rounded step count per row drifted: 5.12 us steps,
    // rows every 0.01 s came at 0.0099996, 0.0199991, ..., 0.0599974 and 0.0600025).
    auto interval_end = [&](long k) {
      if (adaptive) return std::min(k, intervals);
      return std::min(total, std::max(k, std::lround(std::min(double(k) * out_dt / dt, double(total)))));
    };
    const auto t0 = std::chrono::steady_clock::now();
    auto wall_s = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    Diagnostics d = sim.diagnostics();
    write_row(d);
    double min_gap = d.min_gap, max_ke = d.ke;
    int max_contact = 0;
    // The long-run warning (checked at every output time, after every chunk of steps and,
    // with the adaptive step, at every stop check, so a long first interval is no exception).
    LongRunWarning long_run("run", s.duration);
    auto check_progress = [&](double t_now) { long_run.check(t_now); };
    // Simulation's stop check between steps (about every kStopCheckSteps).
    sim.set_stop_check([&] {
      check_progress(sim.time());
      return stop_requested();
    });
    // One output time: its frame, row and summary figures, from the state checked there.
    // The adaptive step stops within half a step of an output time, so a duration less
    // than half a step past the last output time takes no step: that state has its row.
    double last_out_t = sim.time();
    // A node deeper than half the mean element edge inside a plane, an obstacle or another
    // body is one contact did not hold: a body squeezed between obstacles that close in ran
    // 4 mm into one of them with exit 0 and nothing said (a probe's find). Said once.
    const double deep = 0.5 * element_edge_lengths(sim.mesh()).mean;
    bool said_deep = false;
    auto output = [&](long done, const Diagnostics& dd, const HostState& st, double dt_of_state) {
      if (!(dd.t > last_out_t)) return;
      last_out_t = dd.t;
      d = dd;
      write_frame(d.t, st, dt_of_state);
      write_row(d);
      if (!said_deep && d.min_gap < -deep) {
        said_deep = true;
        std::fprintf(stderr,
                     "%swarning: at t = %.6g s a node is %.4g mm inside a plane, an obstacle or another body (min_gap), "
                     "more than half the mean element edge (%.4g mm): contact did not hold it (a body squeezed between "
                     "obstacles or planes that close in, or pushed in by another body); the motion from here is not "
                     "physical\n",
                     tty ? "\n" : "", d.t, -d.min_gap * 1e3, deep * 1e3);
      }
      min_gap = std::min(min_gap, d.min_gap);
      max_ke = std::max(max_ke, d.ke);
      max_contact = std::max(max_contact, d.n_contact);
      if (done < intervals) check_progress(d.t);
      if (tty) std::fprintf(stderr, "\r t = %.4f s  (%3.0f%%)", d.t, 100.0 * double(done) / double(intervals));
    };
    // The device steps output interval k + 1 while the host checks and writes interval k
    // (Simulation::queue / collect; on the CPU the same calls in the same order, nothing
    // overlapping): the same states, checks and rows as the loop below. A trip the
    // adaptive step survives rolls back to the last row written: queued again from there.
    // (an output interval is at most ceil(out_dt / dt) steps: interval_end rounds each end)
    const bool pipelined =
        !o->sync_checks && intervals > 0 && std::ceil(out_dt / dt) <= double(kMaxChunkSteps) && sim.pipelines();
    try {
      if (pipelined) {
        long queued = 0, done = 0;  // steps (adaptive: output times) queued, and written
        long queued_k = 0, done_k = 0;  // output times queued, and written
        std::deque<long> sizes;     // steps (adaptive: intervals) of each queued call, oldest first
        auto queue_next = [&] {
          const long end = interval_end(++queued_k);
          sizes.push_back(end - queued);
          queued = end;
          if (adaptive)
            sim.queue_until(std::min(s.duration, double(queued) * out_dt));
          else
            sim.queue(sizes.back());
        };
        queue_next();
        while (!sizes.empty()) {
          if (queued < intervals && !stop_requested()) queue_next();
          const Simulation::Checkpoint& c = sim.collect();
          if (c.stopped) break;  // the stop check cut its steps short: not an output time
          if (c.rolled_back) {
            sizes.clear();
            queued = done, queued_k = done_k;
            if (!stop_requested()) queue_next();
            continue;
          }
          done += sizes.front();
          ++done_k;
          sizes.pop_front();
          output(done, c.diag, c.state, c.dt);
        }
      }
      for (long done = 0, done_k = 0; !pipelined && done < intervals && !stop_requested();) {
        const long n = interval_end(++done_k) - done;
        long k = 0;
        // The output interval in chunks; the watchdog checks at the end of each.
        if (adaptive) {
          sim.advance_to(std::min(s.duration, double(done + n) * out_dt));
          if (sim.stopped_early()) break;  // stopped between steps: no row off the output times
          k = n;
        }
        while (k < n && !stop_requested()) {
          const long m = std::min(kMaxChunkSteps, n - k);
          sim.advance(m, m);
          if (sim.stopped_early()) break;  // between steps: no row off the output times
          k += m;
          check_progress(sim.time());
        }
        done += k;
        if (k < n) break;  // stopped inside an output interval: rows and frames stay on output times
        output(done, sim.diagnostics(), sim.state(), sim.params().dt);
      }
    } catch (const SimulationDiverged& e) {
      if (tty) std::fprintf(stderr, "\n");
      std::fprintf(stderr, "softtled: %s\n", e.what());
      // The rolled-back, last healthy state, unless that is the last row already written.
      const Diagnostics back = sim.diagnostics();
      if (csv && csv_row(back, t_dec).substr(0, last_row_t.size() + 1) != last_row_t + ",") write_row(back);
      if (csv) csv->close();
      return int(kExitDiverged);
    }
    if (tty) std::fprintf(stderr, "\n");
    if (csv) csv->close();
    if (stop_requested()) {
      std::fprintf(stderr, "softtled: stopped by signal %d at t = %.*f s of %g s; wrote %s\n", stop_signal(), t_dec,
                   sim.time(), s.duration, written().c_str());
      return exit_code_for_signal(stop_signal());
    }
    const double wall = wall_s();
    const long steps = sim.total_steps();
    if (adaptive)
      std::fprintf(summary,
                   "simulated %.4g s in %ld steps of %.4g us mean (%.4g-%.4g us): %.3g s wall, %.1f us/step, "
                   "real-time factor %.3g; %ld omega_max estimates, %.1f %% of the wall time\n",
                   d.t, steps, d.t / double(std::max(1L, steps)) * 1e6, sim.dt_min_used() * 1e6, sim.dt_max_used() * 1e6,
                   wall, wall / double(std::max(1L, steps)) * 1e6, d.t / wall, sim.estimates(),
                   100 * sim.estimate_seconds() / wall);
    else
      std::fprintf(summary, "simulated %.4g s in %ld steps of %.4g us: %.3g s wall, %.1f us/step, real-time factor %.3g\n",
                   d.t, total, dt * 1e6, wall, wall / double(std::max(1L, total)) * 1e6, d.t / wall);
    std::fprintf(summary,
                 "final centroid (%.6g, %.6g, %.6g) mm, min gap over run %.6g mm, max contacts %d, max KE %.3g J, final KE %.3g J\n",
                 d.centroid[0] * 1e3, d.centroid[1] * 1e3, d.centroid[2] * 1e3, min_gap * 1e3, max_contact, max_ke, d.ke);
    if (csv || vtu) std::fprintf(summary, "wrote %s\n", written().c_str());
    return 0;
  };
}

}  // namespace softtled
