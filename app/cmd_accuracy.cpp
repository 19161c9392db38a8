// `softtled accuracy`: the speed-for-accuracy trade on the paper's torus drop. Runs a
// reference (finest level, double, small lambda) and a sweep over mesh level, precision,
// lambda = dt/dt_cr and element type; writes accuracy.csv and accuracy.md.
//
// Every argument is checked before the reference run (which takes hours on a CPU), and
// each variant prints a progress line with an estimate of the time left.
#include <CLI/CLI.hpp>
#include <chrono>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "analysis/accuracy_study.h"
#include "sim/io/output_file.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

namespace {
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> r;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) r.push_back(x);
  return r;
}

// A flag's comma-separated list: every item given, none twice (an empty item, or a
// repeated one that would run the same variant again and write its row twice, is an
// error); "" is no items.
std::vector<std::string> list_of(const std::string& flag, const std::string& list) {
  std::vector<std::string> r;
  if (list.empty()) return r;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = list.find(',', start);
    r.push_back(list.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (r.back().empty()) throw InputError(flag + " '" + list + "': item " + std::to_string(r.size()) + " is empty");
    for (std::size_t i = 0; i + 1 < r.size(); ++i)
      if (r[i] == r.back()) throw InputError(flag + " '" + list + "': '" + r.back() + "' is given twice");
    if (comma == std::string::npos) return r;
    start = comma + 1;
  }
}

// Relative cost of a variant: tets ~ NU NV, steps ~ sqrt(NU NV) / lambda (dt_cr ~ edge
// length); doubles cost about 1.5 floats. Scaled by the measured rate for the ETA.
double cost_units(const std::string& level, const std::string& prec, double lambda) {
  const AccuracyLevel l = parse_accuracy_level("level", level);
  return std::pow(double(l.nu) * l.nv, 1.5) / lambda * (prec == "double" ? 1.5 : 1.0);
}

std::string duration_text(double s) {
  char b[64];
  if (s < 90) std::snprintf(b, sizeof b, "%.0f s", s);
  else if (s < 5400) std::snprintf(b, sizeof b, "%.0f min", s / 60);
  else std::snprintf(b, sizeof b, "%.1f h", s / 3600);
  return b;
}


std::string default_out_dir() {
  const std::time_t now = std::time(nullptr);
  char b[64];
  std::strftime(b, sizeof b, "accuracy-%Y%m%d-%H%M%S", std::localtime(&now));
  std::string d = b;
  for (int k = 2; std::filesystem::exists(d); ++k) d = std::string(b) + "-" + std::to_string(k);
  return d;
}
}  // namespace

// commands.h: $SOFTTLED_ASSETS, ./assets, then the source tree this was built from.
std::string default_scene() {
  std::vector<std::string> roots;
  if (const char* a = std::getenv("SOFTTLED_ASSETS")) roots.push_back(a);
  roots.push_back("assets");
#ifdef SOFTTLED_SOURCE_DIR
  roots.push_back(std::string(SOFTTLED_SOURCE_DIR) + "/assets");
#endif
  for (const auto& r : roots) {
    const std::string p = r + "/scenes/torus_drop.toml";
    if (std::filesystem::exists(p)) return p;
  }
  throw InputError("no --scene given and assets/scenes/torus_drop.toml not found (set SOFTTLED_ASSETS)");
}

