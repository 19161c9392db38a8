#include "sim/scene/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

#include <toml++/toml.h>

#include "sim/mesh/surface_io.h"
#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_io.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/core/exact_number.h"
#include "sim/scene/scene_geometry.h"

namespace softtled {
namespace {

// One table per named mode: the names parse_scene accepts and *_name() returns.
template <class E>
using Names = std::vector<std::pair<const char*, E>>;
const Names<MaterialModel> kMaterialModels = {{"neo_hookean", kTaylorNeoHookean}, {"stable_neo_hookean", kStableNeoHookean}};
const Names<ElementType> kElements = {{"T4", kT4}, {"T4ANP", kT4ANP}};
const Names<ContactMode> kContactModes = {{"sliding", kSliding}, {"static", kStatic}, {"coulomb", kCoulomb}};
const Names<Precision> kPrecisions = {{"float", Precision::kFloat}, {"double", Precision::kDouble}};
const Names<ObstacleShape> kObstacleShapes = {
    {"sphere", kObstacleSphere}, {"box", kObstacleBox}, {"capsule", kObstacleCapsule}, {"mesh", kObstacleMesh}};


template <class E>
const char* name_of(const Names<E>& names, E value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "?";
}

// Reads keys of a table and remembers which were read, so leftovers can be reported.
class Reader {
 public:
  // label: how "body.*" keys are named in messages ("body[1]" for the second [[body]]).
  Reader(const toml::table& root, std::string source, std::string label = "")
      : root_(root), source_(std::move(source)), label_(std::move(label)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& msg) const {
    const std::string shown = !label_.empty() && key.rfind("body.", 0) == 0 ? label_ + key.substr(4) : key;
    throw InputError(source_ + ": " + shown + ": " + msg);
  }
  bool used(const std::string& key) const { return used_.count(key) > 0; }

  // A quoted key with a dot ("time.duration" = 1) is one key named time.duration, not the
  // duration key of [time]: no scene key has a dot in its name, so it is unknown.
  [[noreturn]] void fail_quoted(const std::string& key) const {
    fail(key, "unknown key: a quoted key containing '.' is one key, not a dotted path "
              "(write time.duration = ..., not \"time.duration\" = ...)");
  }

  const toml::node* get(const std::string& key) {
    used_.insert(key);
    return root_.at_path(key).node();
  }

  double num(const std::string& key, double def, double lo = -INFINITY, double hi = INFINITY,
             bool lo_open = false) {
    const toml::node* n = get(key);
    if (!n) return def;
    double v;
    if (auto i = n->as_integer()) v = double(i->get());
    else if (auto f = n->as_floating_point()) v = f->get();
    else fail(key, "expected a number");
    if (!std::isfinite(v)) fail(key, "must be finite, got " + std::to_string(v));
    if (v < lo || (lo_open && v == lo) || v > hi) {
      fail(key, "value " + exact_number(v) + " out of range " + (lo_open ? "(" : "[") + exact_number(lo) + ", " + exact_number(hi) + "]");
    }
    // A quantity that must be positive is never subnormal: it underflows to 0 in the first
    // product (material.rho = 5e-324 gave nodes of no mass, reported as "node 0 belongs to
    // no element").
    if (lo_open && lo == 0 && v < std::numeric_limits<double>::min())
      fail(key, "value " + exact_number(v) + " is subnormal: at least " + exact_number(std::numeric_limits<double>::min()));
    return v;
  }

  int integer(const std::string& key, int def, int lo, int hi) {
    const toml::node* n = get(key);
    if (!n) return def;
    auto i = n->as_integer();
    if (!i) fail(key, "expected an integer");
    if (i->get() < lo || i->get() > hi) fail(key, "value out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return int(i->get());
  }

  bool boolean(const std::string& key, bool def) {
    const toml::node* n = get(key);
    if (!n) return def;
    auto b = n->as_boolean();
    if (!b) fail(key, "expected true or false");
    return b->get();
  }

  std::string str(const std::string& key, const std::string& def, const std::set<std::string>& allowed = {}) {
    const toml::node* n = get(key);
    if (!n) return def;
    auto s = n->as_string();
    if (!s) fail(key, "expected a string");
    if (!allowed.empty() && !allowed.count(s->get())) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(key, quoted(s->get()) + " is not one of: " + list);
    }
    return s->get();
  }

  // A string key that must be one of the names; returns its value.
  template <class E>
  E choice(const std::string& key, E def, const Names<E>& names) {
    std::set<std::string> allowed;
    for (const auto& nv : names) allowed.insert(nv.first);
    const std::string s = str(key, name_of(names, def), allowed);
    for (const auto& [name, v] : names)
      if (s == name) return v;
    return def;
  }

  template <std::size_t N>
  // limit: largest allowed |component| (in the key's own unit).
  std::array<double, N> vec(const std::string& key, std::array<double, N> def, double limit = INFINITY) {
    const toml::node* n = get(key);
    if (!n) return def;
    auto a = n->as_array();
    if (!a || a->size() != N) fail(key, "expected an array of " + std::to_string(N) + " numbers");
    std::array<double, N> r;
    for (std::size_t i = 0; i < N; ++i) {
      const auto v = (*a)[i].value<double>();
      if (!v || !std::isfinite(*v)) fail(key, "element " + std::to_string(i) + " is not a finite number");
      if (std::abs(*v) > limit) {
        fail(key, "element " + std::to_string(i) + " = " + exact_number(*v) + " is out of range [" + exact_number(-limit) + ", " +
                      exact_number(limit) + "]");
      }
      r[i] = *v;
    }
    return r;
  }

