#include "sim/mesh/surface_io.h"
#include "sim/io/output_file.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace softtled {
namespace {

// Parses a number and rejects trailing garbage, so "1.0abc" is an error, not 1.0, and a
// value that is not finite (nan, inf, 1e400) on its own line: caught later, at the first
// face that used it, the message named the face's line.
double to_number(const std::string& tok, const std::string& name, int line) {
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (tok.empty() || end != tok.c_str() + tok.size())
    throw InputError(name + ":" + std::to_string(line) + ": '" + tok + "' is not a number");
  if (!std::isfinite(v))
    throw InputError(name + ":" + std::to_string(line) + ": '" + tok + "' is NaN or infinite (or beyond the range of a double)");
  return v;
}


constexpr std::size_t kMaxElements = 50'000'000;  // refuse absurd counts before allocating

}  // namespace

bool triangulate_polygon(const std::vector<double>& xyz, const std::vector<int>& poly, std::vector<int>& out) {
  const int n = int(poly.size());
  if (n < 3) return false;
  if (n == 3) {
    out.insert(out.end(), poly.begin(), poly.end());
    return true;
  }
  const int npoint = int(xyz.size() / 3);
  for (int i = 0; i < n; ++i) {
    if (poly[i] < 0 || poly[i] >= npoint) return false;
    for (int j = 0; j < i; ++j)
      if (poly[i] == poly[j]) return false;
  }
  // Coordinates relative to the first vertex; Newell's normal of the polygon.
  std::vector<double> p(3 * n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) p[3 * i + k] = xyz[3 * poly[i] + k] - xyz[3 * poly[0] + k];
  double N[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const double* c = &p[3 * i];
    const double* d = &p[3 * ((i + 1) % n)];
    N[0] += (c[1] - d[1]) * (c[2] + d[2]);
    N[1] += (c[2] - d[2]) * (c[0] + d[0]);
    N[2] += (c[0] - d[0]) * (c[1] + d[1]);
  }
  const double len = std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
  if (!(len > 0) || !std::isfinite(len)) return false;
  for (double& v : N) v /= len;
  // In-plane basis (u, v) with u x v = N: the polygon projects counter-clockwise.
  const int axis = std::fabs(N[0]) <= std::fabs(N[1]) && std::fabs(N[0]) <= std::fabs(N[2]) ? 0
                   : std::fabs(N[1]) <= std::fabs(N[2])                                    ? 1
                                                                                            : 2;
  double e[3] = {0, 0, 0};
  e[axis] = 1;
  double u[3] = {N[1] * e[2] - N[2] * e[1], N[2] * e[0] - N[0] * e[2], N[0] * e[1] - N[1] * e[0]};
  const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (double& x : u) x /= ul;
  const double v[3] = {N[1] * u[2] - N[2] * u[1], N[2] * u[0] - N[0] * u[2], N[0] * u[1] - N[1] * u[0]};
  std::vector<double> q(2 * n);
  for (int i = 0; i < n; ++i) {
    const double* c = &p[3 * i];
    q[2 * i] = c[0] * u[0] + c[1] * u[1] + c[2] * u[2];
    q[2 * i + 1] = c[0] * v[0] + c[1] * v[1] + c[2] * v[2];
  }
  auto cross = [&](int a, int b, int c) {  // (b - a) x (c - a), z component
    return (q[2 * b] - q[2 * a]) * (q[2 * c + 1] - q[2 * a + 1]) - (q[2 * b + 1] - q[2 * a + 1]) * (q[2 * c] - q[2 * a]);
  };
  auto d2 = [&](int a, int b) {
    const double dx = q[2 * b] - q[2 * a], dy = q[2 * b + 1] - q[2 * a + 1];
    return dx * dx + dy * dy;
  };
  auto same = [&](int a, int b) { return q[2 * a] == q[2 * b] && q[2 * a + 1] == q[2 * b + 1]; };
  // Strictly convex corner, with the same tolerance as the surface check's degenerate test.
  auto convex = [&](int a, int b, int c) { return cross(a, b, c) > 1e-12 * std::max(d2(a, b), d2(a, c)); };
  std::vector<int> prev(n), next(n);
  for (int i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  const std::size_t out0 = out.size();
  int m = n, cur = 0, misses = 0;
  while (m > 3) {
    const int a = prev[cur], b = cur, c = next[cur];
    bool ear = convex(a, b, c);
    // Only a corner that is not strictly convex can lie in the ear (or on its edges).
    for (int r = next[c]; ear && r != a; r = next[r]) {
      if (convex(prev[r], r, next[r]) || same(r, a) || same(r, b) || same(r, c)) continue;
      if (cross(a, b, r) >= 0 && cross(b, c, r) >= 0 && cross(c, a, r) >= 0) ear = false;
    }
    if (ear) {
      out.insert(out.end(), {poly[a], poly[b], poly[c]});
      next[a] = c, prev[c] = a;
      --m;
      cur = c;
      misses = 0;
    } else {
      cur = next[cur];
      if (++misses > m) {  // a full turn without an ear: not a simple polygon
        out.resize(out0);
        return false;
      }
    }
  }
  if (!convex(prev[cur], cur, next[cur])) {
    out.resize(out0);
    return false;
  }
  out.insert(out.end(), {poly[prev[cur]], poly[cur], poly[next[cur]]});
  return true;
}

namespace {

// Triangulates the polygons collected by a parser once all vertices are known.
struct PolygonList {
  std::string name;                // file name for messages
  bool by_line = true;             // tag is a line number (OBJ) or a face number (OFF)
  std::vector<int> index;          // all polygons' vertex indices, one after another
  std::vector<std::size_t> start;  // polygon k is index[start[k] .. start[k + 1])
  std::vector<long> tag;           // line or face of polygon k, for messages
  void add(const std::vector<int>& poly, long at) {
    if (start.empty()) start.push_back(0);
    index.insert(index.end(), poly.begin(), poly.end());
    start.push_back(index.size());
    tag.push_back(at);
  }
  std::string where(std::size_t k) const {
    return by_line ? name + ":" + std::to_string(tag[k]) : name + ": face " + std::to_string(tag[k]);
  }
  void triangulate_into(SurfaceMesh& s) const {
    std::vector<int> poly;
    for (std::size_t k = 0; k + 1 < start.size(); ++k) {
      poly.assign(index.begin() + start[k], index.begin() + start[k + 1]);
      for (int v : poly) {
        if (v < 0 || v >= s.npoint())
          throw InputError(where(k) + ": refers to vertex " + std::to_string(v) + " of " + std::to_string(s.npoint()) +
                           " (0-based)");
        // Before the ear clipping, which would call such a face "not a simple polygon".
        for (int d = 0; d < 3; ++d) {
          const double x = s.xyz[3 * std::size_t(v) + d];
          if (!std::isfinite(x))
            throw InputError(where(k) + ": vertex " + std::to_string(v) + " (0-based) has a NaN or infinite coordinate");
          if (!(std::fabs(x) < 1e150)) {  // as check_closed_surface's triangles (the ear test overflows)
            char xs[32];
            std::snprintf(xs, sizeof xs, "%.3g", x);
            throw InputError(where(k) + ": vertex " + std::to_string(v) + " (0-based): the coordinates overflow (" + xs +
                             "; coordinates must stay well below 1e150)");
          }
        }
      }
      if (!triangulate_polygon(s.xyz, poly, s.tri))
        throw InputError(where(k) + ": face of " + std::to_string(poly.size()) +
                         " vertices is not a simple polygon (it intersects itself, repeats a vertex or is degenerate)");
    }
  }
};

}  // namespace

SurfaceMesh parse_obj(const std::string& data, const std::string& name) {
  SurfaceMesh s;
  PolygonList polygons{name, true, {}, {}, {}};
  std::istringstream in(has_bom(data) ? data.substr(3) : data);
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    // A comment may end any line: '#' at the start of a word ("1.#QNAN" is a bad number,
    // not a comment).
    std::size_t hash = line.find('#');
    while (hash != std::string::npos && hash > 0 && !std::isspace(static_cast<unsigned char>(line[hash - 1])))
      hash = line.find('#', hash + 1);
    std::istringstream ls(line.substr(0, hash));
    std::string tag;
    if (!(ls >> tag)) continue;
    const std::string at = name + ":" + std::to_string(lineno);
    if (tag == "v") {
      std::string a, b, c, more;
      if (!(ls >> a >> b >> c)) throw InputError(at + ": vertex needs 3 coordinates");
      s.xyz.insert(s.xyz.end(), {to_number(a, name, lineno), to_number(b, name, lineno), to_number(c, name, lineno)});
      // x y z, then an optional w, or r g b [a] (vertex colours): numbers, read and unused.
      for (int k = 0; ls >> more; ++k) {
        if (k == 4) throw InputError(at + ": vertex with more than 7 numbers (x y z, then w, or r g b, or r g b a)");
        to_number(more, name, lineno);
      }
    } else if (tag == "f") {
      std::vector<int> poly;
      std::string tok;
      while (ls >> tok) {
        const std::string head = tok.substr(0, tok.find('/'));
        // v, v/vt, v//vn or v/vt/vn: the texture and normal indices are unused but must be
        // indices or empty (some exporters write "1//" or "1/"); a corrupt field is not skipped.
        for (std::size_t p = tok.find('/'), n = 0; p != std::string::npos; p = tok.find('/', p + 1), ++n) {
          const std::size_t e = tok.find('/', p + 1);
          const std::string field = tok.substr(p + 1, e == std::string::npos ? std::string::npos : e - p - 1);
          if (n >= 2 || field.find_first_not_of("-0123456789") != std::string::npos)
            throw InputError(at + ": bad face corner '" + tok + "' (v, v/vt, v//vn or v/vt/vn expected)");
        }
        const double v = to_number(head, name, lineno);
        if (v != std::floor(v) || v == 0 || std::fabs(v) > 1e9)
          throw InputError(at + ": bad vertex index '" + head + "'");
        if (v < 0 && -v > s.npoint())
          throw InputError(at + ": vertex index " + head + " counts back past the first vertex (" +
                           std::to_string(s.npoint()) + " vertices before this line)");
        int idx = static_cast<int>(v);
        idx = idx > 0 ? idx - 1 : s.npoint() + idx;  // negative: relative to the end
        poly.push_back(idx);
        if (poly.size() > std::size_t(kMaxPolygonVertices))
          throw InputError(name + ":" + std::to_string(lineno) + ": face with more than " +
                           std::to_string(kMaxPolygonVertices) + " vertices");
      }
      if (poly.size() < 3) throw InputError(name + ":" + std::to_string(lineno) + ": face with fewer than 3 vertices");
      polygons.add(poly, lineno);
    }
    if (s.xyz.size() > 3 * kMaxElements || polygons.index.size() > 3 * kMaxElements) throw InputError(name + ": too large");
  }
  polygons.triangulate_into(s);
  check_and_orient_closed_surface(s, name);
  drop_unused_vertices(s);
  return s;
}

