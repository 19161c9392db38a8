#include "sim/core/exact_number.h"
#include "sim/core/stop_request.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/io/output_file.h"  // ResourceError

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <cctype>
#include <cmath>
#include <limits>
#include <new>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

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
                     " (TetGen does not terminate below that), got " + exact_number(rho));
}

void check_theta(double theta, const std::string& where) {
  // 0, or at least 0.001 so that the number prints without an exponent (TetGen's q
  // parser reads digits and '.' only).
  if (!(theta == 0 || (theta >= 1e-3 && theta <= kMaxMinDihedralDeg)))
    throw InputError(where + ": the minimum dihedral angle must be 0 (TetGen's default) or in 0.001.." +
                     num(kMaxMinDihedralDeg) + " degrees (larger bounds do not terminate), got " + exact_number(theta));
}

// Parses TetgenOptions::switches: only the documented subset, each letter once.
// unit_m: metres per length unit of a<V> (the scene's units).
Switches parse_switches(const std::string& text, double unit_m) {
  const std::string key = "mesh.switches";
  if (text.size() > kMaxSwitchesLength)
    throw InputError(key + ": too long (" + std::to_string(text.size()) + " characters; at most " +
                     std::to_string(kMaxSwitchesLength) + ")");
  const std::string allowed = " (allowed: p, q[rho][/theta], a<volume in the scene's units^3>, Y, z, Q)";
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
    } else if (!exponent && j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
      // TetGen reads q's numbers as plain decimals: "q1e3" would be q1 then an unknown 'e'.
      throw InputError(key + ": '" + text.substr(start, j + 1 - start) + "...': '" + part_start +
                       "' takes a plain decimal number, no exponent" + allowed);
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
      const double mm = unit_m * kMm;
      s.a_mm3 = number(true, "a", start) * mm * mm * mm;
      if (!(s.a_mm3 >= std::numeric_limits<double>::min() && std::isfinite(s.a_mm3)))  // (a subnormal bound crashed TetGen)
        throw InputError(key + ": '" + text.substr(start, i - start) +
                         "': the volume bound must be finite and > 0, and not below 2.2e-308 mm^3");
    } else if (c == 'Y') {
      s.keep_boundary = true;
    }
    if (c != 'q' && c != 'a' && starts_number())
      throw InputError(key + ": '" + text.substr(start, i + 1 - start) + "': '" + std::string(1, c) + "' takes no number" + allowed);
  }
  return s;
}

void check_budget(long max_tets, double time_limit_s) {
  if (!(max_tets >= 1 && max_tets <= kMaxTetsLimit))
    throw InputError("mesh.max_tets: must be in 1.." + std::to_string(kMaxTetsLimit) + ", got " + std::to_string(max_tets));
  if (!(time_limit_s >= 0 && time_limit_s <= 1e6))
    throw InputError("mesh.time_limit_s: must be in 0..1e6 s (0: no limit), got " + num(time_limit_s));
}

Switches resolve(const TetgenOptions& o) {
  check_budget(o.max_tets, o.time_limit_s);
  if (!o.switches.empty()) return parse_switches(o.switches, o.switches_unit_m);
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
  if (o.max_volume > 0 && !(s.a_mm3 >= std::numeric_limits<double>::min()))
    throw InputError("mesh.max_volume: " + num(o.max_volume) + " m^3 is below the smallest bound (2.2e-308 mm^3); 0 means no bound");
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

void check_surface_for_meshing(const SurfaceMesh& surface, const std::string& what) {
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
  // -a switches -q on with TetGen's default bound 2.
  const bool quality = sw.quality || sw.a_mm3 > 0;
  if (!quality) return 2.5 * ntri;
  const double rho = sw.quality ? sw.rho : 2.0, theta = sw.quality ? sw.theta : 0.0;
  const double g_rho = std::max(0.5, std::pow(rho - 1, -0.7));
  const double t = theta / 22;
  const double g_theta = std::pow(1 - t * t, -1.5);
  const double layer = V > 0 ? 4 * A * A * A / (9 * V * V) : INFINITY;
  const double volume = sw.a_mm3 > 0 ? 2.5 * (V * kMm * kMm * kMm) / sw.a_mm3 : 0;  // in mm^3: a tiny bound in m^3 underflows
  return std::max(2.5 * ntri, layer) * g_rho * g_theta + volume;
}

}  // namespace