  template <std::size_t N>
  std::array<int, N> ivec(const std::string& key, std::array<int, N> def, int lo, int hi) {
    const toml::node* n = get(key);
    if (!n) return def;
    auto a = n->as_array();
    if (!a || a->size() != N) fail(key, "expected an array of " + std::to_string(N) + " integers");
    std::array<int, N> r;
    for (std::size_t i = 0; i < N; ++i) {
      auto v = (*a)[i].as_integer();
      if (!v || v->get() < lo || v->get() > hi) fail(key, "element " + std::to_string(i) + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      r[i] = int(v->get());
    }
    return r;
  }

  // Every leaf key that was not read is an error (typos must not be silently ignored).
  void reject_unknown() const {
    for (const auto& [k, v] : root_) {
      const std::string key(k.str());
      if (key.find('.') != std::string::npos) fail_quoted(key);
      if (key == "body") continue;  // read_bodies checks its own tables
      if (auto t = v.as_table()) {
        for (const auto& [k2, v2] : *t) {
          (void)v2;
          const std::string name(k2.str());
          if (name.find('.') != std::string::npos) fail_quoted(key + ".\"" + name + "\"");
          const std::string full = key + "." + name;
          if (!used_.count(full)) fail(full, "unknown key (see README, 'Scene format')");
        }
      } else if (!used_.count(key)) {
        if (v.is_array_of_tables())
          fail(key, "[[" + key + "]] repeats a table; only [[body]], [[obstacle]] and [[fixed]] may repeat (write [" + key + "])");
        fail(key, "unknown key (see README, 'Scene format')");
      }
    }
  }

 private:
  const toml::table& root_;
  std::string source_;
  std::string label_;
  std::set<std::string> used_;
};

// Dotted keys nest one table per part, and toml++ recurses once per part with no limit of
// its own (its nesting limit counts brackets and braces only): 40000 parts overflow the
// stack. So the text is scanned first, outside strings and comments, for chains of parts
// joined by dots ("a.b.c", "\"x\" . y"), and a chain of more than kMaxDottedParts parts is
// refused, naming the start of the key and its line. A float or time has one dot, a real
// scene key at most four parts (body.material.E); nothing in a value string is counted.
constexpr int kMaxDottedParts = 32;

void check_dotted_keys(const std::string& text, const std::string& where) {
  const std::size_t n = text.size();
  std::size_t i = 0, line = 1, chain_start = 0, chain_line = 1;
  int dots = 0;
  bool in_chain = false;
  auto reset = [&] { in_chain = false, dots = 0; };
  auto touch = [&] {
    if (!in_chain) in_chain = true, dots = 0, chain_start = i, chain_line = line;
  };
  auto bare = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '+'; };
  while (i < n) {
    const char c = text[i];
    if (c == '#') {  // comment: to the end of the line
      while (i < n && text[i] != '\n') ++i;
      reset();
    } else if (c == '\n') {
      ++line, ++i;
      reset();
    } else if (c == ' ' || c == '\t' || c == '\r') {
      ++i;
    } else if (c == '"' || c == '\'') {
      touch();
      const bool multi = i + 2 < n && text[i + 1] == c && text[i + 2] == c;
      i += multi ? 3 : 1;
      while (i < n) {
        if (c == '"' && text[i] == '\\') {
          if (i + 1 < n && text[i + 1] == '\n') ++line;
          i += 2;
          continue;
        }
        if (text[i] == '\n') {
          if (!multi) break;  // an unterminated string: toml++ reports it
          ++line;
        }
        if (text[i] == c && (!multi || (i + 2 < n && text[i + 1] == c && text[i + 2] == c))) {
          i += multi ? 3 : 1;
          if (multi)
            while (i < n && text[i] == c) ++i;  // up to two quotes may end the content
          break;
        }
        ++i;
      }
      if (multi) reset();  // a multi-line string is a value, never a key part
    } else if (c == '.') {
      touch();
      ++i;
      if (++dots + 1 > kMaxDottedParts) {
        std::string shown = text.substr(chain_start, std::min<std::size_t>(40, i - chain_start));
        for (char& ch : shown)
          if (!std::isprint(static_cast<unsigned char>(ch))) ch = '?';
        throw InputError(where + ":" + std::to_string(chain_line) + ": key '" + shown +
                         "...' has more than " + std::to_string(kMaxDottedParts) +
                         " dotted parts (scene keys have at most 4)");
      }
    } else if (bare(c)) {
      touch();
      ++i;
    } else {
      ++i;
      reset();
    }
  }
}

// Scales v to unit length; false for a zero vector. Divides by the largest component first
// so huge values do not overflow when squared (nor tiny ones underflow).
bool normalize(std::array<double, 3>& v) {
  double big = 0;
  for (double x : v) big = std::max(big, std::fabs(x));
  if (!(big > 0)) return false;
  for (double& x : v) x /= big;
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (double& x : v) x /= n;
  return true;
}

// "N.rest" of an indexed --set key (body.N.rest, obstacle.N.rest): N (0-based, at most 3
// digits, no leading zero: one spelling per index) and rest, which must not be empty; form
// is the message for anything else.
std::pair<std::size_t, std::string> split_index(const std::string& kv, const std::string& leaf, const char* form) {
  const auto dot = leaf.find('.');
  const std::string idx = leaf.substr(0, dot);
  const std::string rest = dot == std::string::npos ? "" : leaf.substr(dot + 1);
  if (idx.empty() || idx.size() > 3 || idx.find_first_not_of("0123456789") != std::string::npos || rest.empty() ||
      (idx.size() > 1 && idx[0] == '0'))
    throw InputError("--set " + quoted(kv) + ": " + form);
  return {std::stoul(idx), rest};
}

// The scene's tables: --set sets their keys one by one, never a whole table.
const std::set<std::string> kSections = {"body",    "material", "damping", "gravity", "floor",  "slope", "obstacle",
                                         "contact", "time",     "solver",  "output",  "mesh",   "fixed"};

// A table or an array holding a table: a value only a section takes.
bool is_table_value(const toml::node& n) {
  if (n.is_table()) return true;
  if (auto a = n.as_array())
    for (const auto& e : *a)
      if (is_table_value(e)) return true;
  return false;
}

// Body keys given with --set: (body index, key), so that read_body can refuse one the
// body's shape does not use rather than ignore what was asked for.
using BodySets = std::set<std::pair<std::size_t, std::string>>;

void apply_override(toml::table& root, const std::string& kv, const std::string& source, BodySets& body_sets) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--set " + quoted(kv) + ": expected key=value");
  const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
  // One value on one line: anything after it (a second key on a new line) is refused,
  // not silently parsed as more TOML or dropped.
  if (value.find_first_of("\n\r") != std::string::npos)
    throw InputError("--set " + key + ": the value must be on one line (one key=value per --set)");
  check_dotted_keys("v = " + value, "--set " + key);
  // Parse the value as TOML; a bare word that is not TOML becomes a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed = toml::table{};
    parsed.insert("v", value);
  }
  if (parsed.size() != 1 || !parsed.contains("v"))
    throw InputError("--set " + key + ": unexpected content after the value (one key=value per --set)");
  const toml::node& v = *parsed["v"].node();
  const auto dot = key.find('.');
  const std::string section = dot == std::string::npos ? "" : key.substr(0, dot);
  std::string leaf = dot == std::string::npos ? key : key.substr(dot + 1);
  // --set sets leaf keys: a whole section (material={E=5}, obstacle=[{...}], obstacle=[])
  // would replace or add tables and drop the file's other keys.
  const std::string one_by_one = ": set its keys one by one (--set " + (section.empty() ? key : section) +
                                 (section == "body" || section == "obstacle" || section == "fixed" || key == "body" ||
                                          key == "obstacle" || key == "fixed"
                                      ? ".N.key=value)"
                                      : ".key=value)");
  if (section.empty() && kSections.count(key))
    throw InputError(source + ": --set " + key + ": '" + key + "' is a section, not a key" + one_by_one);
  if (is_table_value(v))
    throw InputError(source + ": --set " + key + ": a table value is not accepted" + one_by_one);
  // body.N.key / body.N.material.key: the N-th body (0-based, file order) of [[body]]
  // tables, or of the one [body] table (N = 0). body.X.key with X not a body key or
  // "material" is an index, checked here.
  const std::string first = leaf.substr(0, leaf.find('.'));
  if (section == "body" && leaf.find('.') != std::string::npos && first != "material") {
    if (first.empty() || first.size() > 3 || first.find_first_not_of("0123456789") != std::string::npos)
      throw InputError("--set " + quoted(kv) + ": the body index " + quoted(first) +
                       " is invalid: body keys are 'body.N.key' (N = 0, 1, ... in file order)");
  }
  if (section == "body" && !leaf.empty() && std::isdigit(static_cast<unsigned char>(leaf[0]))) {
    auto [n, rest] = split_index(kv, leaf, "body keys are 'body.N.key' (N = 0, 1, ... in file order)");
    toml::table* body = nullptr;
    if (auto* arr = root["body"].as_array()) {
      if (n < arr->size()) body = (*arr)[n].as_table();
    } else if (n == 0) {
      if (!root.contains("body")) root.insert("body", toml::table{});
      body = root["body"].as_table();
    }
    if (!body) throw InputError(source + ": --set " + key + ": the scene has no body " + std::to_string(n));
    if (rest.rfind("material.", 0) == 0) {
      rest = rest.substr(9);
      if (!body->contains("material")) body->insert("material", toml::table{});
      body = (*body)["material"].as_table();
      if (!body) throw InputError(source + ": --set " + key + ": 'material' is not a table");
    } else if (rest == "material") {
      throw InputError(source + ": --set " + key + ": 'material' is a table, not a key: set its keys one by one (--set " +
                       key + ".key=value)");
    }
    if (rest.empty() || rest.find('.') != std::string::npos)
      throw InputError("--set " + quoted(kv) + ": body keys are 'body.N.key' or 'body.N.material.key'");
    body->insert_or_assign(rest, v);
    body_sets.insert({n, rest});
    return;
  }
  // obstacle.N.key, fixed.N.key: the N-th [[obstacle]] or [[fixed]] table (0-based, file
  // order). They are only changed here, never added: a shape or a region needs several
  // keys at once. Which keys a table takes is checked where the tables are read
  // (read_obstacles, read_fixed), as for the file's own keys.
  if (section == "obstacle" || section == "fixed") {
    const std::string form = section + " keys are '" + section + ".N.key' (N = 0, 1, ... in file order)";
    auto [n, rest] = split_index(kv, leaf, form.c_str());
    if (rest.find('.') != std::string::npos) throw InputError("--set " + quoted(kv) + ": " + form);
    auto* arr = root[section].as_array();
    if (!arr) throw InputError(source + ": --set " + key + ": the scene has no [[" + section + "]] tables");
    toml::table* table = n < arr->size() ? (*arr)[n].as_table() : nullptr;
    if (!table)
      throw InputError(source + ": --set " + key + ": the scene has no " + section + " " + std::to_string(n) + " (it has " +
                       std::to_string(arr->size()) + ", numbered from 0)");
    table->insert_or_assign(rest, v);
    return;
  }
  if (section == "body" && root["body"].as_array())
    throw InputError(source + ": --set " + key + ": the scene has [[body]] tables: use body.N." + leaf);
  if (section == "body" && first == "material" && leaf != first)  // body.material.E: which body is not said
    throw InputError("--set " + quoted(kv) + ": a body's own material is set with 'body.N.material.key' (N = 0, 1, ... " +
                     "in file order: --set body.0." + leaf + "=...); the scene's [material] with 'material.key'");
  if (leaf.empty() || leaf.find('.') != std::string::npos)
    throw InputError("--set " + quoted(kv) + ": keys are 'section.key' or 'key'");
  if (section == "body" && leaf == "material")
    throw InputError(source + ": --set " + key + ": 'material' is a table, not a key: set its keys one by one " +
                     "(--set body.0.material.key=value)");
  toml::table* target = &root;
  if (!section.empty()) {
    if (!root.contains(section)) root.insert(section, toml::table{});
    target = root[section].as_table();
    if (!target) throw InputError(source + ": --set " + key + ": '" + section + "' is not a table");
  }
  target->insert_or_assign(leaf, v);
  if (section == "body") body_sets.insert({0, leaf});
}

