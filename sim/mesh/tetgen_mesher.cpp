#include "sim/mesh/tetgen_mesher.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

#ifndef TETLIBRARY
#define TETLIBRARY  // library interface of tetgen.h: errors are thrown, not exit()
#endif
#include <tetgen.h>

namespace softtled {
namespace {

constexpr double kMm = 1000.0;  // TetGen meshes in millimetres (see tetrahedralize_surface)

// The settings TetGen runs with, checked; lengths in millimetres.
struct Switches {
  bool quality = false;
  double rho = 2.0;    // radius-edge bound (TetGen's default when q has no number)
  double theta = 0.0;  // minimum dihedral angle [deg], 0: TetGen's default
  double a_mm3 = 0.0;  // largest tet volume, 0: none
  bool keep_boundary = false;
};

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void check_rho(double rho, const std::string& where) {
  if (!(rho >= kMinRadiusEdge && rho <= kMaxRadiusEdge))
    throw InputError(where + ": the radius-edge bound must be in " + num(kMinRadiusEdge) + ".." + num(kMaxRadiusEdge) +
                     " (TetGen does not terminate below that), got " + num(rho));
}

void check_theta(double theta, const std::string& where) {
  // 0, or at least 0.001 so that the number prints without an exponent (TetGen's q
  // parser reads digits and '.' only).
  if (!(theta == 0 || (theta >= 1e-3 && theta <= kMaxMinDihedralDeg)))
    throw InputError(where + ": the minimum dihedral angle must be 0 (TetGen's default) or in 0.001.." +
                     num(kMaxMinDihedralDeg) + " degrees (larger bounds do not terminate), got " + num(theta));
}

// Parses TetgenOptions::switches: only the documented subset, each letter once.
Switches parse_switches(const std::string& text) {
  const std::string key = "mesh.switches";
  if (text.size() > kMaxSwitchesLength)
    throw InputError(key + ": too long (" + std::to_string(text.size()) + " characters; at most " +
                     std::to_string(kMaxSwitchesLength) + ")");
  const std::string allowed = " (allowed: p, q[rho][/theta], a<volume in mm^3>, Y, z, Q)";
  Switches s;
  std::string seen;
  std::size_t i = 0;
  if (!text.empty() && text[0] == '-') ++i;
  // A number: digits with at most one '.', and for 'a' an exponent e[+-]digits.
  auto number = [&](bool exponent, const std::string& part_start, std::size_t start) -> double {
    std::size_t j = i;
    bool digits = false, dot = false;
    while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || text[j] == '.')) {
      if (text[j] == '.') {
        if (dot) throw InputError(key + ": bad number in '" + text.substr(start, j + 1 - start) + "'" + allowed);
        dot = true;
      } else {
        digits = true;
      }
      ++j;
    }
    if (!digits) throw InputError(key + ": '" + part_start + "' needs a number here: '" + text.substr(start, j + 1 - start) + "'" + allowed);
    if (exponent && j < text.size() && text[j] == 'e') {
      std::size_t k = j + 1;
      if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
      const std::size_t d0 = k;
      while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
      if (k == d0) throw InputError(key + ": bad exponent in '" + text.substr(start, k + 1 - start) + "'");
      j = k;
    }
    const double v = std::strtod(text.substr(i, j - i).c_str(), nullptr);
    i = j;
    return v;
  };
  auto starts_number = [&] { return i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'); };
  while (i < text.size()) {
    const char c = text[i];
    const std::size_t start = i;
    if (std::string("pqaYzQ").find(c) == std::string::npos) {
      const std::string shown = std::isprint(static_cast<unsigned char>(c)) ? std::string(1, c) : "\\x" + num(int(static_cast<unsigned char>(c)));
      throw InputError(key + ": '" + shown + "' is not supported" + allowed);
    }
    if (seen.find(c) != std::string::npos) throw InputError(key + ": '" + std::string(1, c) + "' given twice");
    seen += c;
    ++i;
    if (c == 'q') {
      s.quality = true;
      if (starts_number()) s.rho = number(false, "q", start);
      if (i < text.size() && text[i] == '/') {
        ++i;
        s.theta = number(false, "q.../", start);
      }
      check_rho(s.rho, key + ": '" + text.substr(start, i - start) + "'");
      check_theta(s.theta, key + ": '" + text.substr(start, i - start) + "'");
    } else if (c == 'a') {
      s.a_mm3 = number(true, "a", start);
      if (!(s.a_mm3 > 0 && std::isfinite(s.a_mm3)))
        throw InputError(key + ": '" + text.substr(start, i - start) + "': the volume bound must be finite and > 0");
    } else if (c == 'Y') {
      s.keep_boundary = true;
    }
    if (c != 'q' && c != 'a' && starts_number())
      throw InputError(key + ": '" + text.substr(start, i + 1 - start) + "': '" + std::string(1, c) + "' takes no number" + allowed);
  }
  return s;
}

void check_budget(long max_tets) {
  if (!(max_tets >= 1 && max_tets <= kMaxTetsLimit))
    throw InputError("mesh.max_tets: must be in 1.." + std::to_string(kMaxTetsLimit) + ", got " + std::to_string(max_tets));
}

Switches resolve(const TetgenOptions& o) {
  check_budget(o.max_tets);
  if (!o.switches.empty()) return parse_switches(o.switches);
  Switches s;
  if (!(o.radius_edge == 0 || (o.radius_edge >= kMinRadiusEdge && o.radius_edge <= kMaxRadiusEdge)))
    throw InputError("mesh.radius_edge: must be 0 (no quality bound) or in " + num(kMinRadiusEdge) + ".." +
                     num(kMaxRadiusEdge) + " (TetGen does not terminate below that), got " + num(o.radius_edge));
  check_theta(o.min_dihedral, "mesh.min_dihedral_deg");
  if (!(o.max_volume >= 0 && std::isfinite(o.max_volume) && std::isfinite(o.max_volume * kMm * kMm * kMm)))
    throw InputError("mesh.max_volume: must be finite and >= 0 (0: no bound), got " + num(o.max_volume) + " m^3");
  s.quality = o.radius_edge > 0;
  s.rho = o.radius_edge;
  s.theta = o.min_dihedral;
  s.a_mm3 = o.max_volume * kMm * kMm * kMm;
  s.keep_boundary = o.keep_boundary;
  return s;
}

std::string format(const Switches& s) {
  std::string r = "p";
  if (s.quality) {
    r += "q" + num(s.rho);
    if (s.theta > 0) r += "/" + num(s.theta);
  }
  if (s.a_mm3 > 0) r += "a" + num(s.a_mm3);
  if (s.keep_boundary) r += "Y";
  return r + "zQ";  // zero-based indices, quiet
}

}  // namespace

