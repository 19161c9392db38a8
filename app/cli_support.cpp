#include "app/cli_support.h"

#include <cerrno>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <unistd.h>

#include "sim/core/stop_request.h"
#include "sim/core/input_error.h"
#include "sim/io/abrupt_exit.h"
#include "sim/io/output_file.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/solver/solver_factory.h"
#if defined(SOFTTLED_HAVE_CUDA)
#include "sim/solver/cuda/device_info.h"
#endif

namespace softtled {

bool g_verbose = false;

namespace {
std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int sig) {
  if (g_stop) {  // second signal: do not wait for the step to finish
    remove_on_abrupt_exit();  // temporaries being written, ffmpeg's process group
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  g_stop = sig;
}
}  // namespace

CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        double v;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
        if (!std::isfinite(v)) return "must be finite, got " + s;
        if (v < lo || v > hi) return "value " + s + " not in [" + fmt(lo) + ", " + fmt(hi) + "]";
        return {};
      },
      "in [" + fmt(lo) + ", " + fmt(hi) + "]");
}

CLI::Validator int_range(long lo, long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        long v;
        if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not an integer in range";
        if (v < lo || v > hi) return "value " + s + " not in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        return {};
      },
      "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

void install_stop_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  // No SA_RESTART: a write blocked on a reader that does not read (run --csv FIFO, --csv -
  // into a stalled pipe) returns EINTR and the stop is seen (OutputFile); restarted, it
  // blocked until a second signal ended the program without its closing line. Blocking
  // calls elsewhere retry EINTR (TetGen's pipe, ffmpeg's, waitpid); stdio does not, so
  // messages written to a stalled stdout or stderr while a stop is under way may be lost.
  sa.sa_flags = 0;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGHUP, &sa, nullptr);  // a closed terminal: stop as for SIGTERM
  // TetGen is killed at once, not awaited; an output FIFO's wait for its reader and the
  // start-up's stable-step estimate end too.
  set_stop_request_check([] { return stop_requested(); });
}

int stop_signal() { return int(g_stop); }

namespace {
extern "C" void on_abrupt_signal(int sig) {
  remove_on_abrupt_exit();  // temporaries being written, ffmpeg's process group
  std::signal(sig, SIG_DFL);
  std::raise(sig);  // delivered when the handler returns (blocked in it): the program dies of it
}
}  // namespace

void install_abrupt_exit_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_abrupt_signal;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGPIPE, SIGQUIT, SIGALRM, SIGUSR1, SIGUSR2, SIGXCPU}) {
    struct sigaction old {};
    // An ignored signal stays ignored (`trap '' PIPE`: a closed pipe is then EPIPE, exit 5).
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_DFL) sigaction(sig, &sa, nullptr);
  }
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '"' || c == '\\') {
      o += '\\', o += char(c), ++i;
    } else if (c < 0x20 || c == 0x7f) {  // control characters: \n, \t, \r, else \u00XX
      char u[8];
      std::snprintf(u, sizeof u, "\\u%04x", c);
      o += c == '\n' ? "\\n" : c == '\t' ? "\\t" : c == '\r' ? "\\r" : u, ++i;
    } else if (c < 0x80) {
      o += char(c), ++i;
    } else {
      // A well-formed UTF-8 sequence is copied (no overlong form, surrogate or code point
      // above U+10FFFF, RFC 3629); any other byte becomes U+FFFD.
      const std::size_t len = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
      bool ok = len > 0 && i + len <= s.size();
      for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xc0) == 0x80;
      if (ok && len > 2) {
        const unsigned char c1 = static_cast<unsigned char>(s[i + 1]);
        ok = !(c == 0xe0 && c1 < 0xa0) && !(c == 0xed && c1 > 0x9f) && !(c == 0xf0 && c1 < 0x90) &&
             !(c == 0xf4 && c1 > 0x8f);
      }
      if (ok) {
        o.append(s, i, len), i += len;
      } else {
        o += "\xef\xbf\xbd", ++i;
      }
    }
  }
  return o + "\"";
}

namespace {
int g_stdout_errno = 0;
}

void flush_stdout() {
  errno = 0;
  if ((std::fflush(stdout) != 0 || std::ferror(stdout)) && g_stdout_errno == 0) g_stdout_errno = errno;
}

int stdout_errno() { return g_stdout_errno; }

int exit_code_for_signal(int sig) {
  return sig == SIGINT ? kExitSigint : sig == SIGTERM ? kExitSigterm : sig == SIGHUP ? kExitSighup : 128 + sig;
}

std::string resolve_backend(const std::string& requested) {
  if (requested != "auto") {
    check_backend_available(requested);  // "cuda" without CUDA or a device: refused here, before any work
    return requested;
  }
#if defined(SOFTTLED_HAVE_CUDA)
  std::string why;
  if (cuda::device_count(&why) > 0) return "cuda";
  if (g_verbose) std::fprintf(stderr, "backend auto: %s; running on the CPU\n", why.c_str());
#else
  if (g_verbose) std::fprintf(stderr, "backend auto: no CUDA backend in this build; running on the CPU\n");
#endif
  return "cpu";
}

std::unique_ptr<Simulation> make_simulation(const Scene& s, const std::string& backend) {
  try {
    return std::make_unique<Simulation>(s, resolve_backend(backend));
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.compare(0, s.source.size(), s.source) == 0) throw;
    throw InputError(s.source + ": " + what);
  }
}

long checked_step_count(double duration, double dt, const std::string& what, bool frame_time) {
  if (!(dt > 0 && std::isfinite(dt))) throw InputError(what + ": the time step " + fmt(dt) + " s is not positive");
  if (!(duration >= 0 && std::isfinite(duration))) throw InputError(what + ": " + fmt(duration) + " s is not a finite time >= 0");
  const double steps = std::nearbyint(duration / dt);
  if (!(steps <= kMaxRunSteps))
    throw InputError(what + ": " + fmt(duration) + " s at dt = " + fmt(dt) + " s is " + fmt(duration / dt) +
                     " steps, above the limit of " + fmt(kMaxRunSteps));
  if (duration > 0 && steps < 1 && !frame_time)
    throw InputError(what + ": " + fmt(duration) + " s is shorter than half the time step dt = " + fmt(dt) +
                     " s, so no step would run");
  return long(steps);
}

int time_decimals(double dt) {
  if (!(dt > 0)) return 6;
  const int d = int(std::ceil(-std::log10(dt))) + 2;
  return std::max(6, std::min(17, d));
}

LongRunWarning::LongRunWarning(const char* what, double t_end) : what_(what), t_end_(t_end), tty_(isatty(2)) {}

void LongRunWarning::check(double t_now) {
  constexpr double kAfterS = 2, kWarnFromS = 300;
  if (warned_) return;
  const double w = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (!(w > kAfterS) || !(t_now > 0) || !(t_now < t_end_)) return;
  warned_ = true;
  const double left = w / t_now * (t_end_ - t_now);
  if (left > kWarnFromS)
    std::fprintf(stderr,
                 "%swarning: this %s will take about %.0f more minutes of wall time (%.1f %% done after %.0f s); "
                 "Ctrl-C stops it and keeps the output written so far\n",
                 tty_ ? "\n" : "", what_, left / 60, 100.0 * t_now / t_end_, w);
}

}  // namespace softtled