// [mesh]: the TetGen options, with the ranges of the switch grammar (tetgen_mesher.h),
// then the switches TetGen would run with, so that every mesh.* problem is reported here,
// prefixed with the scene file, before any surface is built.
void read_mesh_keys(Reader& r, Scene& s) {
  s.tetgen.radius_edge = r.num("mesh.radius_edge", 2.0, 0, kMaxRadiusEdge);
  if (s.tetgen.radius_edge > 0 && s.tetgen.radius_edge < kMinRadiusEdge)
    r.fail("mesh.radius_edge", "must be 0 (no quality bound) or in 1.1..1000 (TetGen does not terminate below 1.1)");
  s.tetgen.min_dihedral = r.num("mesh.min_dihedral_deg", 0.0, 0, kMaxMinDihedralDeg);
  if (s.tetgen.min_dihedral > 0 && s.tetgen.min_dihedral < 0.001)
    r.fail("mesh.min_dihedral_deg", "must be 0 (TetGen's default) or in 0.001..20 degrees");
  s.tetgen.max_volume = r.num("mesh.max_volume", 0.0, 0, INFINITY);
  s.tetgen.keep_boundary = r.boolean("mesh.keep_boundary", false);
  {
    const toml::node* n = r.get("mesh.switches");
    if (n && n->as_string() && n->as_string()->get().size() > kMaxSwitchesLength)
      r.fail("mesh.switches", "at most " + std::to_string(kMaxSwitchesLength) + " characters, got " +
                                  std::to_string(n->as_string()->get().size()));
  }
  s.tetgen.switches = r.str("mesh.switches", "");
  // The switches replace these keys: given too (or by --set, or by an accuracy level's
  // @q), they were dropped without a word and accuracy rows were labelled with them.
  if (!s.tetgen.switches.empty())
    for (const char* k : {"radius_edge", "min_dihedral_deg", "max_volume", "keep_boundary"})
      if (r.get(std::string("mesh.") + k))
        r.fail("mesh.switches", std::string("replaces mesh.") + k + ", which is given too; give one or the other");
  s.tetgen.max_tets = r.integer("mesh.max_tets", int(kDefaultMaxTets), 1, int(kMaxTetsLimit));
  s.tetgen.time_limit_s = r.num("mesh.time_limit_s", kDefaultTetgenTimeLimitS, 0, 1e6);
  s.mesh_cache = r.boolean("mesh.cache", true);
  s.tetgen.switches_unit_m = s.length_unit;  // a<V> in the scene's units^3
  TetgenOptions o = s.tetgen;  // as scene_tetgen_options: max_volume in m^3
  o.max_volume = s.tetgen.max_volume * s.length_unit * s.length_unit * s.length_unit;
  if (s.tetgen.max_volume > 0 && !(o.max_volume > 0))  // a subnormal bound: 0 would mean none
    r.fail("mesh.max_volume", "must be 0 (no bound) or a volume that stays above 0 in m^3, got " + exact_number(s.tetgen.max_volume));
  try {
    (void)tetgen_switches(o);
  } catch (const InputError& e) {
    throw InputError(s.source + ": " + e.what());
  }
}

