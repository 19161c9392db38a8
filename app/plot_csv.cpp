#include "app/plot_csv.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "sim/core/input_error.h"
#include "sim/mesh/surface_io.h"

namespace softtled {

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) {
      if (!bad[i].empty()) throw InputError(bad[i]);
      return &cols[i];
    }
  return nullptr;
}

namespace {
// Decimal number syntax: [+-] digits [. digits] [(e|E) [+-] digits], at least one digit
// before the exponent. Refuses what strtod would also take: hex, inf, nan, spaces inside.
bool is_decimal(const std::string& s) {
  std::size_t i = 0, n = s.size();
  auto digits = [&] {
    const std::size_t b = i;
    while (i < n && s[i] >= '0' && s[i] <= '9') ++i;
    return i - b;
  };
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  std::size_t mant = digits();
  if (i < n && s[i] == '.') {
    ++i;
    mant += digits();
  }
  if (mant == 0) return false;
  if (i < n && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
    if (digits() == 0) return false;
  }
  return i == n;
}

std::string trim(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

std::string shown(const std::string& cell) {  // a cell as quoted in a message
  std::string r;
  for (char c : cell.substr(0, 40)) r += (c == '\0' ? std::string("\\0") : std::string(1, c));
  return cell.size() > 40 ? r + "..." : r;
}
}  // namespace

CsvTable parse_csv_table(const std::string& text_in, const std::string& path) {
  std::string_view text(text_in);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  CsvTable t;
  long lineno = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string line(text.substr(pos, nl - pos));
    pos = nl + 1;
    ++lineno;
    const std::string where = path + ":" + std::to_string(lineno);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find('\0') != std::string::npos)
      throw InputError(where + ": a NUL byte at column " + std::to_string(line.find('\0') + 1) + " (not a text CSV)");
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::size_t b = 0;
    for (;;) {
      const std::size_t c = line.find(',', b);
      cells.push_back(line.substr(b, c == std::string::npos ? std::string::npos : c - b));
      if (c == std::string::npos) break;
      b = c + 1;
    }
    if (t.names.empty()) {
      for (std::string& c : cells) c = trim(c);
      for (std::size_t c = 0; c < cells.size(); ++c)  // which one would be plotted?
        for (std::size_t d = 0; d < c; ++d)
          if (cells[c] == cells[d]) throw InputError(where + ": column '" + shown(cells[c]) + "' appears twice in the header");
      t.names = cells;
      t.cols.resize(cells.size());
      t.bad.resize(cells.size());
      continue;
    }
    if (cells.size() != t.names.size())
      throw InputError(where + ": " + std::to_string(cells.size()) + " values, the header has " + std::to_string(t.names.size()));
    const std::string row = std::to_string(t.cols[0].size() + 1);
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string cell = trim(cells[c]);
      const std::string at = where + " (row " + row + "): column " + t.names[c] + ": '" + shown(cells[c]) + "' ";
      const double v = is_decimal(cell) ? std::strtod(cell.c_str(), nullptr) : NAN;
      if (t.bad[c].empty() && !is_decimal(cell)) t.bad[c] = at + "is not a decimal number";
      if (t.bad[c].empty() && !(std::fabs(v) <= kMaxPlotValue)) t.bad[c] = at + "is not a finite number of magnitude at most 1e30";
      t.cols[c].push_back(v);
    }
  }
  if (t.names.empty()) throw InputError(path + ": empty file (expected a header row: softtled run --csv)");
  return t;
}

bool parse_wxh_size(const std::string& s, int lo, int hi, int& w, int& h) {
  const std::size_t x = s.find('x');
  if (x == std::string::npos) return false;
  auto side = [&](const std::string& d, int& v) {
    if (d.empty() || d.size() > 9) return false;  // 9 digits cannot overflow an int
    for (char c : d)
      if (c < '0' || c > '9') return false;
    const long n = std::stol(d);
    if (n < lo || n > hi) return false;
    v = int(n);
    return true;
  };
  int a = 0, b = 0;
  if (!side(s.substr(0, x), a) || !side(s.substr(x + 1), b)) return false;
  w = a, h = b;
  return true;
}

CsvTable read_csv_table(const std::string& path, std::uint64_t max_bytes) {
  return parse_csv_table(read_input_file(path, max_bytes), path);
}

std::vector<PlotPanel> run_plot_panels(const CsvTable& table, const std::string& title) {
  auto need = [&](const char* name) -> const std::vector<double>& {
    const std::vector<double>* c = table.column(name);
    if (!c) throw InputError(std::string("the CSV has no column '") + name + "' (expected softtled run --csv output)");
    return *c;
  };
  const std::vector<double>&t = need("t"), &cy = need("cy"), &ke = need("ke"), &se = need("se"), &pe = need("pe");
  if (t.empty()) throw InputError("the CSV has a header but no rows");
  // A run's rows in time order: the energy is drawn from the first row's potential, and
  // the curves join the rows in file order.
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1]))
      throw InputError("the CSV's times do not increase: row " + std::to_string(i + 1) + " has t = " + std::to_string(t[i]) +
                       " after " + std::to_string(t[i - 1]) + " (expected softtled run --csv output)");
  std::vector<double> h(cy.size()), k(t.size()), s(t.size()), p(t.size()), sum(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    h[i] = cy[i] * 1e3;
    k[i] = ke[i] * 1e6, s[i] = se[i] * 1e6, p[i] = (pe[i] - pe[0]) * 1e6;
    sum[i] = k[i] + s[i] + p[i];
  }
  PlotPanel a;
  a.title = (title.empty() ? "" : title + ": ") + "centroid height cy [mm]";
  a.xlabel = "t [s]";
  a.series.push_back({"cy", t, h, Vec3{0.12f, 0.35f, 0.75f}});
  PlotPanel b;
  b.title = "energy [uJ]";
  b.xlabel = "t [s]";
  b.series.push_back({"kinetic ke", t, k, Vec3{0.85f, 0.25f, 0.20f}});
  b.series.push_back({"strain se", t, s, Vec3{0.15f, 0.60f, 0.25f}});
  b.series.push_back({"gravity pe - pe(0)", t, p, Vec3{0.20f, 0.40f, 0.85f}});
  b.series.push_back({"sum", t, sum, Vec3{0.25f, 0.25f, 0.28f}});
  return {a, b};
}

}  // namespace softtled
