#include "sim/mesh/tet_mesh.h"
#include "sim/io/output_file.h"

#include <sstream>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "sim/mesh/surface_mesh.h"

namespace softtled {

std::string boundary_manifold_problem(const TetMesh& m, const std::function<std::string(int)>& node_name) {
  return triangles_manifold_problem(m.boundary_tri, m.nnode(), node_name, "boundary");
}

double tet_signed_volume(const double* a, const double* b, const double* c, const double* d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) / 6.0;
}

bool point_in_tet(const double* a, const double* b, const double* c, const double* d, const double* x) {
  const double v = tet_signed_volume(a, b, c, d);
  if (v == 0) return false;
  const double l[4] = {tet_signed_volume(x, b, c, d) / v, tet_signed_volume(a, x, c, d) / v,
                       tet_signed_volume(a, b, x, d) / v, tet_signed_volume(a, b, c, x) / v};
  return l[0] >= 0 && l[1] >= 0 && l[2] >= 0 && l[3] >= 0;
}

BoundaryFaces::BoundaryFaces(const TetMesh& m) : of_node_(m.nnode()) {
  for (int f = 0; f < m.nbtri(); ++f)
    for (int k = 0; k < 3; ++k) of_node_[m.boundary_tri[3 * f + k]].push_back(f);
}

bool BoundaryFaces::strictly_inside(const TetMesh& m, int e, const double* x) const {
  const int* t = &m.tet[4 * e];
  if (!point_in_tet(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]], x)) return false;
  // On a boundary triangle, x shares it with e, so the triangle has a node of e.
  for (int i = 0; i < 4; ++i)
    for (int f : of_node_[t[i]]) {
      const double* a = &m.X[3 * m.boundary_tri[3 * f]];
      const double* b = &m.X[3 * m.boundary_tri[3 * f + 1]];
      const double* c = &m.X[3 * m.boundary_tri[3 * f + 2]];
      const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double ax[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
      const double n[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
      const double n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
      const double len = std::sqrt(std::max({ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2],
                                             ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2]}));
      if (!(n2 > 0)) continue;
      const double off = (n[0] * ax[0] + n[1] * ax[1] + n[2] * ax[2]) / std::sqrt(n2);
      if (!(std::fabs(off) <= kOnFace * len)) continue;
      // In the triangle, within the same tolerance: the barycentric coordinates of x's
      // projection (Ericson, Real-Time Collision Detection, sec. 3.4).
      const double d00 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2], d01 = ab[0] * ac[0] + ab[1] * ac[1] + ab[2] * ac[2];
      const double d11 = ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2];
      const double d20 = ax[0] * ab[0] + ax[1] * ab[1] + ax[2] * ab[2], d21 = ax[0] * ac[0] + ax[1] * ac[1] + ax[2] * ac[2];
      const double den = d00 * d11 - d01 * d01;
      const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
      if (v >= -kOnFace && w >= -kOnFace && v + w <= 1 + kOnFace) return false;  // on the boundary: touching
    }
  return true;
}

double tet_mesh_volume(const TetMesh& m) {
  double v = 0;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    v += tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
  }
  return v;
}

// Faces of tet (0,1,2,3) oriented outward (counter-clockwise seen from outside) when the
// tet is positive, i.e. (X1-X0) x (X2-X0) . (X3-X0) > 0: face opposite corner a.
static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

TetMesh make_tet_mesh(std::vector<double> X, std::vector<int> tet) {
  TetMesh m;
  m.X = std::move(X);
  m.tet = std::move(tet);
  const int n = m.nnode();
  for (int e = 0; e < m.ntet(); ++e) {
    int* t = &m.tet[4 * e];
    for (int a = 0; a < 4; ++a)
      if (t[a] < 0 || t[a] >= n) throw InputError("tet " + std::to_string(e) + " refers to a missing node");
    double v = tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
    if (v < 0) {
      std::swap(t[2], t[3]);
      v = -v;
    }
    if (!(v > 0)) throw InputError("tet " + std::to_string(e) + " has zero volume");
  }
  std::map<std::array<int, 3>, std::pair<int, std::array<int, 3>>> faces;  // sorted -> count, oriented
  for (int e = 0; e < m.ntet(); ++e)
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> o = {m.tet[4 * e + kFace[f][0]], m.tet[4 * e + kFace[f][1]], m.tet[4 * e + kFace[f][2]]};
      std::array<int, 3> k = o;
      std::sort(k.begin(), k.end());
      auto& entry = faces[k];
      ++entry.first;
      entry.second = o;
    }
  std::set<int> surf;
  for (const auto& [k, entry] : faces)
    if (entry.first == 1) {
      m.boundary_tri.insert(m.boundary_tri.end(), entry.second.begin(), entry.second.end());
      surf.insert(k.begin(), k.end());
    }
  m.surface_nodes.assign(surf.begin(), surf.end());
  return m;
}

int TetMesh::nbody() const {
  return node_body.empty() ? 1 : node_body.back() + 1;
}