// [[obstacle]] tables: the shape's keys and no others, each checked and named
// ("obstacle[1].radius: ..."), at most kMaxObstacles of them.
void read_obstacles(Reader& r, Scene& s) {
  const toml::node* node = r.get("obstacle");
  if (!node) return;
  auto arr = node->as_array();
  if (!arr) r.fail("obstacle", "expected [[obstacle]] tables");
  if (arr->size() > std::size_t(kMaxObstacles))
    r.fail("obstacle", "at most " + std::to_string(kMaxObstacles) + " obstacles, got " + std::to_string(arr->size()));
  const double far = kMaxCoordinate / s.length_unit;  // |coordinate| and size bound, scene units
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const std::string key = "obstacle[" + std::to_string(i) + "]";
    auto t = (*arr)[i].as_table();
    if (!t) r.fail(key, "expected a table ([[obstacle]])");
    Scene::ObstacleDesc o;
    auto sh = (*t)["shape"].as_string();
    if (!(*t)["shape"].node()) r.fail(key + ".shape", "required: \"sphere\", \"box\", \"capsule\" or \"mesh\"");
    if (!sh) r.fail(key + ".shape", "expected a string");
    const std::string shape = sh->get();
    bool known = false;
    for (const auto& [name, v] : kObstacleShapes)
      if (shape == name) o.shape = v, known = true;
    if (!known) r.fail(key + ".shape", quoted(shape) + " is not one of: sphere, box, capsule, mesh");
    const std::set<std::string> keys =
        o.shape == kObstacleSphere ? std::set<std::string>{"shape", "center", "radius", "velocity"}
        : o.shape == kObstacleBox  ? std::set<std::string>{"shape", "center", "size", "rotation_deg", "velocity"}
        : o.shape == kObstacleMesh
            ? std::set<std::string>{"shape", "file", "center", "scale", "rotation_deg", "resolution", "velocity"}
            : std::set<std::string>{"shape", "a", "b", "radius", "velocity"};
    for (const auto& [k, v] : *t) {
      (void)v;
      const std::string name(k.str());
      if (!keys.count(name)) {
        std::string list;
        for (const auto& a : keys) list += (list.empty() ? "" : ", ") + a;
        r.fail(key + "." + name, "unknown key (a " + shape + " obstacle takes " + list + ")");
      }
    }
    // A vector key: required or not, finite, each |component| <= limit.
    auto vec3 = [&](const char* name, bool required, double limit, std::array<double, 3>& out) {
      const toml::node* n = (*t)[name].node();
      const std::string full = key + "." + name;
      if (!n) {
        if (required) r.fail(full, std::string("required for a ") + shape + " obstacle");
        return;
      }
      auto a = n->as_array();
      if (!a || a->size() != 3) r.fail(full, "expected an array of 3 numbers");
      for (int k = 0; k < 3; ++k) {
        const auto v = (*a)[k].value<double>();
        if (!v || !std::isfinite(*v)) r.fail(full, "element " + std::to_string(k) + " is not a finite number");
        if (std::fabs(*v) > limit) {
          r.fail(full, "element " + std::to_string(k) + " = " + exact_number(*v) + " is out of range [" + exact_number(-limit) + ", " +
                           exact_number(limit) + "]");
        }
        out[k] = *v;
      }
    };
    // A size at least 1e-6 m, as for a mesh obstacle's extent and a body's surface: a
    // radius of 5e-324 (subnormal) or a 1e-320 box ran as an obstacle of no size.
    const double tiny = 1e-6 / s.length_unit;  // scene units
    auto positive = [&](const char* name, double v) {
      if (!(v > 0)) {
        std::ostringstream m;
        m << "must be positive, got " << v;
        r.fail(key + "." + name, m.str());
      }
    };
    auto length = [&](const char* name, double v) {  // a positive length of at least 1e-6 m
      positive(name, v);
      if (v < tiny) r.fail(key + "." + name, "value " + exact_number(v) + " is below 1e-6 m (" + exact_number(tiny) + " in the scene's units)");
    };
    vec3("velocity", false, kMaxSpeed, o.velocity);
    if (o.shape == kObstacleSphere || o.shape == kObstacleCapsule) {
      const toml::node* n = (*t)["radius"].node();
      if (!n) r.fail(key + ".radius", std::string("required for a ") + shape + " obstacle");
      if (auto i = n->as_integer()) o.radius = double(i->get());
      else if (auto f = n->as_floating_point()) o.radius = f->get();
      else r.fail(key + ".radius", "expected a number");
      if (!std::isfinite(o.radius)) r.fail(key + ".radius", "must be finite, got " + std::to_string(o.radius));
      length("radius", o.radius);
      if (o.radius > far) r.fail(key + ".radius", "larger than the coordinate range (1e4 m)");
    }
    if (o.shape == kObstacleSphere) {
      vec3("center", true, far, o.center);
    } else if (o.shape == kObstacleBox) {
      vec3("center", true, far, o.center);
      vec3("size", true, far, o.size);
      for (int k = 0; k < 3; ++k) {
        if (!(o.size[k] > 0)) r.fail(key + ".size", "element " + std::to_string(k) + " must be positive");
        if (o.size[k] < tiny)
          r.fail(key + ".size", "element " + std::to_string(k) + " = " + exact_number(o.size[k]) + " is below 1e-6 m (" + exact_number(tiny) +
                                    " in the scene's units)");
      }
      vec3("rotation_deg", false, kMaxRotationDeg, o.rotation_deg);
    } else if (o.shape == kObstacleMesh) {
      // The file is read, checked and turned into a distance grid at start-up
      // (scene_obstacles), where its errors name obstacle[i].file.
      const toml::node* f = (*t)["file"].node();
      if (!f) r.fail(key + ".file", "required for a mesh obstacle (a closed OBJ, OFF or STL surface)");
      if (!f->as_string() || f->as_string()->get().empty()) r.fail(key + ".file", "expected a file name");
      o.file = f->as_string()->get();
      vec3("center", false, far, o.center);
      vec3("rotation_deg", false, kMaxRotationDeg, o.rotation_deg);
      if (const toml::node* n = (*t)["scale"].node()) {
        if (auto i = n->as_integer()) o.scale = double(i->get());
        else if (auto fl = n->as_floating_point()) o.scale = fl->get();
        else r.fail(key + ".scale", "expected a number");
        if (!std::isfinite(o.scale)) r.fail(key + ".scale", "must be finite, got " + std::to_string(o.scale));
        positive("scale", o.scale);
      }
      if (const toml::node* n = (*t)["resolution"].node()) {
        auto i = n->as_integer();
        if (!i) r.fail(key + ".resolution", "expected an integer (distance grid cells across the mesh's longest side)");
        if (i->get() < kMinSdfResolution || i->get() > kMaxSdfResolution)
          r.fail(key + ".resolution", "value " + std::to_string(i->get()) + " out of range [" +
                                          std::to_string(kMinSdfResolution) + ", " + std::to_string(kMaxSdfResolution) +
                                          "] (cells across the mesh's longest side; the grid is at most 127^3 nodes)");
        o.resolution = int(i->get());
      }
    } else {
      vec3("a", true, far, o.a);
      vec3("b", true, far, o.b);
    }
    s.obstacles.push_back(o);
  }
}


