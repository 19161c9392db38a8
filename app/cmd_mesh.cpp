// `softtled mesh`: tetrahedralize a scene's bodies or a surface file and report the paper's
// Table I counts plus element quality and the critical time step (sim/io/mesh_report.h):
// for one body as a list, for several one row per body and the total.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_geometry.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tet_io.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/io/mesh_report.h"
#include "sim/io/output_file.h"
#include "sim/io/vtu_writer.h"

namespace softtled {

namespace {

// A report's keys, the same for the whole mesh and for each body.
void print_json_fields(const MeshReport& r) {
  std::printf("\"input_points\": %d, \"input_facets\": %d, \"input_segments\": %ld, \"mesh_points\": %d, "
              "\"tetrahedra\": %d, \"faces\": %ld, \"edges\": %ld, \"boundary_faces\": %ld, \"boundary_edges\": %ld, "
              "\"min_Le_m\": %.6g, \"median_Le_m\": %.6g, \"min_dihedral_deg\": %.4g, \"wave_speed_m_s\": %.6g, "
              "\"dt_le_s\": %.6g, \"dt_eigen_s\": %.6g, \"dt_cr_s\": %.6g",
              r.input_points, r.input_facets, r.input_segments, r.nodes, r.tets, r.counts.faces, r.counts.edges,
              r.counts.boundary_faces, r.counts.boundary_edges, r.quality.min_Le, r.quality.median_Le,
              r.quality.min_dihedral_deg, r.wave_speed, r.dt_le, r.dt_eigen, r.dt_cr);
}

// One body: a list in the order of the paper's Table I.
void print_list(const MeshReport& r, const Scene& s) {
  std::printf("%-18s %10d\n%-18s %10d\n%-18s %10ld\n", "Input points", r.input_points, "Input facets", r.input_facets,
              "Input segments", r.input_segments);
  std::printf("%-18s %10d\n%-18s %10d\n%-18s %10ld\n%-18s %10ld\n%-18s %10ld\n%-18s %10ld\n", "Mesh points", r.nodes,
              "Mesh tetrahedra", r.tets, "Mesh faces", r.counts.faces, "Mesh edges", r.counts.edges, "Boundary faces",
              r.counts.boundary_faces, "Boundary edges", r.counts.boundary_edges);
  std::printf("%-18s %10.4g mm (element %d)\n%-18s %10.4g mm\n%-18s %10.3g deg\n", "Min Le", r.quality.min_Le * 1e3,
              r.quality.worst_element, "Median Le", r.quality.median_Le * 1e3, "Min dihedral", r.quality.min_dihedral_deg);
  std::printf("%-18s %10.4g m/s (E = %g Pa, nu = %g, rho = %g kg/m^3)\n%-18s %10.4g us\n%-18s %10.4g us\n%-18s %10.4g us\n",
              "Wave speed c", r.wave_speed, s.E, s.nu, s.rho, "Le/c (eq. 9)", r.dt_le * 1e6, "2/omega_max",
              r.dt_eigen * 1e6, "dt_cr (smaller)", r.dt_cr * 1e6);
}

// Several bodies: one row per body (its own E and rho), then the total.
void print_rows(const std::vector<MeshReport>& rows, const Scene& s) {
  std::printf("%-9s %8s %8s %8s %8s %8s %8s %8s %8s %9s %9s %8s %9s %8s %8s %8s %8s %8s\n", "", "input", "input",
              "mesh", "tets", "faces", "edges", "bound.", "bound.", "min Le", "median Le", "min dih.", "E", "rho", "c",
              "Le/c", "2/omega", "dt_cr");
  std::printf("%-9s %8s %8s %8s %8s %8s %8s %8s %8s %9s %9s %8s %9s %8s %8s %8s %8s %8s\n", "", "points", "facets",
              "points", "", "", "", "faces", "edges", "mm", "mm", "deg", "Pa", "kg/m^3", "m/s", "us", "us", "us");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const MeshReport& r = rows[i];
    const bool total = i + 1 == rows.size();
    char E[32] = "", rho[32] = "";
    if (!total) {
      std::snprintf(E, sizeof E, "%g", s.body_E(int(i)));
      std::snprintf(rho, sizeof rho, "%g", s.body_rho(int(i)));
    }
    std::printf("%-9s %8d %8d %8d %8d %8ld %8ld %8ld %8ld %9.4g %9.4g %8.3g %9s %8s %8.4g %8.4g %8.4g %8.4g\n",
                total ? "total" : ("body[" + std::to_string(i) + "]").c_str(), r.input_points, r.input_facets, r.nodes,
                r.tets, r.counts.faces, r.counts.edges, r.counts.boundary_faces, r.counts.boundary_edges,
                r.quality.min_Le * 1e3, r.quality.median_Le * 1e3, r.quality.min_dihedral_deg, E, rho, r.wave_speed,
                r.dt_le * 1e6, r.dt_eigen * 1e6, r.dt_cr * 1e6);
  }
}

}  // namespace