Command add_accuracy_command(CLI::App& app) {
  struct Opts {
    std::string scene, out, backend = "auto";
    std::string levels = "45x9,91x19,182x38", ref = "273x57", lambdas = "0.1,0.25,0.5,1.0", adaptive_lambdas;
    std::string precisions = "float,double", elements = "T4,T4ANP";
    double t_end = 0.2, ref_lambda = 0.25;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("accuracy", "speed-for-accuracy sweep against a converged reference");
  CLI::Option* scene_opt = c->add_option(
      "--scene", o->scene, "base scene (default: scenes/torus_drop.toml under $SOFTTLED_ASSETS, ./assets or the source tree)");
  CLI::Option* out_opt = c->add_option("--out", o->out, "output directory for accuracy.csv and accuracy.md (default: a new ./accuracy-DATE-TIME)");
  c->add_option("--backend", o->backend, "cpu, cuda or auto")->check(CLI::IsMember({"cpu", "cuda", "auto"}))->capture_default_str();
  c->add_option("--levels", o->levels, "torus grids to sweep, e.g. 45x9,91x19; NUxNV@qRHO sets TetGen's radius-edge bound")
      ->capture_default_str();
  c->add_option("--ref", o->ref, "reference grid (finest)")->capture_default_str();
  c->add_option("--ref-lambda", o->ref_lambda, "lambda of the reference")->check(finite_range(1e-3, 1))->capture_default_str();
  c->add_option("--lambdas", o->lambdas, "lambda = dt/dt_cr values, each in (0, 1]")->capture_default_str();
  c->add_option("--adaptive-lambdas", o->adaptive_lambdas,
                "also runs with time.dt = \"adaptive\" at these safety factors, each in (0, 1] (default: none)");
  c->add_option("--precisions", o->precisions, "float,double")->capture_default_str();
  c->add_option("--elements", o->elements, "T4,T4ANP")->capture_default_str();
  c->add_option("--t-end", o->t_end, "simulated time per run [s]")->check(finite_range(1e-3, 10))->capture_default_str();
  return [o, scene_opt, out_opt]() {
    // ---- every argument first: the reference run takes hours on a CPU ----
    if (scene_opt->count() && o->scene.empty()) throw InputError("--scene: empty path");
    if (out_opt->count() && o->out.empty()) throw InputError("--out: empty path");
    // The backend first: "cuda" on a build or machine without one is refused before the
    // scene is read, any level meshed or --out created.
    const std::string backend = resolve_backend(o->backend);
    if (o->scene.empty()) o->scene = default_scene();
    auto parse_lambdas = [](const std::string& flag, const std::string& list) {
      std::vector<double> out;
      for (const auto& ls : list_of(flag, list)) {
        double v = 0;
        std::size_t used = 0;
        try {
          v = std::stod(ls, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != ls.size() || !std::isfinite(v) || !(v >= 1e-3 && v <= 1))
          throw InputError(flag + " '" + list + "': '" + ls + "' is not a number in [0.001, 1]");
        if (std::find(out.begin(), out.end(), v) != out.end())
          throw InputError(flag + " '" + list + "': " + ls + " is the same value as an earlier item");
        out.push_back(v);
      }
      return out;
    };
    const std::vector<double> lambdas = parse_lambdas("--lambdas", o->lambdas);
    const std::vector<double> adaptive_lambdas = parse_lambdas("--adaptive-lambdas", o->adaptive_lambdas);
    // Levels in their canonical spelling (AccuracyLevel::name), so that "045x9" and "45x9"
    // are one level (given twice) and what runs is what was checked.
    std::vector<std::string> levels;
    for (const std::string& l : list_of("--levels", o->levels)) {
      levels.push_back(parse_accuracy_level("--levels", l).name());
      if (std::find(levels.begin(), levels.end() - 1, levels.back()) != levels.end() - 1)
        throw InputError("--levels '" + o->levels + "': '" + l + "' is the same level as an earlier item");
    }
    o->ref = parse_accuracy_level("--ref", o->ref).name();
    const std::vector<std::string> precs = list_of("--precisions", o->precisions), elements = list_of("--elements", o->elements);
    if (lambdas.empty() || levels.empty() || precs.empty() || elements.empty())
      throw InputError("--levels, --lambdas, --precisions and --elements each need at least one value");
    for (const auto& p : precs)
      if (p != "float" && p != "double") throw InputError("--precisions: '" + p + "' is not float or double");
    for (const auto& e : elements)
      if (e != "T4" && e != "T4ANP") throw InputError("--elements: '" + e + "' is not T4 or T4ANP");
    // The scene with each level's overrides (parse only: unknown keys, ranges, the mesh.* grammar).
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    const Scene base = load_scene(o->scene);
    auto check_scene = [&](const std::string& flag, const std::string& level) {
      // The levels are torus grids (body.segments): on any other body, or on a scene of
      // several, every level would be the same mesh and the sweep would measure nothing.
      // (Asked of the scene as it is: with the level's body.segments it would not load.)
      if (base.body_count() != 1 || base.shape != "torus")
        throw InputError(flag + " '" + level + "': the levels set body.segments, a torus's grid; " + o->scene + " has " +
                         (base.body_count() != 1 ? std::to_string(base.body_count()) + " bodies" : "body.shape = \"" + base.shape + "\"") +
                         " (the accuracy sweep takes one torus)");
      std::vector<std::string> set = parse_accuracy_level(flag, level).overrides();
      set.push_back("time.dt=\"auto\"");
      try {
        load_scene(o->scene, set);
      } catch (const InputError& e) {  // the level's value, not the scene file, is at fault
        throw InputError(flag + " '" + level + "': " + e.what());
      }
    };
    check_scene("--ref", o->ref);
    for (const auto& l : levels) check_scene("--levels", l);
    // The reference is the finest mesh: a level finer in either direction would be measured
    // against a coarser answer than itself.
    auto grid = [](const std::string& level) {
      const AccuracyLevel l = parse_accuracy_level("level", level);
      return std::make_pair(l.nu, l.nv);
    };
    for (const auto& l : levels)
      if (grid(l).first > grid(o->ref).first || grid(l).second > grid(o->ref).second)
        throw InputError("--ref '" + o->ref + "' is coarser than --levels '" + l +
                         "': the reference must be at least as fine as every level in both directions");
    if (o->out.empty()) o->out = default_out_dir();  // never the committed bench/accuracy
    check_output_dir(o->out, "--out");
    {
      std::error_code ec;  // e.g. under /sys or /proc, which check_output_dir cannot tell
      std::filesystem::create_directories(o->out, ec);
      if (ec) throw InputError("--out " + o->out + ": cannot create directory: " + ec.message());
    }
    const std::string csv_path = o->out + "/accuracy.csv", md_path = o->out + "/accuracy.md";
    check_output_file(csv_path, "--out");
    check_output_file(md_path, "--out");
    std::vector<PathUse> paths = scene_inputs(base, "--scene");
    paths.push_back({csv_path, "--out", true});
    paths.push_back({md_path, "--out", true});
    check_distinct_paths(paths);
    // Every run's step is the sweep's own (time.dt = "auto" at each --lambdas, "adaptive" at
    // each --adaptive-lambdas): a scene's fixed or adaptive step was replaced without a word.
    if (!base.dt_auto) {
      char dt[32];
      std::snprintf(dt, sizeof dt, "%.6g s", base.dt);
      std::fprintf(stderr, "note: %s: time.dt = %s is not used: accuracy sets the step itself (--lambdas, --adaptive-lambdas)\n",
                   o->scene.c_str(), base.dt_adaptive ? "\"adaptive\"" : dt);
    }
    // SIGINT/SIGTERM/SIGHUP: stop after the run in progress, keeping the rows written.
    install_stop_signals();

    const double t1 = std::min(0.05, o->t_end), t2 = std::min(0.1, o->t_end);
    const AccuracyTimes times{o->t_end, t1, t2};
    const std::string header =
        "level,ntet,precision,element,lambda,dt_us,steps,us_per_step,wall_s,centroid_rms_mm,max_err_mm_t1,mean_err_mm_t1,"
        "max_err_mm_t2,mean_err_mm_t2,rest_height_err_mm,dt_mode";
    // accuracy.csv and accuracy.md are each rewritten whole (atomically) with every row, so an
    // earlier result in --out stays intact until this run has a row to replace it with (the
    // CSV opened in place had been emptied at once, and a stop before the first row left an
    // empty CSV beside the old table).
    // A FIFO or device (a reader taking the rows as they come) is written in place, once:
    // reopened for each row, its reader saw the end after the first.
    struct stat cst;
    std::unique_ptr<OutputFile> csv_stream;
    if (::stat(csv_path.c_str(), &cst) == 0 && !S_ISREG(cst.st_mode)) {
      csv_stream = std::make_unique<OutputFile>(csv_path);
      csv_stream->write(header + "\n");
      csv_stream->flush();
    }
    std::vector<std::string> rows;
    auto csv_text = [&] {
      std::string text = header + "\n";
      for (const auto& r : rows) text += r + "\n";
      return text;
    };
    auto md_text = [&] {
      std::ostringstream md;
      md << "# Speed for accuracy\n\nScene `" << o->scene << "`, backend " << backend << ", t_end " << o->t_end
         << " s; reference " << o->ref << " (double, T4ANP, lambda " << o->ref_lambda
         << "). Errors in mm against the reference (README, \"Speed for accuracy\").\n\n|";
      for (const auto& h : split(header)) md << " " << h << " |";
      md << "\n|";
      for (std::size_t i = 0; i < split(header).size(); ++i) md << "---|";
      md << "\n";
      for (const auto& r : rows) {
        md << "|";
        for (const auto& f : split(r)) md << " " << f << " |";
        md << "\n";
      }
      return md.str();
    };
    // The two files hold the same rows: accuracy.md's temporary is complete before the CSV
    // takes the row (written first, a full disk under accuracy.md had left the CSV a row
    // ahead), and is renamed after it; only that rename failing leaves them apart, and the
    // message then says so.
    auto add_row = [&](const std::string& row) {
      rows.push_back(row);
      OutputFile md(md_path, OutputFile::kAtomic);
      md.write(md_text());
      md.finish();
      if (csv_stream) {
        csv_stream->write(row + "\n");
        csv_stream->flush();
      } else {
        write_file_atomic(csv_path, csv_text());
      }
      try {
        md.commit();
      } catch (const ResourceError& e) {
        throw ResourceError(std::string(e.what()) + " (" + csv_path + " has this row, " + md_path + " not)");
      }
      std::fputs((row + "\n").c_str(), stdout);
      flush_stdout();
    };
    auto emit = [&](const AccuracyRun& r, const AccuracyErrors& e) {
      char buf[512];
      std::snprintf(buf, sizeof buf, "%s,%d,%s,%s,%.3g,%.4g,%ld,%.4g,%.4g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%s", r.level.c_str(),
                    r.ntet, r.precision.c_str(), r.element.c_str(), r.lambda, r.dt * 1e6, r.steps, r.us_per_step, r.wall_s,
                    e.centroid_rms * 1e3, e.max_err[0] * 1e3, e.mean_err[0] * 1e3, e.max_err[1] * 1e3, e.mean_err[1] * 1e3,
                    e.rest * 1e3, r.adaptive ? "adaptive" : "auto");
      add_row(buf);
    };

    // ---- progress: cost units of every run, the rate measured on the runs so far ----
    using Job = AccuracyVariant;
    std::vector<Job> jobs = {{o->ref, "double", "T4ANP", o->ref_lambda}, {o->ref, "double", "T4", o->ref_lambda}};
    for (const auto& level : levels)
      for (const auto& el : elements)
        for (const auto& prec : precs)
          for (double l : lambdas) jobs.push_back({level, prec, el, l});
    for (const auto& level : levels)
      for (const auto& el : elements)
        for (const auto& prec : precs)
          for (double l : adaptive_lambdas) jobs.push_back({level, prec, el, l, true});
    double units_left = 0, units_done = 0, wall_done = 0;
    for (const auto& j : jobs) units_left += cost_units(j.level, j.precision, j.lambda);
    const auto start = std::chrono::steady_clock::now();
    std::size_t k = 0;
    auto begin_job = [&](const Job& j) {
      ++k;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::string eta = "ETA after the first run";
      if (units_done > 0) eta = "about " + duration_text(wall_done / units_done * units_left) + " left";
      std::fprintf(stderr, "[%zu/%zu] %s %s %s lambda %g, %g s simulated ... (%s elapsed, %s)\n", k, jobs.size(),
                   j.level.c_str(), j.precision.c_str(), j.element.c_str(), j.lambda, o->t_end, duration_text(elapsed).c_str(),
                   eta.c_str());
      return std::chrono::steady_clock::now();
    };
    auto end_job = [&](const Job& j, std::chrono::steady_clock::time_point t0) {
      const double u = cost_units(j.level, j.precision, j.lambda);
      units_done += u, units_left -= u;
      wall_done += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };

    auto stopped = [&]() {
      if (rows.empty())
        std::fprintf(stderr, "softtled: stopped by signal %d after 0 of %zu runs; wrote nothing (%s and %s as they were)\n",
                     stop_signal(), jobs.size(), csv_path.c_str(), md_path.c_str());
      else
        std::fprintf(stderr, "softtled: stopped by signal %d after %zu of %zu runs; wrote %zu rows to %s and %s\n",
                     stop_signal(), rows.size(), jobs.size(), rows.size(), csv_path.c_str(), md_path.c_str());
      return exit_code_for_signal(stop_signal());
    };
    if (stop_requested()) return stopped();
    auto t0 = begin_job(jobs[0]);
    const auto stop = [] { return stop_requested(); };  // answered between steps
    const AccuracyRun ref =
        run_accuracy_variant(o->scene, backend, jobs[0], times, {}, stop);
    if (ref.stopped) return stopped();
    end_job(jobs[0], t0);
    const FieldSampler sampler(*ref.mesh);
    emit(ref, compare_runs(ref, ref, sampler, t2));
    if (stop_requested()) return stopped();
    // The reference's own convergence: T4 on the same grid, and the next level down.
    t0 = begin_job(jobs[1]);
    const AccuracyRun ref_t4 =
        run_accuracy_variant(o->scene, backend, jobs[1], times, {}, stop);
    if (ref_t4.stopped) return stopped();
    end_job(jobs[1], t0);
    emit(ref_t4, compare_runs(ref_t4, ref, sampler, t2));
    for (std::size_t i = 2; i < jobs.size(); ++i) {
      if (stop_requested()) return stopped();
      const Job& j = jobs[i];
      t0 = begin_job(j);
      try {
        const AccuracyRun r = run_accuracy_variant(o->scene, backend, j, times, {}, stop);
        if (r.stopped) return stopped();
        emit(r, compare_runs(r, ref, sampler, t2));
      } catch (const SimulationDiverged& e) {
        std::fprintf(stderr, "%s %s %s lambda %g: %s\n", j.level.c_str(), j.precision.c_str(), j.element.c_str(), j.lambda, e.what());
        char lam[32];
        std::snprintf(lam, sizeof lam, "%.3g", j.lambda);
        add_row(j.level + ",," + j.precision + "," + j.element + "," + lam + ",diverged,,,,,,,,,," +
                (j.adaptive ? "adaptive" : "auto"));
      }
      end_job(j, t0);
    }
    if (stop_requested()) return stopped();
    if (csv_stream) csv_stream->close();
    std::fprintf(stderr, "wrote %s and %s\n", csv_path.c_str(), md_path.c_str());
    return 0;
  };
}

}  // namespace softtled
