// VTK XML UnstructuredGrid (.vtu) reader: one Piece, Points and the Cells arrays
// connectivity / offsets / types, in ASCII, inline binary (base64) or appended data (raw or
// base64), uncompressed. VTK_TETRA (10) cells are kept, other cell types counted. Other
// arrays (PointData, CellData: what `softtled mesh --vtu` and `run --vtu` add) are ignored,
// and so are XML comments; CDATA sections are read as their text.
#include <algorithm>
#include <cstring>
#include <string_view>
#include <type_traits>

#include "sim/mesh/tet_io.h"
#include "sim/mesh/tet_io_cursor.h"

namespace softtled {
namespace {

using tet_io::Cursor;

struct Xml {
  const std::string& d;
  const std::string& name;
  std::size_t xml_end;  // where <AppendedData>'s raw bytes may begin: tags are searched before it

  [[noreturn]] void fail(const std::string& what) const { throw InputError(name + ": " + what); }

  // The start tag "<tag ...>" at or after `from` (before `limit`), as [begin, end) of its text.
  bool find_tag(const std::string& tag, std::size_t from, std::size_t limit, std::size_t& b, std::size_t& e) const {
    const std::string open = "<" + tag;
    for (std::size_t p = d.find(open, from); p != std::string::npos && p < limit; p = d.find(open, p + 1)) {
      const std::size_t q = p + open.size();
      if (q < d.size() && (Cursor::space(d[q]) || d[q] == '>' || d[q] == '/')) {
        const std::size_t close = d.find('>', q);
        if (close == std::string::npos || close >= std::max(limit, xml_end)) fail("<" + tag + "> is not closed (truncated file?)");
        b = p, e = close + 1;
        return true;
      }
    }
    return false;
  }
  std::size_t find_end(const std::string& tag, std::size_t from) const {
    const std::size_t p = d.find("</" + tag, from);
    if (p == std::string::npos || p > xml_end) fail("</" + tag + "> missing (truncated file?)");
    return p;
  }
  // Attribute `key` of the tag text [b, e); false when absent.
  bool attr(std::size_t b, std::size_t e, const std::string& key, std::string& out) const {
    const std::string_view tag(d.data() + b, e - b);
    for (std::size_t p = tag.find(key); p != std::string_view::npos; p = tag.find(key, p + 1)) {
      if (p == 0 || !Cursor::space(tag[p - 1])) continue;
      std::size_t q = p + key.size();
      while (q < tag.size() && Cursor::space(tag[q])) ++q;
      if (q >= tag.size() || tag[q] != '=') continue;
      ++q;
      while (q < tag.size() && Cursor::space(tag[q])) ++q;
      if (q >= tag.size() || (tag[q] != '"' && tag[q] != '\'')) fail("attribute " + key + " without a quoted value");
      const std::size_t r = tag.find(tag[q], q + 1);
      if (r == std::string_view::npos) fail("attribute " + key + " not closed");
      out = std::string(tag.substr(q + 1, r - q - 1));
      return true;
    }
    return false;
  }
  long long int_attr(std::size_t b, std::size_t e, const std::string& key, long long lo, long long hi) const {
    std::string v;
    if (!attr(b, e, key, v)) fail("<" + std::string(d.substr(b + 1, std::min<std::size_t>(e - b - 1, 20))) + "...>: attribute " + key + " missing");
    long long x = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
    if (r.ec != std::errc() || r.ptr != v.data() + v.size() || x < lo || x > hi)
      fail("attribute " + key + "=\"" + v.substr(0, 30) + "\" is not an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
    return x;
  }
};

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// Decodes base64 text (white space skipped; '=' padding ends a block, and another block may
// follow, as VTK writes the header and the data as two blocks).
std::string base64_decode(std::string_view s, const Xml& x) {
  std::string out;
  out.reserve(s.size() / 4 * 3);
  unsigned buf = 0;
  int bits = 0, quad = 0;
  for (char c : s) {
    if (Cursor::space(c)) continue;
    if (c == '=') {
      ++quad;
      if (quad == 4) quad = 0, buf = 0, bits = 0;  // end of a padded block
      continue;
    }
    const int v = base64_value(c);
    if (v < 0) x.fail("binary data: '" + std::string(1, c) + "' is not a base64 character");
    buf = (buf << 6) | unsigned(v);
    bits += 6;
    quad = (quad + 1) % 4;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(char((buf >> bits) & 0xff));
    }
  }
  return out;
}

struct Array {
  std::string type, format, name;
  long long components = 1, offset = -1;
  std::size_t content_b = 0, content_e = 0;  // inline text
};

class VtuReader {
 public:
  VtuReader(const std::string& data, const std::string& name, long max_tets)
      : x_{data, name, data.size()}, max_tets_(max_tets) {}