// The body keys that only some shapes use, and those each shape uses (the others apply to
// every shape).
const std::set<std::string> kShapeKeys = {"major_radius", "tube_radius", "segments", "size", "divisions",
                                          "radius",       "subdivisions", "file",   "scale"};
std::set<std::string> shape_keys(const std::string& shape) {
  if (shape == "torus") return {"major_radius", "tube_radius", "segments"};
  if (shape == "box") return {"size", "divisions"};
  if (shape == "sphere") return {"radius", "subdivisions"};
  return {"file", "scale"};  // file, tet_file
}

// One body's keys (body.* in table t, under the name label), into b. set_here: the keys
// --set gave this body.
void read_body(const toml::table& t, const std::string& source, const std::string& label, BodyDesc& b,
               const std::set<std::string>& set_here, const std::string& surface = "") {
  toml::table root;
  root.insert("body", t);
  Reader r(root, source, label == "body" ? "" : label);
  b.key = label;
  b.shape = r.str("body.shape", b.shape, {"torus", "box", "sphere", "file", "tet_file"});
  b.radius = r.num("body.radius", b.radius, 0, INFINITY, true);
  b.subdivisions = r.integer("body.subdivisions", b.subdivisions, 0, 7);
  b.file = r.str("body.file", "");
  if (!surface.empty()) {  // `mesh --surface`: the surface file is this body, whatever the scene says
    for (const char* k : {"shape", "file"})
      if (set_here.count(k))
        r.fail(std::string("body.") + k, "not used with --surface: the surface file " + quoted(surface) +
                                             " is the body (without --surface, mesh meshes the scene's body)");
    b.shape = "file";
    b.file = surface;
  }
  b.major_radius = r.num("body.major_radius", b.major_radius, 0, INFINITY, true);
  b.tube_radius = r.num("body.tube_radius", b.tube_radius, 0, INFINITY, true);
  b.segments = r.ivec<2>("body.segments", b.segments, 3, 4096);
  b.size = r.vec<3>("body.size", b.size);
  for (double v : b.size) if (!(v > 0)) r.fail("body.size", "sides must be positive");
  b.divisions = r.ivec<3>("body.divisions", b.divisions, 1, 1024);
  b.scale = r.num("body.scale", 1.0, 0, INFINITY, true);
  b.position = r.vec<3>("body.position", b.position);
  b.rotation_deg = r.vec<3>("body.rotation_deg", b.rotation_deg, kMaxRotationDeg);
  b.velocity = r.vec<3>("body.velocity", b.velocity, kMaxSpeed);
  if (b.shape == "torus" && !(b.tube_radius < b.major_radius)) r.fail("body.tube_radius", "must be smaller than body.major_radius");
  if (b.shape == "file" && b.file.empty()) r.fail("body.file", "required when body.shape = \"file\"");
  if (b.shape == "tet_file" && b.file.empty()) r.fail("body.file", "required when body.shape = \"tet_file\"");
  if (b.shape == "tet_file" && !is_tet_file_extension(b.file))
    r.fail("body.file", quoted(b.file) + ": a tet mesh file must end in .msh, .vtu, .node, .ele or .mesh");
  if (const toml::node* mat = r.get("body.material")) {
    auto mt = mat->as_table();
    if (!mt) r.fail("body.material", "expected a table ([body.material]) with E, nu, rho, model, element");
    for (const auto& [k, v] : *mt) {
      (void)v;
      const std::string name(k.str());
      if (name != "E" && name != "nu" && name != "rho" && name != "model" && name != "element")
        r.fail("body.material." + name, "unknown key (a body's material takes E, nu, rho, model, element)");
    }
    b.own_E = r.num("body.material.E", -1, 0, kMaxYoungsModulus, true);
    b.own_rho = r.num("body.material.rho", -1, 0, kMaxDensity, true);
    b.own_nu = r.num("body.material.nu", -2, kMinPoisson, kMaxPoisson, false);
    if (b.own_nu > -2 && !(b.own_nu > kMinPoisson && b.own_nu < kMaxPoisson)) r.fail("body.material.nu", "must lie in (-1, 0.5)");
    if (r.get("body.material.model")) b.own_model = r.choice("body.material.model", kTaylorNeoHookean, kMaterialModels);
    if (r.get("body.material.element")) b.own_element = r.choice("body.material.element", kT4, kElements);
  }
  for (const auto& [k, v] : t) {
    (void)v;
    const std::string name(k.str());
    if (name.find('.') != std::string::npos) r.fail_quoted("body.\"" + name + "\"");
    if (!r.used("body." + name)) r.fail("body." + name, "unknown key (see README, 'Scene format')");
  }
  // A key of another shape does nothing. Asked for with --set it is refused; in the file
  // (say, left over when --set changed the shape) it is reported and left.
  // With --surface the scene's own shape keys are replaced with the body, silently.
  const std::set<std::string> own = shape_keys(b.shape);
  for (const std::string& name : kShapeKeys) {
    if (!t.contains(name) || own.count(name)) continue;
    if (!surface.empty() && !set_here.count(name)) continue;
    std::string uses;
    for (const std::string& k : own) uses += (uses.empty() ? "" : ", ") + k;
    const std::string why = surface.empty()
                                ? "not used by a " + b.shape + " body (its shape keys: " + uses + ")"
                                : "not used with --surface: the body is the surface file " + quoted(surface) +
                                      " (its shape key: scale)";
    if (set_here.count(name)) r.fail("body." + name, why);
    std::fprintf(stderr, "warning: %s: %s.%s is %s; ignored\n", source.c_str(), label.c_str(), name.c_str(),
                 why.c_str());
  }
}