namespace {

// Tokens of an OFF file line by line ('#' starts a comment), so that a parser can tell
// whether an entry fills its line (then trailing columns are colours or normals).
class OffTokens {
 public:
  OffTokens(const std::string& data, const std::string& name) : d_(data), name_(name) {}
  // Moves to the next line with tokens if the current one is used up; false at the end.
  bool ensure() {
    while (k_ == line_.size()) {
      if (pos_ >= d_.size()) return false;
      std::size_t eol = d_.find('\n', pos_);
      if (eol == std::string::npos) eol = d_.size();
      std::size_t end = d_.find('#', pos_);
      if (end == std::string::npos || end > eol) end = eol;
      ++lineno_;
      line_.clear();
      k_ = 0;
      for (std::size_t i = pos_; i < end;) {
        while (i < end && std::isspace(static_cast<unsigned char>(d_[i]))) ++i;
        const std::size_t j0 = i;
        while (i < end && !std::isspace(static_cast<unsigned char>(d_[i]))) ++i;
        if (i > j0) line_.emplace_back(d_.substr(j0, i - j0));
      }
      pos_ = eol + 1;
    }
    return true;
  }
  bool at_line_start() const { return k_ == 0; }
  const std::string& peek() const { return line_[k_]; }  // needs left_in_line() > 0
  std::size_t left_in_line() const { return line_.size() - k_; }
  const std::string& take() {
    if (!ensure()) throw InputError(name_ + ": file ends early (line " + std::to_string(lineno_) + ")");
    return line_[k_++];
  }
  double number() { return to_number(take(), name_, lineno_); }
  // An integer in [lo, hi]; `what` names it in the message.
  long integer(long lo, long hi, const std::string& what) {
    const std::string& t = take();
    const double v = to_number(t, name_, lineno_);
    if (v != std::floor(v) || !(v >= lo && v <= hi))
      throw InputError(at() + ": " + what + " '" + t + "' is not an integer in " + std::to_string(lo) + ".." +
                       std::to_string(hi));
    return long(v);
  }
  std::string at() const { return name_ + ":" + std::to_string(lineno_); }