  TetSoup read() {
    const std::string& d = x_.d;
    std::size_t b = 0, e = 0;
    {  // appended data first: tags are looked for only before it
      std::size_t ab = 0, ae = 0;
      if (x_.find_tag("AppendedData", 0, d.size(), ab, ae)) {
        x_.xml_end = ab;
        std::string enc = "raw";
        x_.attr(ab, ae, "encoding", enc);
        if (enc != "raw" && enc != "base64") x_.fail("AppendedData encoding '" + enc + "' (raw or base64 expected)");
        appended_base64_ = enc == "base64";
        const std::size_t u = d.find('_', ae);
        if (u == std::string::npos) x_.fail("AppendedData without the '_' that starts it (truncated file?)");
        appended_ = u + 1;
        has_appended_ = true;
      }
    }
    if (!x_.find_tag("VTKFile", 0, x_.xml_end, b, e)) x_.fail("not a VTK XML file (<VTKFile> missing)");
    std::string v;
    if (!x_.attr(b, e, "type", v) || v != "UnstructuredGrid")
      x_.fail("VTKFile type '" + v + "': only UnstructuredGrid (.vtu) is supported");
    if (x_.attr(b, e, "compressor", v) && !v.empty())
      x_.fail("compressed data (" + v + ") is not supported: save the .vtu uncompressed");
    if (x_.attr(b, e, "byte_order", v) && v != "LittleEndian") {
      if (v != "BigEndian") x_.fail("byte_order '" + v + "' (LittleEndian or BigEndian expected)");
      big_endian_ = true;
    }
    if (x_.attr(b, e, "header_type", v)) {
      if (v == "UInt64") header_bytes_ = 8;
      else if (v != "UInt32") x_.fail("header_type '" + v + "' (UInt32 or UInt64 expected)");
    }
    std::size_t pb = 0, pe = 0;
    if (!x_.find_tag("Piece", e, x_.xml_end, pb, pe)) x_.fail("no <Piece>");
    const long long npoint = x_.int_attr(pb, pe, "NumberOfPoints", 0, kMaxTetFileCount);
    const long long ncell = x_.int_attr(pb, pe, "NumberOfCells", 0, 4 * (long long)kMaxTetFileCount);
    std::size_t qb = 0, qe = 0;
    if (x_.find_tag("Piece", pe, x_.xml_end, qb, qe)) x_.fail("more than one <Piece> (only one is supported)");
    // Points: the first DataArray inside <Points>.
    std::size_t sb = 0, se = 0;
    if (!x_.find_tag("Points", pe, x_.xml_end, sb, se)) x_.fail("no <Points>");
    const std::size_t points_end = x_.find_end("Points", se);
    std::size_t ab = 0, ae = 0;
    if (!x_.find_tag("DataArray", se, points_end, ab, ae)) x_.fail("<Points> without a DataArray");
    const Array pa = array(ab, ae);
    if (pa.components != 3) x_.fail("Points have " + std::to_string(pa.components) + " components (3 expected)");
    TetSoup soup;
    soup.tet_numbering = "VTK cell";  // the cell's index among all cells, what ParaView shows
    soup.X = values<double>(pa, 3 * npoint, "Points");
    // Cells: connectivity, offsets, types by name.
    if (!x_.find_tag("Cells", pe, x_.xml_end, sb, se)) x_.fail("no <Cells>");
    const std::size_t cells_end = x_.find_end("Cells", se);
    Array cell_arrays[3];  // connectivity, offsets, types
    const char* cell_names[3] = {"connectivity", "offsets", "types"};
    bool has[3] = {false, false, false};
    for (std::size_t p = se; x_.find_tag("DataArray", p, cells_end, ab, ae); p = ae) {
      const Array a = array(ab, ae);
      for (int k = 0; k < 3; ++k)
        if (a.name == cell_names[k]) {
          // Which one a reader takes is not said anywhere: the later one was used silently.
          if (has[k]) x_.fail("<Cells> has two DataArrays named '" + a.name + "' (one is expected)");
          cell_arrays[k] = a, has[k] = true;
        }
    }
    if (!has[0] || !has[1] || !has[2]) x_.fail("<Cells> needs the DataArrays connectivity, offsets and types");
    const Array &conn = cell_arrays[0], &offs = cell_arrays[1], &types = cell_arrays[2];
    const std::vector<long long> ty = values<long long>(types, ncell, "types");
    std::vector<long long> off = values<long long>(offs, -1, "offsets");
    if (off.size() == std::size_t(ncell) + 1 && !off.empty() && off[0] == 0) off.erase(off.begin());  // VTK 9's layout
    if (off.size() != std::size_t(ncell))
      x_.fail("offsets has " + std::to_string(off.size()) + " values for " + std::to_string(ncell) + " cells");
    const std::vector<long long> cn = values<long long>(conn, ncell > 0 ? off.back() : 0, "connectivity");
    long long prev = 0;
    for (long long c = 0; c < ncell; ++c) {
      const long long end = off[std::size_t(c)];
      if (end < prev || end > (long long)cn.size())
        x_.fail("cell " + std::to_string(c) + ": offset " + std::to_string(end) + " out of order or past the connectivity");
      if (ty[std::size_t(c)] == 10) {
        if (end - prev != 4) x_.fail("cell " + std::to_string(c) + ": a VTK_TETRA with " + std::to_string(end - prev) + " nodes");
        if (long(soup.tet.size() / 4) >= max_tets_)
          x_.fail("more than " + std::to_string(max_tets_) + " tets (the tet budget, mesh.max_tets)");
        for (long long k = prev; k < end; ++k) {
          const long long n = cn[std::size_t(k)];
          if (n < 0 || n >= npoint)
            x_.fail("cell " + std::to_string(c) + " refers to point " + std::to_string(n) + " of " + std::to_string(npoint));
          soup.tet.push_back(int(n));
        }
        soup.tet_number.push_back(c);
      } else {
        // Skipped, but not unread: a cell of a fixed-size type with another node count, or
        // on a point the file does not have, is corruption (a 4-node "wedge" was skipped
        // with a note, and the mesh accepted with a part missing).
        const long long t = ty[std::size_t(c)], k = fixed_nodes(t);
        if (k > 0 && end - prev != k)
          x_.fail("cell " + std::to_string(c) + ": a " + kind(t) + " with " + std::to_string(end - prev) + " nodes (" +
                  std::to_string(k) + " expected)");
        for (long long j = prev; j < end; ++j)
          if (cn[std::size_t(j)] < 0 || cn[std::size_t(j)] >= npoint)
            x_.fail("cell " + std::to_string(c) + " (" + kind(t) + ") refers to point " + std::to_string(cn[std::size_t(j)]) +
                    " of " + std::to_string(npoint));
        ++soup.skipped[kind(t)];
      }
      prev = end;
    }
    return soup;
  }