// [body] (one body) or [[body]] tables (at most kMaxBodies), each with body.* keys and
// optionally [body.material]. Body 0 goes into the Scene's own BodyDesc.
void read_bodies(Reader& r, const toml::table& root, Scene& s, const BodySets& body_sets, const std::string& surface) {
  const toml::node* node = r.get("body");
  std::vector<const toml::table*> tables;
  bool array = false;
  const toml::table empty;
  if (!node) {
    tables.push_back(&empty);
  } else if (auto t = node->as_table()) {
    tables.push_back(t);
  } else if (auto a = node->as_array()) {
    array = true;
    if (a->empty()) r.fail("body", "expected at least one [[body]] table");
    if (a->size() > std::size_t(kMaxBodies))
      r.fail("body", "at most " + std::to_string(kMaxBodies) + " bodies (kMaxBodies), got " + std::to_string(a->size()));
    for (std::size_t i = 0; i < a->size(); ++i) {
      auto t = (*a)[i].as_table();
      if (!t) r.fail("body[" + std::to_string(i) + "]", "expected a table ([[body]])");
      tables.push_back(t);
    }
  } else {
    r.fail("body", "expected a [body] table or [[body]] tables");
  }
  (void)root;
  if (!surface.empty()) {  // one body, the surface: the others are replaced, and a key set for one would do nothing
    for (const auto& [n, key] : body_sets)
      if (n > 0)
        r.fail("body[" + std::to_string(n) + "]." + key,
               "not used with --surface: the surface file " + quoted(surface) + " replaces the scene's bodies with one (body 0)");
    tables.resize(1);
  }
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const std::string label = array ? "body[" + std::to_string(i) + "]" : "body";
    std::set<std::string> set_here;
    for (const auto& [n, key] : body_sets)
      if (n == i) set_here.insert(key);
    if (i == 0) {
      read_body(*tables[i], s.source, label, s, set_here, surface);
    } else {
      BodyDesc b;
      read_body(*tables[i], s.source, label, b, set_here);
      s.more_bodies.push_back(b);
    }
  }
}
}  // namespace