std::string tetgen_switches(const TetgenOptions& o) { return format(resolve(o)); }

void check_surface_for_meshing(const SurfaceMesh& surface) {
  const std::string what = "surface to mesh";
  auto fail = [&](const std::string& msg) { throw InputError(what + ": " + msg); };
  for (std::size_t i = 0; i < surface.xyz.size(); ++i)
    if (!std::isfinite(surface.xyz[i])) fail("vertex " + std::to_string(i / 3) + " has a NaN or infinite coordinate");
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, far = 0;
  int far_vertex = 0;
  for (int i = 0; i < surface.npoint(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x = surface.xyz[3 * i + k];
      lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
      if (std::fabs(x) > far) far = std::fabs(x), far_vertex = i;
    }
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(size >= kMinExtent && size <= kMaxExtent))
    fail("size " + num(size) + " m (largest bounding-box side) is outside " + num(kMinExtent) + ".." + num(kMaxExtent) + " m");
  if (!(far <= kMaxCoordinate))
    fail("vertex " + std::to_string(far_vertex) + " is " + num(far) + " m from the origin (at most " + num(kMaxCoordinate) +
         " m along each axis)");
  if (!(far <= kMaxOffsetPerExtent * size))
    fail("vertex " + std::to_string(far_vertex) + " is " + num(far) + " m from the origin, more than " +
         num(kMaxOffsetPerExtent) + " times the body's size " + num(size) +
         " m (its coordinates would lose the precision TetGen needs)");
  {  // before the triangles are read
    SurfaceMesh copy = surface;  // indices, closed, manifold, oriented, non-degenerate
    check_and_orient_closed_surface(copy, what);
  }
  for (int t = 0; t < surface.ntri(); ++t) {
    const double* p[3] = {&surface.xyz[3 * surface.tri[3 * t]], &surface.xyz[3 * surface.tri[3 * t + 1]],
                          &surface.xyz[3 * surface.tri[3 * t + 2]]};
    double longest = 0, shortest = INFINITY;
    for (int k = 0; k < 3; ++k) {
      const double* a = p[k];
      const double* b = p[(k + 1) % 3];
      const double l = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
      longest = std::max(longest, l), shortest = std::min(shortest, l);
    }
    if (!(shortest >= kMinEdgePerExtent * size))
      fail("triangle " + std::to_string(t) + " has a short edge of " + num(shortest) + " m, below " + num(kMinEdgePerExtent) +
           " of the body's size " + num(size) + " m (TetGen cannot resolve it)");
    const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double height = std::sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) / longest;  // 2 area / base
    if (!(height >= kMinHeightPerExtent * size))
      fail("triangle " + std::to_string(t) + " is a sliver (height " + num(height) + " m, below " + num(kMinHeightPerExtent) +
           " of the body's size " + num(size) + " m; TetGen cannot resolve it)");
  }
}