 private:
  // Nodes of VTK's fixed-size linear and quadratic cell types (vtkCellType.h); 0 for the
  // others (poly-vertex, polyline, strip, polygon, polyhedron, higher order: any count).
  static long long fixed_nodes(long long t) {
    switch (t) {
      case 1: return 1;
      case 3: return 2;
      case 5: return 3;
      case 8: case 9: case 10: return 4;
      case 11: case 12: return 8;
      case 13: return 6;
      case 14: return 5;
      case 21: return 3;
      case 22: return 6;
      case 23: return 8;
      case 24: return 10;
      case 25: return 20;
      default: return 0;
    }
  }
  static std::string kind(long long t) {
    switch (t) {
      case 1: return "vertex";
      case 3: return "line";
      case 5: return "triangle";
      case 9: return "quad";
      case 12: return "hexahedron";
      case 13: return "wedge";
      case 14: return "pyramid";
      case 24: return "quadratic tetra";
      default: return "VTK cell type " + std::to_string(t);
    }
  }

  Array array(std::size_t b, std::size_t e) {
    Array a;
    if (!x_.attr(b, e, "type", a.type)) x_.fail("DataArray without a type");
    x_.attr(b, e, "Name", a.name);
    if (!x_.attr(b, e, "format", a.format)) a.format = "ascii";
    std::string nc;
    if (x_.attr(b, e, "NumberOfComponents", nc)) a.components = x_.int_attr(b, e, "NumberOfComponents", 1, 1000);
    if (a.format == "appended") {
      if (!has_appended_) x_.fail("DataArray '" + a.name + "' is appended but there is no <AppendedData>");
      a.offset = x_.int_attr(b, e, "offset", 0, (long long)x_.d.size());
    } else if (a.format == "ascii" || a.format == "binary") {
      if (x_.d[e - 2] == '/') x_.fail("DataArray '" + a.name + "' has no content");
      a.content_b = e;
      a.content_e = x_.find_end("DataArray", e);
    } else {
      x_.fail("DataArray '" + a.name + "': format '" + a.format + "' (ascii, binary or appended expected)");
    }
    return a;
  }