 private:
  const std::string& d_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int lineno_ = 0;
  std::vector<std::string> line_;
  std::size_t k_ = 0;
};

}  // namespace

SurfaceMesh parse_off(const std::string& data, const std::string& name) {
  const std::string unmarked = has_bom(data) ? data.substr(3) : std::string();
  OffTokens in(has_bom(data) ? unmarked : data, name);
  // Header: [ST][C][N][4][n]OFF (geomview's OFF format).
  if (!in.ensure()) throw InputError(name + ": missing 'OFF' header");
  const std::string header = in.take();
  std::size_t h = 0;
  bool texture = false, colour = false, normal = false;
  if (header.compare(0, 2, "ST") == 0) texture = true, h += 2;
  if (h < header.size() && header[h] == 'C') colour = true, ++h;
  if (h < header.size() && header[h] == 'N') normal = true, ++h;
  if (header.substr(h) != "OFF") {
    if (header.size() > 3 && header.compare(header.size() - 3, 3, "OFF") == 0)
      throw InputError(name + ": header '" + header + "': only 3-D OFF with the prefixes ST, C and N is supported");
    throw InputError(name + ": missing 'OFF' header");
  }
  if (in.left_in_line() > 0 && in.peek() == "BINARY") throw InputError(name + ": binary OFF is not supported (write it as text)");
  // Counts: "nv nf ne" or "nv nf", on their own line or after the header; when more
  // numbers follow on that line (everything on one line), exactly three.
  in.ensure();
  const std::size_t ncounts = in.left_in_line() == 2 || in.left_in_line() == 3 ? in.left_in_line() : 3;
  const long nv = in.integer(0, long(kMaxElements), "vertex count");
  const long nf = in.integer(0, long(kMaxElements), "face count");
  if (ncounts == 3) in.integer(0, std::numeric_limits<long>::max() / 2, "edge count");  // unused
  SurfaceMesh s;
  s.xyz.reserve(3 * std::size_t(std::min<long>(nv, long(data.size() / 6 + 1))));
  // Vertex columns: x y z, normal (N), colour (C: RGB or RGBA), texture s t (ST). One
  // vertex per line (then up to 4 trailing colour values are accepted with or without C)
  // or, when the first vertex line holds more, a plain stream of numbers.
  const std::size_t fixed = 3 + (normal ? 3 : 0) + (texture ? 2 : 0);
  bool per_line = true;
  if (nv > 0) {
    in.ensure();
    per_line = in.at_line_start() && in.left_in_line() <= fixed + 4;
  }
  for (long i = 0; i < nv; ++i) {
    std::size_t extra = colour ? 4 : 0;  // stream: geomview's RGBA
    if (per_line) {
      in.ensure();
      if (!in.at_line_start() || in.left_in_line() < fixed)
        throw InputError(in.at() + ": vertex " + std::to_string(i) + " needs " + std::to_string(fixed) + " numbers on its line");
      extra = in.left_in_line() - fixed;
      if (extra > 4)
        throw InputError(in.at() + ": vertex " + std::to_string(i) + " has " + std::to_string(in.left_in_line()) +
                         " numbers; expected " + std::to_string(fixed) + " and at most 4 colour values");
    }
    for (int k = 0; k < 3; ++k) s.xyz.push_back(in.number());
    for (std::size_t k = 3; k < fixed + extra; ++k) in.number();  // normal, colour, texture: checked, unused
  }
  PolygonList polygons{name, false, {}, {}, {}};
  std::vector<int> poly;
  for (long f = 0; f < nf; ++f) {
    in.ensure();
    const bool starts_line = in.at_line_start();
    const std::size_t on_line = in.left_in_line();
    const std::string face = "face " + std::to_string(f);
    const long k = in.integer(3, kMaxPolygonVertices, face + ": vertex count");
    poly.clear();
    for (long j = 0; j < k; ++j) poly.push_back(int(in.integer(0, std::max(0L, nv - 1), face + ": vertex index")));
    // Trailing colour on the face's own line: none, a colour-map index, RGB or RGBA.
    if (starts_line && on_line >= std::size_t(k) + 1 && on_line - std::size_t(k) - 1 <= 4)
      for (std::size_t c = on_line - std::size_t(k) - 1; c > 0; --c) in.number();
    polygons.add(poly, f);
  }
  if (in.ensure()) throw InputError(in.at() + ": unexpected data after the last face ('" + in.peek() + "')");
  polygons.triangulate_into(s);
  check_and_orient_closed_surface(s, name);
  drop_unused_vertices(s);
  return s;
}

