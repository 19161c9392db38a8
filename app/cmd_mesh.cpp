// `softtled mesh`: tetrahedralize a scene's body or a surface file and report the paper's
// Table I counts plus element quality and the critical time step.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>

#include "app/commands.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"
#include "sim/solver/stable_step.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/io/output_file.h"
#include "sim/io/vtu_writer.h"

namespace softtled {

Command add_mesh_command(CLI::App& app) {
  struct Opts {
    std::string scene, surface, write, vtu;
    std::vector<std::string> set;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("mesh", "tetrahedralize and print mesh statistics (paper's Table I)");
  c->add_option("--scene", o->scene, "scene file (TOML)");
  c->add_option("--surface", o->surface, "surface file (.obj/.off/.stl, lengths in the scene's units)");
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  c->add_flag("--json", o->json, "print JSON instead of a table");
  c->add_option("--write", o->write, "write BASE.node and BASE.ele");
  c->add_option("--vtu", o->vtu, "write the tet mesh as a ParaView .vtu file");
  return [o]() {
    // Output paths first: a bad one must fail before minutes of meshing.
    if (!o->write.empty()) {
      check_output_file(o->write + ".node", "--write");
      check_output_file(o->write + ".ele", "--write");
    }
    if (!o->vtu.empty()) check_output_file(o->vtu, "--vtu");
    Scene s = o->scene.empty() ? parse_scene("", "(defaults)", o->set) : load_scene(o->scene, o->set);
    if (!o->surface.empty()) {
      s.shape = "file";
      s.file = o->surface;
      s.source = "--surface";  // no directory: the path is used as given
    }
    const SurfaceMesh surf = scene_surface(s);
    const TetgenOptions topt = scene_tetgen_options(s);
    TetMesh m;
    try {
      m = tetrahedralize_surface(surf, topt);
    } catch (const InputError& e) {  // name the scene (or surface) the mesh came from
      throw InputError((o->surface.empty() ? s.source : "--surface " + o->surface) + ": " + e.what());
    }
    const MeshCounts cnt = count_faces_and_edges(m);
    const MeshQuality q = measure_quality(m);
    const double c_wave = dilatational_wave_speed(s.E, s.nu, s.rho);
    const double dt_le = q.min_Le / c_wave;
    const double dt_eigen = 2.0 / std::sqrt(rest_eigen_scale(m, s.nu, s.material_model) * s.E / s.rho);
    const double dt_cr = std::min(dt_le, dt_eigen);
    const long segments = long(surf.ntri()) * 3 / 2;
    if (o->json) {
      std::printf("{\"input_points\": %d, \"input_facets\": %d, \"input_segments\": %ld, \"mesh_points\": %d, "
                  "\"tetrahedra\": %d, \"faces\": %ld, \"edges\": %ld, \"boundary_faces\": %ld, \"boundary_edges\": %ld, "
                  "\"min_Le_m\": %.6g, \"median_Le_m\": %.6g, \"min_dihedral_deg\": %.4g, \"wave_speed_m_s\": %.6g, "
                  "\"dt_le_s\": %.6g, \"dt_eigen_s\": %.6g, \"dt_cr_s\": %.6g, \"tetgen_switches\": \"%s\"}\n",
                  surf.npoint(), surf.ntri(), segments, m.nnode(), m.ntet(), cnt.faces, cnt.edges, cnt.boundary_faces,
                  cnt.boundary_edges, q.min_Le, q.median_Le, q.min_dihedral_deg, c_wave, dt_le, dt_eigen, dt_cr,
                  tetgen_switches(topt).c_str());
    } else {
      std::printf("TetGen -%s\n", tetgen_switches(topt).c_str());
      std::printf("%-18s %10d\n%-18s %10d\n%-18s %10ld\n", "Input points", surf.npoint(), "Input facets", surf.ntri(),
                  "Input segments", segments);
      std::printf("%-18s %10d\n%-18s %10d\n%-18s %10ld\n%-18s %10ld\n%-18s %10ld\n%-18s %10ld\n", "Mesh points", m.nnode(),
                  "Mesh tetrahedra", m.ntet(), "Mesh faces", cnt.faces, "Mesh edges", cnt.edges, "Boundary faces",
                  cnt.boundary_faces, "Boundary edges", cnt.boundary_edges);
      std::printf("%-18s %10.4g mm (element %d)\n%-18s %10.4g mm\n%-18s %10.3g deg\n", "Min Le", q.min_Le * 1e3,
                  q.worst_element, "Median Le", q.median_Le * 1e3, "Min dihedral", q.min_dihedral_deg);
      std::printf("%-18s %10.4g m/s (E = %g Pa, nu = %g, rho = %g kg/m^3)\n%-18s %10.4g us\n%-18s %10.4g us\n%-18s %10.4g us\n",
                  "Wave speed c", c_wave, s.E, s.nu, s.rho, "Le/c (eq. 9)", dt_le * 1e6, "2/omega_max", dt_eigen * 1e6,
                  "dt_cr (smaller)", dt_cr * 1e6);
    }
    if (!o->write.empty()) write_tetgen_files(m, o->write);
    if (!o->vtu.empty()) write_vtu(o->vtu, m, nullptr, 1.0, neo_hookean_from_E_nu<double>(s.E, s.nu));
    return 0;
  };
}

}  // namespace softtled
