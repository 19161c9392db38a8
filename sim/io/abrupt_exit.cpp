#include "sim/io/abrupt_exit.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstring>

namespace softtled {

namespace {
constexpr int kSlots = 32;
// A file slot: state 0 free, 1 being filled, 2 a path to remove.
struct FileSlot {
  std::atomic<int> state{0};
  char path[PATH_MAX];
};
FileSlot g_files[kSlots];
std::atomic<pid_t> g_groups[kSlots];  // 0: free
// The process the table belongs to. A forked child (TetGen's) inherits the table and the
// handlers: dying of SIGPIPE there, it must not remove the parent's temporaries or kill ffmpeg.
const pid_t g_owner = ::getpid();
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free,
              "the handler reads these atomics: they must be lock-free");
}  // namespace

int track_abrupt_exit_file(const std::string& path) {
  if (path.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int free = 0;
    if (g_files[i].state.compare_exchange_strong(free, 1)) {
      std::memcpy(g_files[i].path, path.c_str(), path.size() + 1);
      g_files[i].state.store(2);
      return i;
    }
  }
  return -1;
}

void untrack_abrupt_exit_file(int slot) {
  if (slot >= 0 && slot < kSlots) g_files[slot].state.store(0);
}

int track_abrupt_exit_group(pid_t pgid) {
  for (int i = 0; i < kSlots; ++i) {
    pid_t free = 0;
    if (pgid > 0 && g_groups[i].compare_exchange_strong(free, pgid)) return i;
  }
  return -1;
}

void untrack_abrupt_exit_group(int slot) {
  if (slot >= 0 && slot < kSlots) g_groups[slot].store(0);
}

void remove_on_abrupt_exit() {
  if (::getpid() != g_owner) return;
  for (auto& g : g_groups) {
    const pid_t p = g.load();
    if (p > 0) ::kill(-p, SIGKILL);
  }
  for (auto& f : g_files)
    if (f.state.load() == 2) ::unlink(f.path);
}

}  // namespace softtled