Scene parse_scene(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
                  const std::string& surface) {
  toml::table root;
  // Text (Python's from_toml or a dict) has the limit of a scene file (load_scene).
  check_input_size("scene " + source, text.size(), kMaxSceneBytes);
  check_dotted_keys(text, source);
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream o;
    o << source << ":" << e.source().begin.line << ":" << e.source().begin.column << ": " << e.description();
    throw InputError(o.str());
  }
  BodySets body_sets;
  for (const auto& kv : overrides) apply_override(root, kv, source, body_sets);
  Reader r(root, source);
  Scene s;
  s.source = source;
  const std::string units = r.str("units", "mm", {"m", "mm"});
  s.length_unit = units == "mm" ? 1e-3 : 1.0;

  read_bodies(r, root, s, body_sets, surface);
  read_mesh_keys(r, s);
  {  // TetGen's options do nothing where no body is meshed: say so rather than take them silently
    bool meshed = false;
    for (int b = 0; b < s.body_count(); ++b) meshed = meshed || s.body(b).shape != "tet_file";
    for (const char* k : {"radius_edge", "min_dihedral_deg", "max_volume", "keep_boundary", "switches", "time_limit_s"})
      if (!meshed && root.at_path(std::string("mesh.") + k).node())
        std::fprintf(stderr, "warning: %s: mesh.%s is not used: every body is a tet_file mesh (not meshed again); ignored\n",
                     s.source.c_str(), k);
  }
  if (const toml::node* fx = r.get("fixed")) {
    auto arr = fx->as_array();
    if (!arr) r.fail("fixed", "expected [[fixed]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      auto t = (*arr)[i].as_table();
      const std::string key = "fixed[" + std::to_string(i) + "]";
      if (!t) r.fail(key, "expected a table with box_min/box_max or plane_point/plane_normal");
      auto get3 = [&](const char* name, std::array<double, 3>& out) {
        const toml::node* n = (*t)[name].node();
        if (!n) return false;
        auto a = n->as_array();
        if (!a || a->size() != 3) r.fail(key + "." + name, "expected an array of 3 numbers");
        for (int k = 0; k < 3; ++k) {
          auto v = (*a)[k].value<double>();
          if (!v || !std::isfinite(*v)) r.fail(key + "." + name, "expected finite numbers");
          out[k] = *v;
        }
        return true;
      };
      Scene::FixedSelector f;
      for (const auto& [k, v] : *t) {
        (void)v;
        const std::string name(k.str());
        if (name != "box_min" && name != "box_max" && name != "plane_point" && name != "plane_normal")
          r.fail(key + "." + name, "unknown key (use box_min/box_max or plane_point/plane_normal)");
      }
      // One selector per table: a box and a plane together would silently drop one.
      const bool box = t->contains("box_min") || t->contains("box_max");
      const bool plane = t->contains("plane_point") || t->contains("plane_normal");
      if (box && plane)
        r.fail(key + "." + (t->contains("plane_point") ? "plane_point" : "plane_normal"),
               "cannot be combined with box_min/box_max in one [[fixed]] table (use one [[fixed]] table per selector)");
      if (box && !t->contains("box_min")) r.fail(key + ".box_min", "required with box_max");
      if (plane && !t->contains("plane_point")) r.fail(key + ".plane_point", "required with plane_normal");
      if (get3("box_min", f.a)) {
        if (!get3("box_max", f.b)) r.fail(key + ".box_max", "required with box_min");
        for (int k = 0; k < 3; ++k)  // an empty box would only be reported as selecting no node
          if (f.a[k] > f.b[k])
            r.fail(key + ".box_min", std::string("exceeds box_max along ") + "xyz"[k] + ": the box is empty");
        f.is_box = true;
      } else if (get3("plane_point", f.a)) {
        if (!get3("plane_normal", f.b)) r.fail(key + ".plane_normal", "required with plane_point");
        if (!normalize(f.b)) r.fail(key + ".plane_normal", "must be non-zero");
        f.is_box = false;
      } else {
        r.fail(key, "needs box_min/box_max or plane_point/plane_normal");
      }
      s.fixed.push_back(f);
    }
  }

  s.material_model = r.choice("material.model", s.material_model, kMaterialModels);
  s.element = r.choice("material.element", s.element, kElements);
  if (s.element == kT4ANP && s.material_model != kTaylorNeoHookean)
    r.fail("material.element", "T4ANP is implemented for the neo_hookean model only");
  s.E = r.num("material.E", s.E, 0, kMaxYoungsModulus, true);
  s.nu = r.num("material.nu", s.nu, kMinPoisson, kMaxPoisson, false);
  if (!(s.nu > kMinPoisson && s.nu < kMaxPoisson)) r.fail("material.nu", "must lie in (-1, 0.5)");
  s.rho = r.num("material.rho", s.rho, 0, kMaxDensity, true);
  // T4ANP is implemented for the Taylor form only (anp.h), body by body: a body's own
  // element or model against its own or the scene's other one.
  for (int i = 0; i < s.body_count(); ++i) {
    const BodyDesc& b = s.body(i);
    if (s.body_element(i) == kT4ANP && s.body_model(i) != kTaylorNeoHookean)
      r.fail(b.own_law() ? b.key + ".material" : "material.element",
             "T4ANP is implemented for the neo_hookean model only");
    if (law_has_negative_energy(s.body_nu(i), s.body_model(i)))
      r.fail(b.own_law() ? b.key + ".material" : "material.nu", negative_energy_law_why());
  }
  // A [material] key that every body overrides is used by no body: said, as the unused
  // contact and floor keys are below (a probe's material.E under two bodies' own E changed
  // nothing, silently).
  using Owns = bool (*)(const BodyDesc&);
  const std::pair<const char*, Owns> own_keys[] = {{"E", [](const BodyDesc& b) { return b.own_E > 0; }},
                                                   {"rho", [](const BodyDesc& b) { return b.own_rho > 0; }},
                                                   {"nu", [](const BodyDesc& b) { return b.own_nu > -2; }},
                                                   {"model", [](const BodyDesc& b) { return b.own_model >= 0; }},
                                                   {"element", [](const BodyDesc& b) { return b.own_element >= 0; }}};
  for (const auto& [k, owns] : own_keys) {
    bool every = true;
    for (int i = 0; i < s.body_count(); ++i) every = every && owns(s.body(i));
    if (every && r.get(std::string("material.") + k))
      std::fprintf(stderr, "warning: %s: material.%s is not used: every body overrides it with its own [body.material] "
                   "%s\n", s.source.c_str(), k, k);
  }
  // One body: its [body.material] overrides [material], and no other body keeps [material],
  // so the body's values become the scene's. The stable step, the solver and the panel's
  // live material all read those (the per-body scales exist only for several bodies, so
  // the one body's own values were otherwise left unused).
  if (s.body_count() == 1) {
    if (s.own_E > 0) s.E = s.own_E;
    if (s.own_rho > 0) s.rho = s.own_rho;
    if (s.own_nu > -2) s.nu = s.own_nu;
    if (s.own_model >= 0) s.material_model = MaterialModel(s.own_model);
    if (s.own_element >= 0) s.element = ElementType(s.own_element);
    s.own_E = s.own_rho = -1;
    s.own_nu = -2;
    s.own_model = s.own_element = -1;
  }
  s.alpha = r.num("damping.alpha", s.alpha, 0, kMaxAlpha);
  s.beta = r.num("damping.beta", s.beta, 0, kMaxBeta);
  s.g = r.vec<3>("gravity.g", s.g, kMaxGravity);

  s.floor = r.boolean("floor.enabled", s.floor);
  s.floor_point = r.vec<3>("floor.point", s.floor_point, kMaxCoordinate / s.length_unit);
  s.floor_normal = r.vec<3>("floor.normal", s.floor_normal);
  if (!normalize(s.floor_normal)) r.fail("floor.normal", "must be non-zero");
  s.slope = r.boolean("slope.enabled", s.slope);
  s.slope_angle_deg = r.num("slope.angle_deg", s.slope_angle_deg, -90, 90);
  s.slope_point = r.vec<3>("slope.point", s.floor_point, kMaxCoordinate / s.length_unit);
  if (s.slope) {
    const std::string why = slope_tilt_error(s.floor_normal, s.slope_angle_deg);
    if (!why.empty()) r.fail("slope.angle_deg", why);
  }

  read_obstacles(r, s);
  s.contact_mode = r.choice("contact.mode", s.contact_mode, kContactModes);
  s.mu = r.num("contact.mu", s.mu, 0, kMaxMu);
  s.contact_nodes = r.str("contact.nodes", s.contact_nodes, {"boundary", "all"});
  s.contact_bodies = r.boolean("contact.bodies", true);
  s.contact_self = r.boolean("contact.self", false);
  // Keys given where the scene does not use them, said rather than taken silently (a probe's
  // static mode with mu = 0 ran exactly as Coulomb with mu = 1000), as time.lambda is below:
  // each applies only once the viewer or set_params switches its part on.
  auto unused = [&](const char* key, const char* why) {
    if (r.get(key)) std::fprintf(stderr, "warning: %s: %s is not used: %s\n", s.source.c_str(), key, why);
  };
  if (s.contact_mode != kCoulomb) unused("contact.mu", "only contact.mode = \"coulomb\" has a friction coefficient");
  if (!s.slope)
    for (const char* k : {"slope.angle_deg", "slope.point"}) unused(k, "slope.enabled is false");
  if (!s.floor && !s.slope)
    for (const char* k : {"floor.point", "floor.normal"}) unused(k, "floor.enabled and slope.enabled are false");

  {
    const toml::node* dt = r.get("time.dt");
    if (!dt || (dt->as_string() && dt->as_string()->get() == "auto")) {
      s.dt_auto = true;
    } else if (dt->as_string() && dt->as_string()->get() == "adaptive") {
      s.dt_auto = false;
      s.dt_adaptive = true;
    } else if (!dt->is_number()) {
      std::string got = dt->as_string() ? quoted(dt->as_string()->get()) : std::string("a ") + (dt->is_boolean() ? "boolean" : dt->is_array() ? "array" : dt->is_table() ? "table" : "date or time");
      r.fail("time.dt", "expected a step in seconds, \"auto\" or \"adaptive\" (lower case), got " + got);
    } else {
      s.dt_auto = false;
      s.dt = r.num("time.dt", 0, 0, INFINITY, true);
    }
  }
  s.lambda = r.num("time.lambda", s.lambda, 0, 1, true);
  // A fixed step takes no fraction of dt_cr: say so rather than run as if it did (a scene's
  // lambda = 0.5 under --set time.dt=1e-5 ran at 1e-5 whatever lambda said).
  if (root.at_path("time.lambda").node() && !s.dt_auto && !s.dt_adaptive)
    std::fprintf(stderr,
                 "warning: %s: time.lambda is not used while time.dt is fixed (%.4g s); it applies only if the step "
                 "is switched to auto live, or a live dt above the stable step is clamped\n",
                 s.source.c_str(), s.dt);
  s.dt_max = r.num("time.dt_max", s.dt_max, 0, INFINITY, true);
  if (root.at_path("time.dt_max").node() && !s.dt_adaptive)
    r.fail("time.dt_max", std::string("applies only with time.dt = \"adaptive\" (here time.dt is ") +
                              (s.dt_auto ? "\"auto\"" : "a fixed step") + ")");
  s.allow_unstable = r.boolean("time.allow_unstable", false);
  s.duration = r.num("time.duration", s.duration, 0, kMaxDuration, true);  // 0 would run no step
  s.output_every = r.num("time.output_every", s.output_every, 0, INFINITY, true);

  s.precision = r.choice("solver.precision", s.precision, kPrecisions);
  s.threads = r.integer("solver.threads", 0, 0, 1024);

  if (const toml::node* tp = r.get("output.track_points")) {
    auto a = tp->as_array();
    if (!a) r.fail("output.track_points", "expected an array of [x, y, z] points");
    // Three CSV columns each, read back every output: 200,000 points ran at 40x the step
    // cost with 600,000-column rows (a probe), so a limit as for bodies and obstacles.
    if (a->size() > std::size_t(kMaxTrackPoints))
      r.fail("output.track_points", std::to_string(a->size()) + " points, at most " + std::to_string(kMaxTrackPoints));
    for (std::size_t i = 0; i < a->size(); ++i) {
      auto p = (*a)[i].as_array();
      if (!p || p->size() != 3) r.fail("output.track_points", "element " + std::to_string(i) + " is not [x, y, z]");
      std::array<double, 3> q;
      for (int k = 0; k < 3; ++k) {
        auto v = (*p)[k].value<double>();
        if (!v || !std::isfinite(*v)) r.fail("output.track_points", "element " + std::to_string(i) + " has a non-number");
        if (!(std::fabs(*v) <= kMaxCoordinate / s.length_unit))
          r.fail("output.track_points", "element " + std::to_string(i) + " lies beyond " +
                                            std::to_string(int(kMaxCoordinate)) + " m from the origin");
        q[k] = *v;
      }
      if (std::find(s.track_points.begin(), s.track_points.end(), q) != s.track_points.end())
        r.fail("output.track_points", "element " + std::to_string(i) + " repeats an earlier point");
      s.track_points.push_back(q);
    }
  }
  r.reject_unknown();
  return s;
}