TetMesh concat_bodies(const std::vector<TetMesh>& bodies, const std::vector<double>& rho_scale,
                      const std::vector<double>& E_scale) {
  TetMesh m;
  bool uniform = true;
  for (std::size_t b = 0; b < bodies.size(); ++b) uniform = uniform && rho_scale[b] == 1.0 && E_scale[b] == 1.0;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const TetMesh& p = bodies[b];
    const int off = m.nnode();
    m.X.insert(m.X.end(), p.X.begin(), p.X.end());
    for (int v : p.tet) m.tet.push_back(v + off);
    for (int v : p.boundary_tri) m.boundary_tri.push_back(v + off);
    for (int v : p.surface_nodes) m.surface_nodes.push_back(v + off);
    m.node_body.insert(m.node_body.end(), p.nnode(), int(b));
    m.tet_body.insert(m.tet_body.end(), p.ntet(), int(b));
    if (!uniform) {
      m.rho_scale.insert(m.rho_scale.end(), p.ntet(), rho_scale[b]);
      m.E_scale.insert(m.E_scale.end(), p.ntet(), E_scale[b]);
    }
  }
  return m;
}

MeshCounts count_faces_and_edges(const TetMesh& m) {
  std::set<std::array<int, 3>> faces;
  std::set<std::pair<int, int>> edges, bedges;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> k = {t[kFace[f][0]], t[kFace[f][1]], t[kFace[f][2]]};
      std::sort(k.begin(), k.end());
      faces.insert(k);
    }
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) edges.insert({std::min(t[a], t[b]), std::max(t[a], t[b])});
  }
  for (int f = 0; f < m.nbtri(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.boundary_tri[3 * f + k], b = m.boundary_tri[3 * f + (k + 1) % 3];
      bedges.insert({std::min(a, b), std::max(a, b)});
    }
  MeshCounts c;
  c.faces = long(faces.size());
  c.edges = long(edges.size());
  c.boundary_faces = m.nbtri();
  c.boundary_edges = long(bedges.size());
  return c;
}

EdgeLengths element_edge_lengths(const TetMesh& m) {
  EdgeLengths r;
  double sum = 0;
  for (int e = 0; e < m.ntet(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const double* p = &m.X[3 * m.tet[4 * e + a]];
        const double* q = &m.X[3 * m.tet[4 * e + b]];
        const double l = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        sum += l;
        r.longest = std::max(r.longest, l);
      }
  if (m.ntet() > 0) r.mean = sum / (6.0 * m.ntet());
  return r;
}

MeshQuality measure_quality(const TetMesh& m) {
  MeshQuality q;
  std::vector<double> Le(m.ntet());
  double min_dih = 180;
  q.min_Le = 1e300;
  for (int e = 0; e < m.ntet(); ++e) {
    const double* p[4];
    for (int a = 0; a < 4; ++a) p[a] = &m.X[3 * m.tet[4 * e + a]];
    const double V = tet_signed_volume(p[0], p[1], p[2], p[3]);
    double nrm[4][3], area[4];
    double amax = 0;
    for (int f = 0; f < 4; ++f) {
      const double* a = p[kFace[f][0]];
      const double* b = p[kFace[f][1]];
      const double* c = p[kFace[f][2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      nrm[f][0] = u[1] * v[2] - u[2] * v[1];
      nrm[f][1] = u[2] * v[0] - u[0] * v[2];
      nrm[f][2] = u[0] * v[1] - u[1] * v[0];
      area[f] = 0.5 * std::sqrt(nrm[f][0] * nrm[f][0] + nrm[f][1] * nrm[f][1] + nrm[f][2] * nrm[f][2]);
      amax = std::max(amax, area[f]);
    }
    Le[e] = 3 * V / amax;
    if (Le[e] < q.min_Le) {
      q.min_Le = Le[e];
      q.worst_element = e;
    }
    // Dihedral angle between faces f and g: pi - angle between their outward normals.
    for (int f = 0; f < 4; ++f)
      for (int g = f + 1; g < 4; ++g) {
        const double d = (nrm[f][0] * nrm[g][0] + nrm[f][1] * nrm[g][1] + nrm[f][2] * nrm[g][2]) / (4 * area[f] * area[g]);
        const double ang = 180.0 - std::acos(std::clamp(d, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
        min_dih = std::min(min_dih, ang);
      }
  }
  std::vector<double> s = Le;
  if (!s.empty()) {
    std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
    q.median_Le = s[s.size() / 2];
  }
  q.min_dihedral_deg = min_dih;
  return q;
}

void write_tetgen_files(const TetMesh& m, const std::string& base) {
  std::ostringstream nd, el;
  nd.precision(17);
  nd << m.nnode() << " 3 0 0\n";
  for (int i = 0; i < m.nnode(); ++i) nd << i << ' ' << m.X[3 * i] << ' ' << m.X[3 * i + 1] << ' ' << m.X[3 * i + 2] << '\n';
  el << m.ntet() << " 4 0\n";
  for (int e = 0; e < m.ntet(); ++e)
    el << e << ' ' << m.tet[4 * e] << ' ' << m.tet[4 * e + 1] << ' ' << m.tet[4 * e + 2] << ' ' << m.tet[4 * e + 3] << '\n';
  // Both or neither: a new .node beside the old .ele would read as another mesh.
  write_files_atomic({{base + ".node", nd.str()}, {base + ".ele", el.str()}});  // checked; ResourceError naming the file
}

}  // namespace softtled