namespace {

bool is_control(char ch) { return ch != '\n' && ch != '\r' && ch != '\t' && ((ch >= 0 && ch < 32) || ch == 127); }

std::size_t first_control_byte(const std::string& d) {
  const auto it = std::find_if(d.begin(), d.end(), is_control);
  return it == d.end() ? std::string::npos : std::size_t(it - d.begin());
}

// The text starts with "solid" (any case, after a byte order mark and white space) and has a
// "facet" before byte `end`: an ASCII STL, not a binary one whose header says "solid".
bool starts_like_ascii_stl(const std::string& d, std::size_t end) {
  std::string head = d.substr(0, std::min(end, d.size()));
  std::transform(head.begin(), head.end(), head.begin(), [](unsigned char ch) { return std::tolower(ch); });
  const std::size_t p = head.find_first_not_of(" \t\r\n", has_bom(head) ? 3 : 0);
  return p != std::string::npos && head.compare(p, 5, "solid") == 0 && head.find("facet", p + 5) != std::string::npos;
}

// Where the text of an ASCII STL ends: the whole file, or, when only control bytes follow
// its "endsolid" (from byte `control` on: a DOS end-of-file mark Ctrl-Z, NUL padding), the
// byte before them. npos when the control bytes are inside the text: not an ASCII STL.
// Such a file was read as binary and refused as a size mismatch of 1818521189 triangles.
std::size_t ascii_stl_end(const std::string& d, std::size_t control) {
  if (control == std::string::npos) return d.size();
  for (std::size_t i = control; i < d.size(); ++i)
    if (!is_control(d[i]) && !std::isspace(static_cast<unsigned char>(d[i]))) return std::string::npos;
  if (!starts_like_ascii_stl(d, control)) return std::string::npos;
  std::string tail = d.substr(0, control);
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return tail.rfind("endsolid") != std::string::npos ? control : std::string::npos;
}

}  // namespace

