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
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGHUP, &sa, nullptr);  // a closed terminal: stop as for SIGTERM
  // TetGen is killed at once, not awaited; an output FIFO's wait for its reader and the
  // start-up's stable-step estimate end too.
  set_stop_request_check([] { return stop_requested(); });
}

int stop_signal() { return int(g_stop); }

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