Command add_mesh_command(CLI::App& app) {
  struct Opts {
    std::string scene, surface, write, vtu;
    std::vector<std::string> set;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("mesh", "tetrahedralize and print mesh statistics (paper's Table I)");
  CLI::Option* scene_opt = c->add_option("--scene", o->scene, "scene file (TOML)");
  CLI::Option* surface_opt = c->add_option("--surface", o->surface, "surface file (.obj/.off/.stl, lengths in the scene's units)");
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  c->add_flag("--json", o->json, "print JSON instead of a table");
  CLI::Option* write_opt = c->add_option("--write", o->write, "write BASE.node and BASE.ele");
  CLI::Option* vtu_opt = c->add_option("--vtu", o->vtu, "write the tet mesh as a ParaView .vtu file (several bodies: a 'body' cell array)");
  return [o, scene_opt, surface_opt, write_opt, vtu_opt]() {
    // An empty value given is an error, not "no scene" (the default torus) or "no output".
    for (const auto& [opt, v] : {std::pair<CLI::Option*, const std::string*>{scene_opt, &o->scene}, {surface_opt, &o->surface},
                                 {write_opt, &o->write}, {vtu_opt, &o->vtu}})
      if (opt->count() && v->empty()) throw InputError(opt->get_name() + ": empty path");
    // Output paths first: a bad one must fail before minutes of meshing.
    if (!o->write.empty()) {
      const std::string name = std::filesystem::path(o->write).filename().string();
      if (name.empty() || name == "." || name == "..")
        throw InputError("--write " + o->write + ": give a base name (BASE.node, BASE.ele), not a directory");
      check_output_file(o->write + ".node", "--write");
      check_output_file(o->write + ".ele", "--write");
    }
    if (!o->vtu.empty()) check_output_file(o->vtu, "--vtu");
    // The surface replaces the scene's bodies: one file body, read as such (body.scale
    // applies to it; body.shape or a torus key given with it is refused, not ignored).
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    check_streams_not_into(o->surface, "--surface");
    Scene s = o->scene.empty() ? parse_scene("", o->surface.empty() ? "(defaults)" : "--surface " + o->surface, o->set, o->surface)
                               : load_scene(o->scene, o->set, o->surface);
    if (!o->surface.empty()) s.source = "--surface";  // no directory: the path is used as given
    {  // no output onto an input or another output
      std::vector<PathUse> paths =
          o->surface.empty() ? scene_inputs(s, "--scene") : std::vector<PathUse>{{o->surface, "--surface"}};
      if (!o->surface.empty() && !o->scene.empty()) paths.push_back({o->scene, "--scene"});
      if (!o->write.empty()) {
        paths.push_back({o->write + ".node", "--write", true});
        paths.push_back({o->write + ".ele", "--write", true});
      }
      if (!o->vtu.empty()) paths.push_back({o->vtu, "--vtu", true});
      check_distinct_paths(paths);
    }
    // SIGINT/SIGTERM/SIGHUP as in run: TetGen's child is killed at once (the InputError it
    // then throws is reported as the stop), the files are written whole or not at all, and
    // a line says which were (killed by the signal, a partial m.vtu.tmp was left, no word).
    install_stop_signals();
    std::vector<std::string> wrote;
    auto stopped = [&] {
      std::string w;
      for (std::size_t i = 0; i < wrote.size(); ++i)
        w += (i == 0 ? "" : i + 1 < wrote.size() ? ", " : " and ") + wrote[i];
      std::fprintf(stderr, "softtled: stopped by signal %d; wrote %s\n", stop_signal(),
                   w.empty() ? "nothing (files already there stay as they were)" : w.c_str());
      return exit_code_for_signal(stop_signal());
    };
    const TetgenOptions topt = scene_tetgen_options(s);
    // Each body meshed by itself, as the Simulation does, then one mesh of the bodies.
    std::vector<SurfaceMesh> surfaces;
    std::vector<TetMesh> parts;
    std::vector<double> rho_scale, E_scale;
    for (int b = 0; b < s.body_count(); ++b) {
      if (s.body(b).shape == "tet_file") {  // the user's tets, read as the Simulation reads them
        std::string note;
        parts.push_back(scene_tet_file_mesh(s, b, &note));
        if (!note.empty()) std::fprintf(stderr, "note: %s\n", note.c_str());
        surfaces.push_back(boundary_surface(parts.back()));  // "input points/facets": the file's boundary
      } else {
        surfaces.push_back(scene_surface(s, b));
        try {
          parts.push_back(tetrahedralize_surface(surfaces.back(), topt));
        } catch (const InputError& e) {  // name the scene (or surface) the mesh came from
          if (stop_requested()) return stopped();  // TetGen's child killed by the stop
          throw InputError((o->surface.empty() ? s.source : "--surface " + o->surface) + ": " + e.what());
        }
      }
      rho_scale.push_back(s.body_rho(b) / s.rho);
      E_scale.push_back(s.body_E(b) / s.E);
    }
    if (stop_requested()) return stopped();  // a tet file read, or a surface meshed, before TetGen saw it
    const TetMesh m = parts.size() == 1 ? parts[0] : concat_bodies(parts, rho_scale, E_scale);
    // TetGen's switches where TetGen meshed some body ("" where every body was a tet file).
    bool meshed = false;
    for (int b = 0; b < s.body_count(); ++b) meshed = meshed || s.body(b).shape != "tet_file";
    const std::string switches = meshed ? tetgen_switches(topt) : "";
    const std::vector<MeshReport> rows =
        parts.size() == 1 ? std::vector<MeshReport>{mesh_report(surfaces[0], m, s.E, s.nu, s.rho, s.material_model)}
                          : body_mesh_reports(s, surfaces, m);
    if (o->json) {
      std::printf("{");
      print_json_fields(rows.back());
      std::printf(", \"tetgen_switches\": %s", json_string(switches).c_str());
      if (rows.size() > 1) {
        std::printf(", \"bodies\": [");
        for (std::size_t b = 0; b + 1 < rows.size(); ++b) {
          std::printf("%s{\"body\": %zu, \"E_Pa\": %.6g, \"rho_kg_m3\": %.6g, ", b ? ", " : "", b, s.body_E(int(b)),
                      s.body_rho(int(b)));
          print_json_fields(rows[b]);
          std::printf("}");
        }
        std::printf("]");
      }
      std::printf("}\n");
    } else {
      for (int b = 0; b < s.body_count(); ++b)  // where each body's tets came from
        if (s.body(b).shape == "tet_file") std::printf("%s: tets read from %s\n", s.body(b).key.c_str(), s.body(b).file.c_str());
      if (meshed) std::printf("TetGen -%s\n", switches.c_str());
      if (rows.size() == 1) print_list(rows[0], s);
      else print_rows(rows, s);
    }
    // A stop between the files leaves the rest unwritten; one during a write lets it finish
    // (a second signal removes its temporary: abrupt_exit.h), unless the write waits for a
    // FIFO's reader: that one is given up (StoppedWhileWaiting).
    try {
      if (!o->write.empty()) {
        if (stop_requested()) return stopped();
        write_tetgen_files(m, o->write);
        wrote.push_back(o->write + ".node");
        wrote.push_back(o->write + ".ele");
      }
      if (!o->vtu.empty()) {
        if (stop_requested()) return stopped();
        write_vtu(o->vtu, m, nullptr, 1.0, {neo_hookean_from_E_nu<double>(s.E, s.nu)});
        wrote.push_back(o->vtu);
      }
    } catch (const StoppedWhileWaiting&) {
      return stopped();
    }
    if (stop_requested()) return stopped();
    return 0;
  };
}

}  // namespace softtled