  static int type_bytes(const std::string& t) {
    if (t == "Int8" || t == "UInt8") return 1;
    if (t == "Int16" || t == "UInt16") return 2;
    if (t == "Int32" || t == "UInt32" || t == "Float32") return 4;
    if (t == "Int64" || t == "UInt64" || t == "Float64") return 8;
    return 0;
  }

  // The array's values as T; count < 0: as many as there are (ASCII) or as the byte count says.
  template <class T>
  std::vector<T> values(const Array& a, long long count, const char* what) {
    const int tb = type_bytes(a.type);
    if (tb == 0) x_.fail(std::string(what) + ": DataArray type '" + a.type + "' is not supported");
    const bool floating = a.type[0] == 'F';
    if (!std::is_floating_point<T>::value && floating) x_.fail(std::string(what) + ": integers expected, not " + a.type);
    std::vector<T> out;
    if (a.format == "ascii") {
      Cursor c(x_.d, x_.name, a.content_b, a.content_e);
      long long lo = INT64_MIN, hi = INT64_MAX;
      int_range(a.type, lo, hi);
      const std::string what_type = std::string(what) + " (" + a.type + ")";
      if (count >= 0) {
        tet_io::check_count(c, count, 4 * (long long)kMaxTetFileCount, 2, what);
        out.reserve(std::size_t(count));
      }
      while (c.more()) {
        if (count >= 0 && (long long)out.size() == count) c.fail(std::string(what) + ": more than " + std::to_string(count) + " values");
        if (std::is_floating_point<T>::value) out.push_back(T(c.number(what)));
        else out.push_back(T(c.integer(lo, hi, what_type)));
        if ((long long)out.size() > 4 * (long long)kMaxTetFileCount) c.fail(std::string(what) + ": too many values");
      }
    } else {
      if (big_endian_) x_.fail("big-endian binary data is not supported");
      std::string bytes = binary_block(a, what);
      if (bytes.size() % std::size_t(tb) != 0) x_.fail(std::string(what) + ": " + std::to_string(bytes.size()) + " bytes is not a whole number of " + a.type);
      const std::size_t n = bytes.size() / std::size_t(tb);
      out.resize(n);
      for (std::size_t i = 0; i < n; ++i) out[i] = convert<T>(a.type, bytes.data() + i * std::size_t(tb));
    }
    if (count >= 0 && (long long)out.size() != count)
      x_.fail(std::string(what) + ": " + std::to_string(out.size()) + " values, " + std::to_string(count) + " expected");
    return out;
  }

  // The values of an integer DataArray type: an ASCII value outside them is not of the
  // declared type (types 266 declared UInt8 was skipped as "VTK cell type 266"; a binary
  // UInt8 cannot hold it). UInt64 stops at INT64_MAX, far above any count or index.
  static void int_range(const std::string& t, long long& lo, long long& hi) {
    if (t == "Int8") lo = INT8_MIN, hi = INT8_MAX;
    else if (t == "UInt8") lo = 0, hi = UINT8_MAX;
    else if (t == "Int16") lo = INT16_MIN, hi = INT16_MAX;
    else if (t == "UInt16") lo = 0, hi = UINT16_MAX;
    else if (t == "Int32") lo = INT32_MIN, hi = INT32_MAX;
    else if (t == "UInt32") lo = 0, hi = UINT32_MAX;
    else if (t == "UInt64") lo = 0;
  }

  template <class T>
  static T convert(const std::string& t, const char* p) {
#define SOFTTLED_VTU_AS(NAME, C) \
  if (t == NAME) {               \
    C v;                         \
    std::memcpy(&v, p, sizeof v); \
    return T(v);                 \
  }
    SOFTTLED_VTU_AS("Float64", double)
    SOFTTLED_VTU_AS("Float32", float)
    SOFTTLED_VTU_AS("Int8", std::int8_t)
    SOFTTLED_VTU_AS("UInt8", std::uint8_t)
    SOFTTLED_VTU_AS("Int16", std::int16_t)
    SOFTTLED_VTU_AS("UInt16", std::uint16_t)
    SOFTTLED_VTU_AS("Int32", std::int32_t)
    SOFTTLED_VTU_AS("UInt32", std::uint32_t)
    SOFTTLED_VTU_AS("Int64", std::int64_t)
    if (t == "UInt64") {
      std::uint64_t v;
      std::memcpy(&v, p, sizeof v);
      return T(v > std::uint64_t(INT64_MAX) ? INT64_MAX : (long long)v);  // out of range anyway
    }
#undef SOFTTLED_VTU_AS
    return T(0);
  }