double estimate_tet_count(const SurfaceMesh& s, const TetgenOptions& o) { return estimate(s, resolve(o)); }

namespace {

// TetGen in a child process. TetGen 1.5 aborts on failed assertions and segfaults on
// some inputs that pass every check we can make beforehand (the fuzzer found a rotated
// box that trips "oriB != 0.0" in insphere_s); in the child that ends the child, not the
// program, and a run past the time limit is killed. The child sends the result through
// a pipe: a header, then the points and the tets.
struct TetgenRun {
  enum Status { kMesh, kIntersects, kThrew, kCrashed, kTimedOut, kTooLarge, kStopped } status = kCrashed;
  int code = 0;        // kThrew: TetGen's error code
  long count = 0;      // kIntersects: facets found crossing others
  long npoints = 0, ntets = 0;
  std::string why;     // kCrashed: how the child ended
  std::vector<double> X;  // 3 x npoints [TetGen's units]
  std::vector<int> tet;   // 4 x ntets
};

struct ChildHeader {
  std::int32_t status, code;
  std::int64_t count, npoints, ntets;
};

bool write_all(int fd, const void* p, std::size_t n) {
  const char* c = static_cast<const char*>(p);
  while (n > 0) {
    const ssize_t w = ::write(fd, c, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    c += w, n -= std::size_t(w);
  }
  return true;
}

constexpr int kStopPollMs = 100;

// Reads n bytes before the deadline; false on end of file, error, timeout (*late) or a
// stop asked (*stopped: the stop check, every kStopPollMs while it waits).
bool read_all(int fd, void* p, std::size_t n, std::chrono::steady_clock::time_point deadline, bool limited, bool* late,
              bool* stopped) {
  char* c = static_cast<char*>(p);
  while (n > 0) {
    if (stop_request_pending()) return *stopped = true, false;
    int wait_ms = -1;
    if (limited) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) return *late = true, false;
      wait_ms = int(std::min<long long>(left, 1 << 30));
    }
    if (stop_request_check_slot() && (wait_ms < 0 || wait_ms > kStopPollMs)) wait_ms = kStopPollMs;
    pollfd pfd{fd, POLLIN, 0};
    const int r = ::poll(&pfd, 1, wait_ms);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return false;
    if (r == 0) continue;  // the deadline and the stop check are tested above
    const ssize_t got = ::read(fd, c, n);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    c += got, n -= std::size_t(got);
  }
  return true;
}

