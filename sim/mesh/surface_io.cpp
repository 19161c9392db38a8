#include "sim/mesh/surface_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

namespace softtled {
namespace {

std::string lower_ext(const std::string& path) {
  const auto dot = path.find_last_of('.');
  std::string e = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

// Parses a number and rejects trailing garbage, so "1.0abc" is an error, not 1.0.
double to_number(const std::string& tok, const std::string& name, int line) {
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (tok.empty() || end != tok.c_str() + tok.size())
    throw InputError(name + ":" + std::to_string(line) + ": '" + tok + "' is not a number");
  return v;
}

constexpr std::size_t kMaxElements = 50'000'000;  // refuse absurd counts before allocating

}  // namespace

SurfaceMesh parse_obj(const std::string& data, const std::string& name) {
  SurfaceMesh s;
  std::istringstream in(data);
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      std::string a, b, c;
      if (!(ls >> a >> b >> c)) throw InputError(name + ":" + std::to_string(lineno) + ": vertex needs 3 coordinates");
      s.xyz.insert(s.xyz.end(), {to_number(a, name, lineno), to_number(b, name, lineno), to_number(c, name, lineno)});
    } else if (tag == "f") {
      std::vector<int> poly;
      std::string tok;
      while (ls >> tok) {
        const std::string head = tok.substr(0, tok.find('/'));
        const double v = to_number(head, name, lineno);
        if (v != std::floor(v) || v == 0 || std::fabs(v) > 1e9)
          throw InputError(name + ":" + std::to_string(lineno) + ": bad vertex index '" + head + "'");
        int idx = static_cast<int>(v);
        idx = idx > 0 ? idx - 1 : s.npoint() + idx;  // negative: relative to the end
        poly.push_back(idx);
      }
      if (poly.size() < 3) throw InputError(name + ":" + std::to_string(lineno) + ": face with fewer than 3 vertices");
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) s.tri.insert(s.tri.end(), {poly[0], poly[k], poly[k + 1]});
    }
    if (s.xyz.size() > 3 * kMaxElements || s.tri.size() > 3 * kMaxElements) throw InputError(name + ": too large");
  }
  check_and_orient_closed_surface(s, name);
  return s;
}

SurfaceMesh parse_off(const std::string& data, const std::string& name) {
  std::istringstream in(data);
  std::vector<std::string> tok;
  std::string line;
  while (std::getline(in, line)) {  // strip comments, keep tokens
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream ls(line);
    std::string t;
    while (ls >> t) tok.push_back(t);
  }
  std::size_t p = 0;
  if (tok.empty() || tok[p] != "OFF") throw InputError(name + ": missing 'OFF' header");
  ++p;
  auto next = [&]() -> double {
    if (p >= tok.size()) throw InputError(name + ": file ends early");
    return to_number(tok[p++], name, 0);
  };
  const double nv = next(), nf = next();
  next();  // edge count, unused
  if (!(nv >= 0 && nf >= 0 && nv < kMaxElements && nf < kMaxElements))
    throw InputError(name + ": bad vertex or face count");
  SurfaceMesh s;
  for (int i = 0; i < int(nv) * 3; ++i) s.xyz.push_back(next());
  for (int f = 0; f < int(nf); ++f) {
    const double k = next();
    if (!(k >= 3 && k < 1000)) throw InputError(name + ": face " + std::to_string(f) + " has a bad vertex count");
    std::vector<int> poly;
    for (int j = 0; j < int(k); ++j) {
      const double v = next();
      if (v != std::floor(v) || v < 0 || v >= nv) throw InputError(name + ": face " + std::to_string(f) + " has a bad vertex index");
      poly.push_back(int(v));
    }
    for (std::size_t j = 1; j + 1 < poly.size(); ++j) s.tri.insert(s.tri.end(), {poly[0], poly[j], poly[j + 1]});
  }
  check_and_orient_closed_surface(s, name);
  return s;
}

SurfaceMesh parse_stl(const std::string& data, const std::string& name) {
  // STL stores triangle soup; vertices are merged by exact coordinates.
  std::vector<double> soup;
  const bool binary_size_ok = data.size() >= 84 && [&] {
    std::uint32_t n;
    std::memcpy(&n, data.data() + 80, 4);
    return std::uint64_t(n) * 50 + 84 == data.size();
  }();
  if (binary_size_ok) {
    std::uint32_t n;
    std::memcpy(&n, data.data() + 80, 4);
    for (std::uint32_t t = 0; t < n; ++t) {
      const char* rec = data.data() + 84 + 50 * std::size_t(t);
      for (int v = 0; v < 3; ++v)
        for (int k = 0; k < 3; ++k) {
          float f;
          std::memcpy(&f, rec + 12 + 12 * v + 4 * k, 4);
          soup.push_back(f);
        }
    }
  } else {
    std::istringstream in(data);
    std::string tok;
    if (!(in >> tok) || tok != "solid")
      throw InputError(name + ": neither binary STL (size does not match the triangle count) nor ASCII STL ('solid' missing)");
    int in_facet = 0;
    while (in >> tok) {
      if (tok == "vertex") {
        std::string a, b, c;
        if (!(in >> a >> b >> c)) throw InputError(name + ": vertex needs 3 coordinates");
        soup.insert(soup.end(), {to_number(a, name, 0), to_number(b, name, 0), to_number(c, name, 0)});
        ++in_facet;
      } else if (tok == "endfacet") {
        if (in_facet != 3) throw InputError(name + ": a facet does not have exactly 3 vertices");
        in_facet = 0;
      }
      if (soup.size() > 9 * kMaxElements) throw InputError(name + ": too large");
    }
    if (soup.size() % 9 != 0) throw InputError(name + ": truncated facet");
  }
  // NaN breaks the map's ordering (it would merge into another vertex): check first.
  for (double v : soup)
    if (!std::isfinite(v)) throw InputError(name + ": a vertex coordinate is NaN or infinite");
  SurfaceMesh s;
  std::map<std::tuple<double, double, double>, int> index;
  for (std::size_t i = 0; i < soup.size(); i += 3) {
    const auto key = std::make_tuple(soup[i], soup[i + 1], soup[i + 2]);
    auto it = index.find(key);
    if (it == index.end()) {
      it = index.emplace(key, s.npoint()).first;
      s.xyz.insert(s.xyz.end(), {soup[i], soup[i + 1], soup[i + 2]});
    }
    s.tri.push_back(it->second);
  }
  check_and_orient_closed_surface(s, name);
  return s;
}

SurfaceMesh load_surface(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open file");
  std::ostringstream buf;
  buf << f.rdbuf();
  const std::string ext = lower_ext(path);
  if (ext == "obj") return parse_obj(buf.str(), path);
  if (ext == "off") return parse_off(buf.str(), path);
  if (ext == "stl") return parse_stl(buf.str(), path);
  throw InputError(path + ": unknown surface format '." + ext + "' (use .obj, .off or .stl)");
}

void write_obj(const SurfaceMesh& s, const std::string& path) {
  std::ofstream o(path);
  if (!o) throw InputError(path + ": cannot write");
  o.precision(17);
  for (int i = 0; i < s.npoint(); ++i) o << "v " << s.xyz[3 * i] << ' ' << s.xyz[3 * i + 1] << ' ' << s.xyz[3 * i + 2] << '\n';
  for (int t = 0; t < s.ntri(); ++t) o << "f " << s.tri[3 * t] + 1 << ' ' << s.tri[3 * t + 1] + 1 << ' ' << s.tri[3 * t + 2] + 1 << '\n';
}

}  // namespace softtled