bool Scene::per_body_law() const {
  for (int i = 0; i < body_count(); ++i)
    if (body(i).own_law()) return true;
  return false;
}

std::string negative_energy_law_why() {
  char buf[200];
  std::snprintf(buf, sizeof buf, "the stable_neo_hookean energy goes below zero under compression for nu < %g (its "
                "alpha grows as lambda -> 0); use nu >= %g or the neo_hookean model", kMinStableNeoHookeanNu,
                kMinStableNeoHookeanNu);
  return buf;
}

const char* material_model_name(MaterialModel m) { return name_of(kMaterialModels, m); }
const char* element_name(ElementType e) { return name_of(kElements, e); }
const char* contact_mode_name(ContactMode m) { return name_of(kContactModes, m); }
const char* precision_name(Precision p) { return name_of(kPrecisions, p); }
const char* obstacle_shape_name(ObstacleShape s) { return name_of(kObstacleShapes, s); }

std::vector<PathUse> scene_inputs(const Scene& s, const std::string& scene_flag) {
  std::vector<PathUse> in;
  if (!s.source.empty() && s.source[0] != '(' && s.source != "--surface") in.push_back({s.source, scene_flag});
  const auto slash = s.source.find_last_of('/');
  auto rel = [&](const std::string& f) {
    return !f.empty() && f[0] != '/' && slash != std::string::npos ? s.source.substr(0, slash + 1) + f : f;
  };
  for (int b = 0; b < s.body_count(); ++b)  // (tet_file_paths: any other file is itself alone)
    if (!s.body(b).file.empty())
      for (const std::string& f : tet_file_paths(rel(s.body(b).file))) in.push_back({f, s.body(b).key + ".file"});
  for (std::size_t i = 0; i < s.obstacles.size(); ++i)
    if (!s.obstacles[i].file.empty()) in.push_back({rel(s.obstacles[i].file), "obstacle[" + std::to_string(i) + "].file"});
  return in;
}

void check_not_scene_input(const Scene& s, const std::string& scene_flag, const PathUse& output) {
  std::vector<PathUse> paths = scene_inputs(s, scene_flag);
  paths.push_back(output);
  check_distinct_paths(paths);
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides, const std::string& surface) {
  // Regular files only, size-capped (a directory or FIFO is refused before it is opened).
  std::string text;
  try {
    text = read_input_file(path, kMaxSceneBytes);
  } catch (const InputError& e) {
    throw InputError(std::string("scene file ") + e.what());
  }
  return parse_scene(text, path, overrides, surface);
}

}  // namespace softtled
