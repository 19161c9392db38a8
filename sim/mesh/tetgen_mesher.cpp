#include "sim/mesh/tetgen_mesher.h"

#include <cstdio>
#include <sstream>
#include <vector>

#ifndef TETLIBRARY
#define TETLIBRARY  // library interface of tetgen.h: errors are thrown, not exit()
#endif
#include <tetgen.h>

namespace softtled {

std::string tetgen_switches(const TetgenOptions& o) {
  std::ostringstream s;
  if (!o.switches.empty()) {
    s << o.switches;
  } else {
    s << "p";
    if (o.radius_edge > 0) {
      s << "q" << o.radius_edge;
      if (o.min_dihedral > 0) s << "/" << o.min_dihedral;
    }
    if (o.max_volume > 0) s << "a" << o.max_volume;
    if (o.keep_boundary) s << "Y";
  }
  std::string r = s.str();
  if (r.find('p') == std::string::npos) r = "p" + r;
  return r + "zQ";  // zero-based indices, quiet
}

TetMesh tetrahedralize_surface(const SurfaceMesh& surf, const TetgenOptions& o) {
  // TetGen reads switches in double precision but is scale-sensitive only through "a";
  // mesh in millimetres so tolerances act on O(1) numbers, then convert back to metres.
  const double to_mm = 1000.0;
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = surf.npoint();
  in.pointlist = new REAL[surf.xyz.size()];
  for (std::size_t i = 0; i < surf.xyz.size(); ++i) in.pointlist[i] = surf.xyz[i] * to_mm;
  in.numberoffacets = surf.ntri();
  in.facetlist = new tetgenio::facet[surf.ntri()];
  in.facetmarkerlist = nullptr;
  for (int t = 0; t < surf.ntri(); ++t) {
    tetgenio::facet& f = in.facetlist[t];
    tetgenio::init(&f);
    f.numberofpolygons = 1;
    f.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&f.polygonlist[0]);
    f.polygonlist[0].numberofvertices = 3;
    f.polygonlist[0].vertexlist = new int[3]{surf.tri[3 * t], surf.tri[3 * t + 1], surf.tri[3 * t + 2]};
  }
  // TetGen 1.5.0 throws on self-intersecting input but then crashes while unwinding (in
  // ~memorypool), so detect intersections first with -d, which returns them as faces.
  {
    tetgenio probe;
    char sw_d[] = "pdzQ";
    try {
      tetrahedralize(sw_d, &in, &probe);
    } catch (int code) {
      throw InputError("TetGen intersection check failed with code " + std::to_string(code));
    }
    if (probe.numberoftrifaces > 0)
      throw InputError("the surface intersects itself (" + std::to_string(probe.numberoftrifaces) +
                       " facets cross others); TetGen needs a closed surface without self-intersections");
  }
  TetgenOptions scaled = o;
  scaled.max_volume = o.max_volume * to_mm * to_mm * to_mm;
  std::string sw = tetgen_switches(scaled);
  std::vector<char> buf(sw.begin(), sw.end());
  buf.push_back('\0');
  try {
    tetrahedralize(buf.data(), &in, &out);
  } catch (int code) {
    const char* why = code == 1 ? "out of memory"
                      : code == 2 ? "internal error"
                      : code == 3 ? "the surface intersects itself"
                      : code == 4 ? "a very small input feature (near-degenerate facets)"
                      : code == 5 ? "two very close input facets"
                      : code == 10 ? "an input error"
                                   : "unknown failure";
    throw InputError("TetGen (-" + sw + ") failed with code " + std::to_string(code) + ": " + why);
  }
  if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4)
    throw InputError("TetGen (-" + sw + ") produced no linear tetrahedra");
  std::vector<double> X(out.pointlist, out.pointlist + 3 * out.numberofpoints);
  for (double& x : X) x /= to_mm;
  std::vector<int> tet(out.tetrahedronlist, out.tetrahedronlist + 4 * out.numberoftetrahedra);
  return make_tet_mesh(std::move(X), std::move(tet));
}

}  // namespace softtled