  std::uint64_t read_header(const char* p) const {
    if (header_bytes_ == 4) {
      std::uint32_t n;
      std::memcpy(&n, p, 4);
      return n;
    }
    std::uint64_t n;
    std::memcpy(&n, p, 8);
    return n;
  }

  // The bytes of a binary or appended array: a header (the byte count) then the data.
  std::string binary_block(const Array& a, const char* what) {
    const std::string& d = x_.d;
    const std::size_t hb = header_bytes_;
    std::string_view text;
    if (a.format == "appended" && !appended_base64_) {
      const std::size_t p = appended_ + std::size_t(a.offset);
      if (p > d.size() || d.size() - p < hb) x_.fail(std::string(what) + ": appended data ends early (truncated file?)");
      const std::uint64_t n = read_header(d.data() + p);
      if (n > d.size() - p - hb) x_.fail(std::string(what) + ": appended data ends early (" + std::to_string(n) + " bytes declared)");
      return d.substr(p + hb, std::size_t(n));
    }
    if (a.format == "appended") {
      const std::size_t p = appended_ + std::size_t(a.offset);
      if (p > d.size()) x_.fail(std::string(what) + ": appended offset past the end of the file");
      std::size_t q = p;
      while (q < d.size() && (base64_value(d[q]) >= 0 || d[q] == '=')) ++q;
      text = std::string_view(d.data() + p, q - p);
    } else {
      text = std::string_view(d.data() + a.content_b, a.content_e - a.content_b);
    }
    // White space stripped, decoded whole: the header and the data are either one base64
    // stream or two (the header padded to a block of its own, as VTK writes them), and the
    // decoder starts afresh after padding, so both read alike. Telling them apart by a '='
    // where a separate header's padding would be took a 1-byte array's own padding
    // ("AQAAAAo=": 4 header bytes and 0x0a) for a header block and read no data.
    std::string s;
    s.reserve(text.size());
    for (char c : text)
      if (!Cursor::space(c)) s.push_back(c);
    std::string data = base64_decode(s, x_);
    if (data.size() < hb) x_.fail(std::string(what) + ": binary data shorter than its header");
    const std::uint64_t n = read_header(data.data());
    data.erase(0, hb);
    if (n > data.size()) x_.fail(std::string(what) + ": binary data ends early (" + std::to_string(n) + " bytes declared, " +
                                 std::to_string(data.size()) + " present)");
    data.resize(std::size_t(n));
    return data;
  }

  Xml x_;
  long max_tets_;
  bool has_appended_ = false, appended_base64_ = false, big_endian_ = false;
  std::size_t appended_ = 0;
  std::size_t header_bytes_ = 4;
};

// The markup that is not the document's: XML comments (<!-- -->) blanked, and CDATA
// sections (<![CDATA[ ]]>) unwrapped to their text, up to the appended data's raw bytes
// (which may hold any bytes). Blanked with spaces, so every offset stays where it was. A
// tag or an array inside a comment was once read as the mesh's (an old <Points> kept in
// a comment replaced the real one). False when there is none (no copy made).
bool blank_markup(const std::string& d, const std::string& name, std::string& out) {
  std::size_t p = 0;
  bool copied = false;
  const auto blank = [&](std::size_t b, std::size_t e) {
    if (!copied) out = d, copied = true;
    for (std::size_t i = b; i < e; ++i)
      if (out[i] != '\n') out[i] = ' ';
  };
  while ((p = d.find('<', p)) != std::string::npos) {
    if (d.compare(p, 4, "<!--") == 0) {
      const std::size_t e = d.find("-->", p + 4);
      if (e == std::string::npos) throw InputError(name + ": an XML comment (<!--) is not closed (truncated file?)");
      blank(p, e + 3);
      p = e + 3;
    } else if (d.compare(p, 9, "<![CDATA[") == 0) {
      const std::size_t e = d.find("]]>", p + 9);
      if (e == std::string::npos) throw InputError(name + ": a CDATA section (<![CDATA[) is not closed (truncated file?)");
      blank(p, p + 9);
      blank(e, e + 3);
      p = e + 3;
    } else if (d.compare(p, 13, "<AppendedData") == 0) {
      break;  // raw bytes follow: not markup
    } else {
      ++p;
    }
  }
  return copied;
}

}  // namespace

TetSoup parse_vtu(const std::string& data, const std::string& name, long max_tets) {
  std::string blanked;
  return VtuReader(blank_markup(data, name, blanked) ? blanked : data, name, max_tets).read();
}

}  // namespace softtled