// TetGen 1.5 does not check every allocation: out of memory it can dereference a null
// pointer and die of SIGSEGV instead of throwing. In the child, a crash while the address
// space is more than half used up under a finite RLIMIT_AS is reported as out of memory
// (TetGen's code 1); any other crash stays a crash. Only async-signal-safe calls here.
int g_crash_fd = -1;
unsigned long long g_as_limit = 0, g_page = 4096;  // bytes; 0: no limit
extern "C" void child_crash_handler(int sig) {
  bool oom = false;
  if (g_as_limit > 0) {
    char buf[32];
    const int f = ::open("/proc/self/statm", O_RDONLY);
    if (f >= 0) {
      const ssize_t n = ::read(f, buf, sizeof buf);
      ::close(f);
      unsigned long long pages = 0;
      for (ssize_t k = 0; k < n && buf[k] >= '0' && buf[k] <= '9'; ++k) pages = 10 * pages + unsigned(buf[k] - '0');
      oom = 2 * pages * g_page > g_as_limit;  // statm's first field: the address space in pages
    }
  }
  if (oom) {
    ChildHeader h{};
    h.status = TetgenRun::kThrew;
    h.code = 1;
    ::_exit(write_all(g_crash_fd, &h, sizeof h) ? 0 : 1);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

[[noreturn]] void child_run(tetgenio& in, const std::string& switches, int fd) {
  rlimit lim{};
  if (::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) g_as_limit = lim.rlim_cur;
  g_page = static_cast<unsigned long long>(::sysconf(_SC_PAGESIZE));
  g_crash_fd = fd;
  // On a stack of its own: the crash may be the stack failing to grow at the limit.
  static char alt_stack[64 * 1024];
  stack_t ss{};
  ss.ss_sp = alt_stack;
  ss.ss_size = sizeof alt_stack;
  ::sigaltstack(&ss, nullptr);
  struct sigaction sa {};
  sa.sa_handler = child_crash_handler;
  sa.sa_flags = SA_ONSTACK;
  ::sigaction(SIGSEGV, &sa, nullptr);
  ::sigaction(SIGBUS, &sa, nullptr);
  ChildHeader h{};
  tetgenio* out = nullptr;
  try {
    // TetGen 1.5.0 throws on self-intersecting input but then crashes while unwinding (in
    // ~memorypool), so detect intersections first with -d, which returns them as faces.
    tetgenio* probe = new tetgenio;  // never freed: the child ends with _exit
    char sw_d[] = "pdzQ";
    tetrahedralize(sw_d, &in, probe);
    // The probe's answer: always when it runs alone (count_self_intersections, no switches).
    if (switches.empty() || probe->numberoftrifaces > 0) {
      h.status = TetgenRun::kIntersects;
      h.count = probe->numberoftrifaces;
    } else {
      std::vector<char> buf(switches.begin(), switches.end());
      buf.push_back('\0');
      out = new tetgenio;
      tetrahedralize(buf.data(), &in, out);
      h.status = TetgenRun::kMesh;
      h.npoints = out->numberofpoints;
      h.ntets = out->numberofcorners == 4 ? out->numberoftetrahedra : 0;
    }
  } catch (int code) {
    h.status = TetgenRun::kThrew;
    h.code = code;
  } catch (const std::bad_alloc&) {
    h.status = TetgenRun::kThrew;
    h.code = 1;  // TetGen's own code for out of memory
  } catch (...) {
    h.status = TetgenRun::kThrew;
    h.code = -1;
  }
  bool ok = write_all(fd, &h, sizeof h);
  if (ok && h.status == TetgenRun::kMesh) {
    ok = write_all(fd, out->pointlist, sizeof(REAL) * 3 * std::size_t(h.npoints)) &&
         write_all(fd, out->tetrahedronlist, sizeof(int) * 4 * std::size_t(h.ntets));
  }
  ::_exit(ok ? 0 : 1);
}

TetgenRun run_tetgen_isolated(tetgenio& in, const std::string& switches, double time_limit_s, long max_points, long max_tets) {
  TetgenRun run;
  int fds[2], err[2];  // the result; TetGen's stderr (its assertion messages)
  if (::pipe2(fds, O_CLOEXEC) != 0) throw ResourceError(std::string("cannot start TetGen: pipe: ") + std::strerror(errno));
  if (::pipe2(err, O_CLOEXEC | O_NONBLOCK) != 0) {
    const int e = errno;
    ::close(fds[0]), ::close(fds[1]);
    throw ResourceError(std::string("cannot start TetGen: pipe: ") + std::strerror(e));
  }
  std::fflush(nullptr);  // the child must not inherit unwritten output
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]), ::close(fds[1]), ::close(err[0]), ::close(err[1]);
    throw ResourceError(std::string("cannot start TetGen: fork: ") + std::strerror(e));
  }
  if (pid == 0) {
    // The child dies with its parent (a `kill` of the parent's pid alone, a second Ctrl-C
    // that ends it at once): otherwise TetGen went on meshing as an orphan at full CPU.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() == 1) ::_exit(1);  // the parent died before prctl
    // TetGen prints warnings on stdout, which may be the program's data stream (--csv -):
    // discard them. Its stderr goes to the parent (non-blocking: dropped when full).
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, 1);
    ::dup2(err[1], 2);
    ::close(fds[0]);
    child_run(in, switches, fds[1]);
  }
  ::close(fds[1]);
  ::close(err[1]);
  const bool limited = time_limit_s > 0;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(limited ? static_cast<long long>(std::min(time_limit_s, 1e9) * 1000) : 0);
  bool late = false, stopped = false, complete = false;
  ChildHeader h{};
  if (read_all(fds[0], &h, sizeof h, deadline, limited, &late, &stopped)) {
    run.code = h.code;
    run.count = long(h.count);
    run.npoints = long(h.npoints);
    run.ntets = long(h.ntets);
    if (h.status == TetgenRun::kMesh) {
      if (h.npoints < 0 || h.ntets < 0 || h.npoints > max_points || h.ntets > max_tets) {
        run.status = TetgenRun::kTooLarge;  // not read: the counts alone are the answer
        complete = true;
      } else {
        run.X.resize(3 * std::size_t(h.npoints));
        run.tet.resize(4 * std::size_t(h.ntets));
        complete = read_all(fds[0], run.X.data(), sizeof(double) * run.X.size(), deadline, limited, &late, &stopped) &&
                   read_all(fds[0], run.tet.data(), sizeof(int) * run.tet.size(), deadline, limited, &late, &stopped);
        if (complete) run.status = TetgenRun::kMesh;
      }
    } else if (h.status == TetgenRun::kIntersects || h.status == TetgenRun::kThrew) {
      run.status = TetgenRun::Status(h.status);
      complete = true;
    }
  }
  ::close(fds[0]);
  if (late || stopped) ::kill(pid, SIGKILL);
  int wstatus = 0;
  pid_t w;
  do w = ::waitpid(pid, &wstatus, 0); while (w < 0 && errno == EINTR);
  if (stopped) {
    run.status = TetgenRun::kStopped;
  } else if (late) {
    run.status = TetgenRun::kTimedOut;
  } else if (!complete) {
    run.status = TetgenRun::kCrashed;
    if (w == pid && WIFSIGNALED(wstatus)) run.why = std::string("signal ") + std::to_string(WTERMSIG(wstatus)) + ", " + strsignal(WTERMSIG(wstatus));
    else if (w == pid && WIFEXITED(wstatus)) run.why = "exit status " + std::to_string(WEXITSTATUS(wstatus));
    else run.why = "ended without a result";
    char buf[4096];
    const ssize_t n = ::read(err[0], buf, sizeof buf - 1);
    if (n > 0) {  // the last line TetGen wrote, e.g. its failed assertion
      std::string text(buf, std::size_t(n));
      while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
      const std::size_t nl = text.find_last_of('\n');
      run.why += ": " + text.substr(nl == std::string::npos ? 0 : nl + 1);
    }
  }
  ::close(err[0]);
  return run;
}

}  // namespace