namespace {

double surface_area(const SurfaceMesh& s) {
  double a = 0;
  for (int t = 0; t < s.ntri(); ++t) {
    const double* p = &s.xyz[3 * s.tri[3 * t]];
    const double* q = &s.xyz[3 * s.tri[3 * t + 1]];
    const double* r = &s.xyz[3 * s.tri[3 * t + 2]];
    const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, e2[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    a += 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  return a;
}

double estimate(const SurfaceMesh& s, const Switches& sw) {
  const double V = std::fabs(enclosed_volume(s)), A = surface_area(s), ntri = s.ntri();
  const double a_m3 = sw.a_mm3 / (kMm * kMm * kMm);
  // -a switches -q on with TetGen's default bound 2.
  const bool quality = sw.quality || sw.a_mm3 > 0;
  if (!quality) return 2.5 * ntri;
  const double rho = sw.quality ? sw.rho : 2.0, theta = sw.quality ? sw.theta : 0.0;
  const double g_rho = std::max(0.5, std::pow(rho - 1, -0.7));
  const double t = theta / 22;
  const double g_theta = std::pow(1 - t * t, -1.5);
  const double layer = V > 0 ? 4 * A * A * A / (9 * V * V) : INFINITY;
  const double volume = a_m3 > 0 ? 2.5 * V / a_m3 : 0;
  return std::max(2.5 * ntri, layer) * g_rho * g_theta + volume;
}

}  // namespace

double estimate_tet_count(const SurfaceMesh& s, const TetgenOptions& o) { return estimate(s, resolve(o)); }

TetMesh tetrahedralize_surface(const SurfaceMesh& surf, const TetgenOptions& o) {
  // TetGen reads switches in double precision but is scale-sensitive only through "a";
  // mesh in millimetres so tolerances act on O(1) numbers, then convert back to metres.
  const double to_mm = kMm;
  const Switches settings = resolve(o);  // checked before TetGen sees anything
  check_surface_for_meshing(surf);
  const double estimated = estimate(surf, settings);
  if (!(estimated <= double(o.max_tets)))
    throw InputError("mesh too large: about " + num(estimated) + " tetrahedra estimated (" + std::to_string(surf.ntri()) +
                     " surface triangles, volume " + num(std::fabs(enclosed_volume(surf))) + " m^3, TetGen -" +
                     format(settings) + "), above the budget of " + std::to_string(o.max_tets) +
                     " (mesh.max_tets); use a coarser surface, a larger mesh.max_volume or a larger mesh.radius_edge");
  // Backstop for a wrong estimate (TetGen runs that would not terminate): at most
  // max_tets / kSteinerPerTet added points.
  const long steiner_cap = std::max(1L, o.max_tets / kSteinerPerTet);
  const std::string sw = format(settings);
  const std::string sw_capped = sw + "S" + std::to_string(steiner_cap);
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
  std::vector<char> buf(sw_capped.begin(), sw_capped.end());
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
  if (long(out.numberofpoints) - surf.npoint() >= steiner_cap || long(out.numberoftetrahedra) > o.max_tets)
    throw InputError("mesh too large: TetGen -" + sw + " made " + std::to_string(out.numberoftetrahedra) +
                     " tetrahedra and " + std::to_string(out.numberofpoints - surf.npoint()) + " added points (" +
                     num(estimated) + " tetrahedra estimated), above the budget of " + std::to_string(o.max_tets) +
                     " tetrahedra / " + std::to_string(steiner_cap) +
                     " added points (mesh.max_tets); the quality bound may not be reachable on this surface: "
                     "use a larger mesh.radius_edge or a smaller mesh.min_dihedral_deg");
  std::vector<double> X(out.pointlist, out.pointlist + 3 * out.numberofpoints);
  for (double& x : X) x /= to_mm;
  std::vector<int> tet(out.tetrahedronlist, out.tetrahedronlist + 4 * out.numberoftetrahedra);
  return make_tet_mesh(std::move(X), std::move(tet));
}

}  // namespace softtled