SurfaceMesh parse_stl(const std::string& data, const std::string& name) {
  // STL stores triangle soup; vertices are merged by exact coordinates.
  std::vector<double> soup;
  // A binary STL is its 84-byte header and 50 bytes per declared triangle. Some exporters
  // pad the file (a line break, alignment bytes): less than one record after the last
  // triangle is accepted and ignored. No ASCII STL can pass for one: its bytes 80-83, read as
  // a count, exceed 10^8 triangles, beyond the 512 MiB a surface file may have.
  const bool binary_size_ok = data.size() >= 84 && [&] {
    std::uint32_t n;
    std::memcpy(&n, data.data() + 80, 4);
    const std::uint64_t need = std::uint64_t(n) * 50 + 84;
    return data.size() >= need && data.size() - need < 50;
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
    // Binary-looking data (control bytes other than line breaks and tabs) of 84 bytes or more: a
    // binary STL whose size does not match its triangle count (its header may well start
    // with "solid").
    std::uint32_t declared = 0;
    if (data.size() >= 84) std::memcpy(&declared, data.data() + 80, 4);
    const auto size_mismatch = [&] {
      const std::uint64_t need = 84 + 50 * std::uint64_t(declared);
      return InputError(name + ": binary STL whose size does not match its triangle count: " + std::to_string(data.size()) +
                        " bytes, but the header declares " + std::to_string(declared) + " triangles (" + std::to_string(need) +
                        " bytes); " +
                        (data.size() < need ? "the file is truncated or its count wrong"
                                            : "more than one record's worth of bytes follows them: the count is wrong or the file corrupt"));
    };
    const std::size_t control = first_control_byte(data);
    const std::size_t text_end = ascii_stl_end(data, control);
    const bool looks_binary = data.size() >= 84 && control != std::string::npos && text_end == std::string::npos;
    if (looks_binary && starts_like_ascii_stl(data, control)) {
      std::ostringstream o;  // a text STL with a stray byte, most likely: say so, and where
      o << name << ":" << 1 + std::count(data.begin(), data.begin() + long(control), '\n')
        << ": starts like an ASCII STL ('solid', then facets), but byte " << control << " is a control byte (0x" << std::hex
        << std::setw(2) << std::setfill('0') << int(static_cast<unsigned char>(data[control]))
        << "), which text does not have; read as a binary STL its size does not match its triangle count";
      throw InputError(o.str());
    }
    if (looks_binary) throw size_mismatch();
    const std::string text = data.substr(0, text_end);  // without trailing control bytes
    std::istringstream lines(has_bom(text) ? text.substr(3) : text);
    std::string line, tok;
    int lineno = 0;
    bool started = false;
    int in_facet = 0;
    while (std::getline(lines, line)) {
      ++lineno;
      std::istringstream in(line);
      bool in_name = false;  // after 'solid': its name, up to the first facet on that line
      while (in >> tok) {
        // Keywords in any case: some CAD exporters write SOLID / FACET / VERTEX.
        std::transform(tok.begin(), tok.end(), tok.begin(), [](unsigned char ch) { return std::tolower(ch); });
        if (!started) {
          if (tok != "solid") {
            throw InputError(name + ":" + std::to_string(lineno) +
                             ": neither binary STL (size does not match the triangle count) nor ASCII STL ('solid' missing)");
          }
          started = in_name = true;
          continue;
        }
        // A whole STL on one line (valid: the format is whitespace-separated) was read as
        // one long name and called empty.
        if (in_name && tok != "facet" && tok != "endsolid") continue;
        in_name = false;
        if (tok == "vertex") {
          std::string a, b, c;
          if (!(in >> a >> b >> c)) throw InputError(name + ":" + std::to_string(lineno) + ": vertex needs 3 coordinates");
          soup.insert(soup.end(), {to_number(a, name, lineno), to_number(b, name, lineno), to_number(c, name, lineno)});
          ++in_facet;
        } else if (tok == "endfacet") {
          if (in_facet != 3) throw InputError(name + ":" + std::to_string(lineno) + ": a facet does not have exactly 3 vertices");
          in_facet = 0;
        }
        if (soup.size() > 9 * kMaxElements) throw InputError(name + ": too large");
      }
    }
    if (!started) {
      throw InputError(name + ": neither binary STL (size does not match the triangle count) nor ASCII STL ('solid' missing)");
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
  drop_unused_vertices(s);
  return s;
}

void check_input_size(const std::string& name, std::uint64_t size, std::uint64_t max_bytes) {
  if (size > max_bytes)
    throw InputError(name + ": " + std::to_string(size) + " bytes, above the limit of " + std::to_string(max_bytes) +
                     " bytes for input files");
}

std::string read_input_file(const std::string& path, std::uint64_t max_bytes, bool check_only) {
  check_no_nul(path, "");
  auto os_error = [&](const char* what) { return InputError(path + ": " + what + ": " + std::strerror(errno)); };
  auto kind = [](mode_t m) {
    return S_ISDIR(m) ? "a directory" : S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device"
         : S_ISBLK(m) ? "a block device" : S_ISSOCK(m) ? "a socket" : "not a plain file";
  };
  auto check = [&](const struct stat& st) {
    if (!S_ISREG(st.st_mode)) throw InputError(path + ": not a regular file (" + kind(st.st_mode) + ")");
    check_input_size(path, std::uint64_t(st.st_size), max_bytes);
  };
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw os_error("cannot open file");
  if (check_only) {
    if (!S_ISREG(st.st_mode)) throw InputError(path + ": not a regular file (" + kind(st.st_mode) + ")");
    return {};
  }
  check(st);  // before opening: opening a FIFO blocks until a writer comes
  // O_NONBLOCK: should the path have become a FIFO since stat, open still returns.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw os_error("cannot open file");
  std::string data;
  try {
    if (::fstat(fd, &st) != 0) throw os_error("cannot open file");
    check(st);
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) throw os_error("cannot open file");
    data.reserve(std::size_t(st.st_size) + 1);
    std::vector<char> buf(1 << 16);
    for (;;) {
      const ssize_t r = ::read(fd, buf.data(), buf.size());
      if (r < 0) {
        if (errno == EINTR) continue;
        throw os_error("read error");
      }
      if (r == 0) break;
      if (std::uint64_t(data.size()) + std::uint64_t(r) > max_bytes)  // it grew since fstat
        throw InputError(path + ": above the limit of " + std::to_string(max_bytes) + " bytes for input files");
      data.append(buf.data(), std::size_t(r));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return data;
}

bool has_bom(const std::string& d) { return d.size() >= 3 && d.compare(0, 3, "\xEF\xBB\xBF") == 0; }

std::string lower_ext(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

SurfaceMesh load_surface(const std::string& path, std::uint64_t max_bytes) {
  const std::string ext = lower_ext(path);
  const bool known = ext == "obj" || ext == "off" || ext == "stl";
  // What the path is comes first (a directory or device is named as such), then the format.
  const std::string data = read_input_file(path, known ? max_bytes : 0, !known);
  if (!known)
    throw InputError(path + (ext.empty() ? ": no file extension" : ": unknown surface format '." + ext + "'") +
                     " (use .obj, .off or .stl)");
  if (ext == "obj") return parse_obj(data, path);
  if (ext == "off") return parse_off(data, path);
  return parse_stl(data, path);
}

void write_obj(const SurfaceMesh& s, const std::string& path) {
  std::ostringstream o;
  o.precision(17);
  for (int i = 0; i < s.npoint(); ++i) o << "v " << s.xyz[3 * i] << ' ' << s.xyz[3 * i + 1] << ' ' << s.xyz[3 * i + 2] << '\n';
  for (int t = 0; t < s.ntri(); ++t) o << "f " << s.tri[3 * t] + 1 << ' ' << s.tri[3 * t + 1] + 1 << ' ' << s.tri[3 * t + 2] + 1 << '\n';
  write_file_atomic(path, o.str());  // every write checked: ResourceError naming the file and the OS reason
}

}  // namespace softtled