namespace {
// The surface as TetGen's input (coordinates times `scale`), with hole points.
void fill_tetgenio(const SurfaceMesh& surf, double scale, const std::vector<double>& holes, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = surf.npoint();
  in.pointlist = new REAL[surf.xyz.size()];
  for (std::size_t i = 0; i < surf.xyz.size(); ++i) in.pointlist[i] = surf.xyz[i] * scale;
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
  if (!holes.empty()) {
    in.numberofholes = int(holes.size() / 3);
    in.holelist = new REAL[holes.size()];
    for (std::size_t i = 0; i < holes.size(); ++i) in.holelist[i] = holes[i] * scale;
  }
}
}  // namespace

long count_self_intersections(const SurfaceMesh& s, double time_limit_s) {
  if (s.ntri() == 0) return 0;
  tetgenio in;
  fill_tetgenio(s, kMm, {}, in);
  const TetgenRun run = run_tetgen_isolated(in, "", time_limit_s, 0, 0);
  if (run.status == TetgenRun::kStopped)  // not "could not be completed": a stop was asked
    throw InputError("meshing stopped: TetGen's self-intersection check was ended before it finished");
  if (run.status != TetgenRun::kIntersects) return -1;
  return run.count;
}

std::vector<double> cavity_hole_points(const SurfaceMesh& surface) {
  std::vector<double> holes;
  // Orienting only swaps vertices within triangles: the shells, their first triangles and
  // their depths (by |winding number|) are the same before and after.
  const ShellNesting nest = shell_nesting(surface);
  if (std::none_of(nest.depth.begin(), nest.depth.end(), [](int d) { return d % 2 == 1; })) return holes;
  SurfaceMesh s = surface;
  check_and_orient_closed_surface(s, "surface");  // cavities oriented inwards (into the cavity)
  for (int c = 0; c < nest.ncomp; ++c) {
    if (nest.depth[c] % 2 == 0) continue;
    bool found = false;
    int tried = 0;
    for (int t = nest.first_tri[c]; t < s.ntri() && !found && tried < 20; ++t) {
      if (nest.tri_comp[t] != c) continue;
      ++tried;
      for (double frac : {1e-3, 1e-2, 1e-1}) {
        double p[3];
        point_off_triangle(s, t, +1, frac, p);  // the normal of a cavity's shell points into the cavity
        if (std::fabs(generalized_winding_number(s, p)) < 0.5 && std::fabs(generalized_winding_number(s, p, &nest.tri_comp, c)) > 0.5) {
          holes.insert(holes.end(), {p[0], p[1], p[2]});
          found = true;
          break;
        }
      }
    }
    if (!found)
      throw InputError("surface to mesh: no point found strictly inside the cavity bounded by shell " + std::to_string(c) +
                       " (its triangle " + std::to_string(nest.first_tri[c]) + "); the shells may intersect");
  }
  return holes;
}

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
  tetgenio in;
  fill_tetgenio(surf, to_mm, cavity_hole_points(surf), in);  // one hole point in each cavity
  const TetgenRun run = run_tetgen_isolated(in, sw_capped, o.time_limit_s,
                                            surf.npoint() + steiner_cap + 16 * long(surf.ntri()) + 64, 2 * o.max_tets + 64);
  switch (run.status) {
    case TetgenRun::kMesh:
      break;
    case TetgenRun::kIntersects:
      throw InputError("the surface intersects itself (" + std::to_string(run.count) +
                       " facets cross others); TetGen needs a closed surface without self-intersections");
    case TetgenRun::kThrew: {
      const int code = run.code;
      const char* why = code == 1 ? "out of memory"
                        : code == 2 ? "internal error"
                        : code == 3 ? "the surface intersects itself"
                        : code == 4 ? "a very small input feature (near-degenerate facets)"
                        : code == 5 ? "two very close input facets"
                        : code == 10 ? "an input error"
                                     : "unknown failure";
      if (code == 1)  // the machine, not the input (exit code 5 in the CLI)
        throw ResourceError("TetGen (-" + sw + ") ran out of memory; use a coarser mesh (mesh.max_volume, mesh.max_tets)");
      throw InputError("TetGen (-" + sw + ") failed with code " + std::to_string(code) + ": " + why);
    }
    case TetgenRun::kCrashed:
      throw InputError("TetGen (-" + sw + ") crashed on this surface (" + run.why +
                       "). TetGen 1.5 has assertions that fail on some exactly co-spherical or co-planar point "
                       "sets: move, turn or rescale the body slightly");
    case TetgenRun::kStopped:  // main() reports it as the stop it is (a signal)
      throw InputError("meshing stopped: TetGen (-" + sw + ") was ended before it finished");
    case TetgenRun::kTimedOut:
      throw InputError("TetGen (-" + sw + ") did not finish within " + num(o.time_limit_s) +
                       " s (mesh.time_limit_s); use a coarser mesh or a larger mesh.radius_edge");
    case TetgenRun::kTooLarge:
      break;  // reported below with the counts
  }
  if (run.status == TetgenRun::kMesh && run.ntets <= 0)
    throw InputError("TetGen (-" + sw + ") produced no linear tetrahedra");
  if (run.status == TetgenRun::kTooLarge || run.npoints - surf.npoint() >= steiner_cap || run.ntets > o.max_tets)
    throw InputError("mesh too large: TetGen -" + sw + " made " + std::to_string(run.ntets) +
                     " tetrahedra and " + std::to_string(run.npoints - surf.npoint()) + " added points (" +
                     num(estimated) + " tetrahedra estimated), above the budget of " + std::to_string(o.max_tets) +
                     " tetrahedra / " + std::to_string(steiner_cap) +
                     " added points (mesh.max_tets); the quality bound may not be reachable on this surface: "
                     "use a larger mesh.radius_edge or a smaller mesh.min_dihedral_deg");
  std::vector<double> X = std::move(run.X);
  for (double& x : X) x /= to_mm;
  TetMesh m = make_tet_mesh(std::move(X), std::move(run.tet));
  check_tetgen_boundary(m);
  return m;
}

void check_tetgen_boundary(const TetMesh& m) {
  const std::string bad = boundary_manifold_problem(m, [&m](int v) {
    char at[120];
    std::snprintf(at, sizeof at, "the point (%.6g, %.6g, %.6g) m", m.X[3 * v], m.X[3 * v + 1], m.X[3 * v + 2]);
    return std::string(at);
  });
  if (!bad.empty())
    throw InputError("the surface's parts touch, and TetGen joined them there: " + bad +
                     "; move the parts apart or make them one closed surface");
}

}  // namespace softtled
