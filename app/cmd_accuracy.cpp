// `softtled accuracy`: the speed-for-accuracy trade on the paper's torus drop. Runs a
// reference (finest level, double, small lambda) and a sweep over mesh level, precision,
// lambda = dt/dt_cr and element type; writes accuracy.csv and accuracy.md.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "analysis/accuracy_study.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

Command add_accuracy_command(CLI::App& app) {
  struct Opts {
    std::string scene = "assets/scenes/torus_drop.toml", out = "bench/accuracy", backend = "auto";
    std::string levels = "45x9,91x19,182x38", ref = "273x57", lambdas = "0.1,0.25,0.5,1.0";
    std::string precisions = "float,double", elements = "T4,T4ANP";
    double t_end = 0.2, ref_lambda = 0.25;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("accuracy", "speed-for-accuracy sweep against a converged reference");
  c->add_option("--scene", o->scene, "base scene (the torus drop)");
  c->add_option("--out", o->out, "output directory for accuracy.csv and accuracy.md");
  c->add_option("--backend", o->backend, "cpu, cuda or auto");
  c->add_option("--levels", o->levels, "torus grids to sweep, e.g. 45x9,91x19; NUxNV@qRHO sets TetGen's radius-edge bound");
  c->add_option("--ref", o->ref, "reference grid (finest)");
  c->add_option("--ref-lambda", o->ref_lambda, "lambda of the reference");
  c->add_option("--lambdas", o->lambdas, "lambda = dt/dt_cr values");
  c->add_option("--precisions", o->precisions, "float,double");
  c->add_option("--elements", o->elements, "T4,T4ANP");
  c->add_option("--t-end", o->t_end, "simulated time per run [s]");
  return [o]() {
    const double t1 = std::min(0.05, o->t_end), t2 = std::min(0.1, o->t_end);
    std::fprintf(stderr, "reference: %s, double, T4ANP and T4, lambda %.2f, %.2f s ...\n", o->ref.c_str(), o->ref_lambda, o->t_end);
    const AccuracyRun ref = run_accuracy_variant(o->scene, o->backend, o->ref, "double", o->ref_lambda, "T4ANP", o->t_end, t1, t2);
    const FieldSampler sampler(*ref.mesh);
    std::filesystem::create_directories(o->out);
    std::ofstream csv(o->out + "/accuracy.csv");
    csv << "level,ntet,precision,element,lambda,dt_us,steps,us_per_step,wall_s,centroid_rms_mm,max_err_mm_t1,mean_err_mm_t1,"
           "max_err_mm_t2,mean_err_mm_t2,rest_height_err_mm\n";
    auto emit = [&](const AccuracyRun& r, const AccuracyErrors& e) {
      char buf[512];
      std::snprintf(buf, sizeof buf, "%s,%d,%s,%s,%.3g,%.4g,%ld,%.4g,%.4g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g\n", r.level.c_str(),
                    r.ntet, r.precision.c_str(), r.element.c_str(), r.lambda, r.dt * 1e6, r.steps, r.us_per_step, r.wall_s,
                    e.centroid_rms * 1e3, e.max_err[0] * 1e3, e.mean_err[0] * 1e3, e.max_err[1] * 1e3, e.mean_err[1] * 1e3,
                    e.rest * 1e3);
      csv << buf;
      csv.flush();
      std::fputs(buf, stdout);
    };
    emit(ref, compare_runs(ref, ref, sampler, t2));
    // The reference's own convergence: T4 on the same grid, and the next level down.
    const AccuracyRun ref_t4 = run_accuracy_variant(o->scene, o->backend, o->ref, "double", o->ref_lambda, "T4", o->t_end, t1, t2);
    emit(ref_t4, compare_runs(ref_t4, ref, sampler, t2));
    auto split = [](const std::string& s) {
      std::vector<std::string> r;
      std::stringstream ss(s);
      std::string x;
      while (std::getline(ss, x, ',')) r.push_back(x);
      return r;
    };
    for (const auto& level : split(o->levels))
      for (const auto& el : split(o->elements))
        for (const auto& prec : split(o->precisions))
          for (const auto& ls : split(o->lambdas)) {
            try {
              const AccuracyRun r = run_accuracy_variant(o->scene, o->backend, level, prec, std::stod(ls), el, o->t_end, t1, t2);
              emit(r, compare_runs(r, ref, sampler, t2));
            } catch (const SimulationDiverged& e) {
              std::fprintf(stdout, "%s,,%s,%s,%s,diverged,,,,,,,,,\n", level.c_str(), prec.c_str(), el.c_str(), ls.c_str());
              std::fprintf(stderr, "%s %s %s lambda %s: %s\n", level.c_str(), prec.c_str(), el.c_str(), ls.c_str(), e.what());
              csv << level << ",," << prec << "," << el << "," << ls << ",diverged,,,,,,,,,\n";
            }
          }
    std::fprintf(stderr, "wrote %s/accuracy.csv\n", o->out.c_str());
    return 0;
  };
}

}  // namespace softtled
