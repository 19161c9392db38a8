#include "sim/io/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <tuple>
#include <utility>

#include "sim/core/input_error.h"
#include "sim/core/stop_request.h"
#include "sim/io/abrupt_exit.h"

namespace softtled {

std::string atomic_target(const std::string& path) {
  struct stat lst, st;
  if (::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode) && ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode))
    if (char* real = ::realpath(path.c_str(), nullptr)) {
      std::string r = real;
      std::free(real);
      return r;
    }
  return path;
}

OutputFile::OutputFile(std::string path, Mode mode) : path_(std::move(path)) {
  if (path_ == "-" && mode == kDirect) {
    std::fflush(stdout);  // what stdio holds goes first: from here on standard output is written with write(2)
    fd_ = STDOUT_FILENO;
    stdout_ = true;
    return;
  }
  // Atomic only for a regular file or a new name: a device (/dev/null, /dev/full) or FIFO
  // is written in place, never replaced by a renamed temporary.
  struct stat st;
  const bool exists = ::stat(path_.c_str(), &st) == 0;
  if (mode == kAtomic && (!exists || S_ISREG(st.st_mode))) {
    open_temporary(exists ? int(st.st_mode & 07777) : -1);
    return;
  }
  const std::string& open_path = path_;  // written in place from here on
  if (exists && S_ISFIFO(st.st_mode)) {
    // Opened without blocking: open(2) on a FIFO nobody reads waits for a reader, and a
    // signal (which only sets the stop flag) restarts it, so Ctrl-C could not stop the run.
    // A reader started beside the run (`run --csv p & cat p`) gets kFifoReaderWaitS to
    // open its end; then the descriptor blocks again for the writes.
    int fd = -1, e = 0;
    for (int tries = 0; tries <= kFifoReaderWaitS * 20; ++tries) {
      fd = ::open(open_path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      e = errno;
      if (fd >= 0 || e != ENXIO) break;
      if (stop_request_pending())
        throw StoppedWhileWaiting(open_path + ": stopped while waiting for the FIFO's reader");
      ::usleep(50000);
    }
    if (fd < 0)
      throw ResourceError(open_path + ": cannot write: " +
                          (e == ENXIO ? "a FIFO with no reader after " + std::to_string(kFifoReaderWaitS) +
                                            " s (start its reader first)"
                                      : std::string(std::strerror(e))));
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) < 0) {
      e = errno;
      ::close(fd);
      throw ResourceError(open_path + ": cannot write: " + std::strerror(e));
    }
    fd_ = fd;
    return;
  }
  fd_ = ::open(open_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) throw ResourceError(open_path + ": cannot write: " + std::strerror(errno));
  if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode)) regular_ = true;
}

void OutputFile::drop_temporary(bool remove) {
  if (tmp_.empty()) return;
  if (remove) std::remove(tmp_.c_str());
  untrack_abrupt_exit_file(abrupt_slot_);
  abrupt_slot_ = -1;
  tmp_.clear();
}

void OutputFile::open_temporary(int mode) {
  // A symlink is kept: its target is replaced (the temporary written beside it).
  target_ = atomic_target(path_);
  tmp_ = target_ + ".tmp";
  // Tracked before it exists, so that a second Ctrl-C arriving during open(2) still removes
  // it (tracked after, a 0-byte NAME.tmp was left in 4 of 15 double Ctrl-Cs); created
  // exclusively, after an earlier run's leftover temporary (a regular file) is removed, so
  // the name tracked is ours once open succeeds. Whatever else holds the name (a directory,
  // a FIFO, a symlink) is refused before it is tracked, so the handler never removes it;
  // O_EXCL | O_NOFOLLOW also fails on one that appears in between.
  auto held = [&](const std::string& what) {
    const std::string t = tmp_;
    tmp_.clear();  // not ours: never removed
    return ResourceError(path_ + ": cannot write its temporary " + t + ": " + what + "; move it away");
  };
  struct stat st;
  if (::lstat(tmp_.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode))
      throw held(S_ISDIR(st.st_mode) ? "a directory holds its name" : S_ISFIFO(st.st_mode) ? "a FIFO holds its name"
                 : S_ISLNK(st.st_mode) ? "a symlink holds its name" : "a special file holds its name");
    if (::unlink(tmp_.c_str()) != 0) throw held(std::string("an earlier file there cannot be removed: ") + std::strerror(errno));
  }
  abrupt_slot_ = track_abrupt_exit_file(tmp_);
  const int fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0666);
  if (fd < 0 || ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const int e = errno;
    if (fd >= 0) {  // ours, created: removed
      ::close(fd);
      ::unlink(tmp_.c_str());
    }
    untrack_abrupt_exit_file(abrupt_slot_);
    abrupt_slot_ = -1;
    // Something appeared at the name in between; any other reason (a missing directory, no
    // permission) is the output's own.
    if (fd < 0 && (e == EEXIST || e == EISDIR || e == ENXIO || e == ELOOP)) throw held(std::strerror(e));
    tmp_.clear();
    throw ResourceError(path_ + ": cannot write: " + std::strerror(e));
  }
  // The replaced file's permissions carry over (a private file stays private); a new file
  // gets 0666 less the umask, as open(2) gave it.
  if (mode >= 0) ::fchmod(fd, mode_t(mode));
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  fd_ = fd;
}

OutputFile::~OutputFile() {
  if (fd_ >= 0 && !stdout_) ::close(fd_);
  drop_temporary(true);
}

void OutputFile::fail(const char* what, bool stopped) {
  const int e = errno;
  std::string msg = (stdout_ ? std::string("standard output") : path_) + ": " + what +
                    (e && !stopped ? std::string(": ") + std::strerror(e) : std::string());
  if (fd_ >= 0 && !stdout_) ::close(fd_);
  fd_ = -1;
  buf_.clear();
  drop_temporary(true);
  if (regular_ && ::truncate(path_.c_str(), off_t(flushed_)) != 0)
    msg += std::string(" (and it could not be cut back to its last complete record: ") + std::strerror(errno) + ")";
  regular_ = false;
  if (stopped) throw StoppedWhileWaiting(msg);
  throw ResourceError(msg);
}

void OutputFile::write_all(const char* data, std::size_t n) {
  // A stop signal interrupts a write that waits for its reader (no SA_RESTART): EINTR, or
  // a short count where part was taken before it (a pipe or FIFO blocks until all of it is,
  // else). Given up then, as the command is stopping; any other signal's is retried.
  constexpr const char* kStopped = "stopped while the write waited for its reader to read";
  while (n > 0) {
    const ssize_t w = ::write(fd_, data, n);
    if (w >= 0) {
      data += w, n -= std::size_t(w);
      if (n > 0 && stop_request_pending()) fail(kStopped, true);
      continue;
    }
    if (errno == EINTR && stop_request_pending()) fail(kStopped, true);
    if (errno != EINTR) fail("write failed");
  }
}

void OutputFile::write(const char* data, std::size_t n) {
  if (fd_ < 0) throw ResourceError(path_ + ": write after close");
  // Buffered up to kBuffer bytes, as stdio buffered (a writer may hand a record over in
  // pieces); a piece that large goes out at once, not copied.
  constexpr std::size_t kBuffer = 1 << 16;
  written_ += (long long)n;
  if (buf_.size() + n > kBuffer) {
    write_all(buf_.data(), buf_.size());
    buf_.clear();
    if (n >= kBuffer) return write_all(data, n);
  }
  buf_.append(data, n);
}

void OutputFile::flush() {
  if (fd_ < 0) return;
  write_all(buf_.data(), buf_.size());
  buf_.clear();
  flushed_ = written_;
}

void OutputFile::finish() {
  if (fd_ < 0) return;
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (stdout_) return;
  // close(2) reports a deferred write error (NFS, a full quota); EINTR there has closed the
  // descriptor all the same (Linux).
  if (::close(fd) != 0 && errno != EINTR) {
    const int e = errno;
    drop_temporary(true);
    throw ResourceError(path_ + ": write failed: " + std::strerror(e));
  }
}

void OutputFile::commit() {
  if (tmp_.empty()) return;
  if (std::rename(tmp_.c_str(), target_.c_str()) != 0) {
    const int e = errno;
    drop_temporary(true);
    throw ResourceError(path_ + ": cannot replace it with " + target_ + ".tmp: " + std::strerror(e));
  }
  drop_temporary(false);
}

void OutputFile::close() {
  finish();
  commit();
}

void write_file_atomic(const std::string& path, const std::string& content) {
  OutputFile f(path, OutputFile::kAtomic);
  f.write(content);
  f.close();
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  // Every temporary complete before the first rename; on a failure the ones this call
  // created are removed (by their OutputFile), never a name it did not create.
  std::vector<std::unique_ptr<OutputFile>> out;
  for (const auto& [path, content] : files) {
    out.push_back(std::make_unique<OutputFile>(path, OutputFile::kAtomic));
    out.back()->write(content);
    out.back()->finish();
  }
  for (auto& f : out) f->commit();
}

namespace {
constexpr const char* kStdoutName = "standard output";
constexpr const char* kStderrName = "standard error";
// "standard output" or "standard error" when st is the file or pipe that stream goes to
// (same device and inode), else nullptr. Standard output is named first.
const char* standard_stream_of(const struct stat& st) {
  for (const auto& [fd, name] : {std::pair<int, const char*>{STDOUT_FILENO, kStdoutName}, {STDERR_FILENO, kStderrName}}) {
    struct stat ss;
    if (::fstat(fd, &ss) == 0 && ss.st_dev == st.st_dev && ss.st_ino == st.st_ino) return name;
  }
  return nullptr;
}
bool g_guard_stderr = false;  // guard_stderr_of_files
// Before refusing because a standard stream goes to a file the command reads or writes (st):
// where standard error goes to that file too and it holds something (2>> or &>> onto it),
// the refusal itself would be appended to what it protects (2>> scene.toml left the scene
// unparsable, 2>> out.csv a ragged last row), so standard error is pointed at the
// controlling terminal when this process is in its foreground (a background one would be
// stopped by SIGTTOU under `stty tostop`), else at /dev/null. An empty file (2> f made it)
// takes the message, as asked.
void keep_stderr_out_of(const struct stat& st) {
  struct stat se;
  if (!g_guard_stderr || st.st_size == 0 || ::fstat(STDERR_FILENO, &se) != 0 || !S_ISREG(se.st_mode) ||
      se.st_dev != st.st_dev || se.st_ino != st.st_ino)
    return;
  std::fflush(stderr);
  int fd = ::open("/dev/tty", O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (fd >= 0 && ::tcgetpgrp(fd) != ::getpgrp()) ::close(fd), fd = -1;
  if (fd < 0) fd = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (fd >= 0) ::dup2(fd, STDERR_FILENO), ::close(fd);
}
std::string parent_of(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string parent = p.parent_path().string();
  return parent.empty() ? "." : parent;
}
}  // namespace

namespace {
// A path the command creates must fit PATH_MAX with its terminating NUL: a longer one
// (NAME.tmp of a 4093-character NAME, a frame in a 4080-character --vtu directory) passed the
// checks and failed with "File name too long" when it was opened, after the work (exit 5).
// what: the file, as the message names it.
void check_path_length(std::size_t length, const std::string& where, const std::string& what) {
  if (length < std::size_t(PATH_MAX)) return;
  throw InputError(where + what + " would be a path of " + std::to_string(length) +
                   " characters, above the system's limit of " + std::to_string(PATH_MAX - 1) +
                   " (File name too long); give a shorter path");
}

// PATH.tmp, which an atomic output is written to first, must be a name the directory can
// hold and not be taken by anything but a regular file: a 253-character name, or a
// directory or FIFO called PATH.tmp, failed the command after its work (exit 5).
void check_temporary_name(const std::string& output, const std::string& where) {
  const std::string path = atomic_target(output);  // where the temporary goes: beside a symlink's target
  const std::string name = std::filesystem::path(path).filename().string();
  long max = ::pathconf(parent_of(path).c_str(), _PC_NAME_MAX);
  if (max <= 0) max = 255;
  if (long(name.size()) + 4 > max)
    throw InputError(where + "a name of " + std::to_string(name.size()) + " characters; with the .tmp it is written under " +
                     "first it must fit the directory's " + std::to_string(max));
  check_path_length(path.size() + 4, where, "the NAME.tmp it is written to first");
  struct stat st;
  const std::string tmp = path + ".tmp";
  if (::lstat(tmp.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(where + "it is written to " + tmp + " first, which is " +
                     (S_ISDIR(st.st_mode) ? "a directory" : S_ISLNK(st.st_mode) ? "a symbolic link" : "a special file") +
                     "; move it away");
}
}  // namespace

void guard_stderr_of_files(bool on) { g_guard_stderr = on; }

void check_streams_not_into(const std::string& path, const std::string& what) {
  check_distinct_paths({{path, what}});  // one input alone: only its test against the streams applies
}

void check_no_nul(const std::string& path, const std::string& what) {
  const auto nul = path.find('\0');
  if (nul != std::string::npos)
    throw InputError((what.empty() ? "" : what + " ") + path.substr(0, nul) + "...: the path holds a NUL byte");
}

void check_png_name(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if ((!std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) && ext != ".png")
    throw InputError(what + " " + path + ": this writes a PNG; give a name ending in .png");
}

void check_output_file(const std::string& path, const std::string& what, bool allow_stdout, bool in_place) {
  if (path == "-" && allow_stdout) return;
  if (path == "-")
    throw InputError(what + " -: standard output is not an option here; give a file name (./- for a file named '-')");
  const std::string where = what + " " + path + ": ";
  if (path.empty()) throw InputError(what + ": empty path");
  check_no_nul(path, what);
  if (path.back() == '/') throw InputError(where + "is a directory name; give a file name");
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw InputError(where + "is a directory; give a file name");
    // The file or pipe standard output or standard error already goes to (--csv
    // /dev/stdout, --csv f > f, --csv f 2> f, --csv /dev/stderr): the command's messages and
    // this output would overwrite or interleave. A device (/dev/null, a terminal) takes both.
    if (!S_ISCHR(st.st_mode)) {
      if (const char* stream = standard_stream_of(st)) {
        keep_stderr_out_of(st);
        throw InputError(where + "is where " + stream + " goes, and the messages would mix with it" +
                         (allow_stdout && stream == kStdoutName ? " (give - to write it to standard output)" : ""));
      }
    }
    if (::access(path.c_str(), W_OK) != 0) throw InputError(where + "cannot write: " + std::strerror(errno));
    if (S_ISREG(st.st_mode) && !in_place) {  // replaced through PATH.tmp in its (target's) directory
      const std::string dir = parent_of(atomic_target(path));
      if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw InputError(where + "cannot replace it: cannot write in directory " + dir + ": " + std::strerror(errno));
      check_temporary_name(path, where);
    }
    return;
  }
  if (errno != ENOENT) throw InputError(where + "cannot write: " + std::strerror(errno));
  const std::string dir = parent_of(path);
  if (::stat(dir.c_str(), &st) != 0)
    throw InputError(where + "directory " + dir + " does not exist: " + std::strerror(errno));
  if (!S_ISDIR(st.st_mode)) throw InputError(where + dir + " is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(where + "cannot write in directory " + dir + ": " + std::strerror(errno));
  if (!in_place) check_temporary_name(path, where);
}

void check_output_dir(const std::string& path, const std::string& what) {
  const std::string where = what + " " + path + ": ";
  if (path.empty()) throw InputError(what + ": empty path");
  check_no_nul(path, what);
  std::string p = path;
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  for (;;) {
    struct stat st;
    if (::stat(p.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        throw InputError(where + (p == path ? std::string("exists and is not a directory") : p + " is not a directory"));
      if (::access(p.c_str(), W_OK | X_OK) != 0) throw InputError(where + "cannot write in " + p + ": " + std::strerror(errno));
      return;
    }
    if (errno != ENOENT && errno != ENOTDIR) throw InputError(where + "cannot use " + p + ": " + std::strerror(errno));
    const std::string parent = parent_of(p);
    if (parent == p) throw InputError(where + "no existing parent directory");
    p = parent;
  }
}

}  // namespace softtled

namespace softtled {
namespace {
// false for "-", empty paths and existing files that are neither regular files nor (for a
// directory output) directories: those are never compared.
bool comparable(const PathUse& u) {
  const std::string& p = u.path;
  if (p.empty() || p == "-") return false;
  struct stat st;
  if (::stat(p.c_str(), &st) == 0) return S_ISREG(st.st_mode) || (u.output_dir && S_ISDIR(st.st_mode));
  return true;
}
// The absolute path of the file p names once every symlink on the way is followed, a
// dangling last one's too (a write through it creates the file it names: `--csv c.csv`
// where c.csv -> v/frame_00002.vtu, not there yet, is that frame).
std::string resolved(const std::string& p) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path cur = fs::absolute(p, ec);
  if (ec) return p;
  for (int hops = 0; hops < 40; ++hops) {  // 40: the kernel's own limit on links followed
    fs::path c = fs::weakly_canonical(cur, ec);
    cur = ec ? cur.lexically_normal() : c;
    struct stat st;
    if (::lstat(cur.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) break;  // weakly_canonical leaves only a dangling one
    std::string target(PATH_MAX, '\0');
    const ssize_t n = ::readlink(cur.c_str(), target.data(), target.size());
    if (n <= 0) break;
    target.resize(std::size_t(n));
    cur = fs::path(target).is_absolute() ? fs::path(target) : cur.parent_path() / target;
  }
  std::string s = cur.string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}
bool same_file(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  const bool ea = ::stat(a.c_str(), &sa) == 0, eb = ::stat(b.c_str(), &sb) == 0;
  if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (ea != eb) return false;
  return resolved(a) == resolved(b);
}
// A name a directory output writes (series.pvd, frame_*.vtu, their .tmp, and a first
// frame staged as .new beside an earlier series': VtuSeries::add).
bool series_name(const std::string& name) {
  std::string base = name;
  for (const char* suffix : {".tmp", ".new"})
    if (base.size() > 4 && base.compare(base.size() - 4, 4, suffix) == 0) base.resize(base.size() - 4);
  return base == "series.pvd" ||
         (base.rfind("frame_", 0) == 0 && base.size() > 4 && base.compare(base.size() - 4, 4, ".vtu") == 0);
}
// The series file of dir that file is, by the name given or by the file it resolves to
// (a symlink elsewhere naming dir/frame_00001.vtu), or "" when it is none.
std::string written_in_dir(const std::string& file, const std::string& dir) {
  for (const std::string& f : {file, resolved(file)}) {
    const std::filesystem::path fp(f);
    const std::string parent = fp.parent_path().string();
    if (series_name(fp.filename().string()) && same_file(parent.empty() ? "." : parent, dir)) return f;
  }
  return "";
}
// The files dir holds under the names its series writes: each is replaced or removed by
// the run, so none may be (a hard link to) an input or another output.
std::vector<std::string> series_entries(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (series_name(e.path().filename().string())) out.push_back(e.path().string());
  return out;
}
// The longest name a series writes in its directory: frame_%05zu (up to 1e8 + 1 output
// times: 9 digits), a body's _bK (kMaxBodies = 32 in scene.h), and .new.tmp when staged
// beside an earlier frame of that name (VtuSeries::add).
constexpr const char* kLongestSeriesName = "frame_100000000_b31.vtu.new.tmp";
}  // namespace

void check_series_dir(const std::string& path, const std::string& what) {
  check_output_dir(path, what);
  check_path_length(path.size() + 1 + std::strlen(kLongestSeriesName), what + " " + path + ": ",
                    std::string("a file the series writes there (up to ") + kLongestSeriesName + ")");
  // Never written through a symlink: an atomic write replaces the file a link names (the
  // scene, when DIR/series.pvd -> ../scene.toml), and the frames an earlier index lists
  // are removed.
  for (const std::string& f : series_entries(path)) {
    struct stat st;
    if (::lstat(f.c_str(), &st) != 0 || S_ISREG(st.st_mode)) continue;
    std::string kind = S_ISDIR(st.st_mode) ? "a directory" : "a special file";
    if (S_ISLNK(st.st_mode)) {
      std::string target(PATH_MAX, '\0');
      const ssize_t n = ::readlink(f.c_str(), target.data(), target.size());
      target.resize(n > 0 ? std::size_t(n) : 0);
      kind = "a symbolic link to " + target + ", which the series would write through";
    }
    throw InputError(what + " " + path + ": " + f + " is not a regular file (" + kind +
                     "), and the series writes a file of that name; move it away");
  }
}

void check_distinct_paths(const std::vector<PathUse>& paths) {
  // Standard output or standard error sent to a regular file (> f, >> f, 2> f) is an output
  // too: not an input, nor a file a directory output writes.
  for (const auto& [fd, stream] : {std::pair<int, const char*>{STDOUT_FILENO, kStdoutName}, {STDERR_FILENO, kStderrName}}) {
    struct stat so;
    if (::fstat(fd, &so) != 0 || !S_ISREG(so.st_mode)) continue;
    for (const PathUse& u : paths) {
      if (!comparable(u)) continue;
      auto is_stream = [&](const std::string& p) {
        struct stat st;
        return ::stat(p.c_str(), &st) == 0 && st.st_dev == so.st_dev && st.st_ino == so.st_ino;
      };
      std::string hit = u.output_dir ? "" : (is_stream(u.path) ? u.path : "");
      // An atomic output's temporary, renamed onto it at the end: the stream's buffered
      // text, flushed at exit, would land in the finished output.
      if (hit.empty() && u.output && !u.output_dir && !u.in_place && is_stream(atomic_target(u.path) + ".tmp"))
        hit = atomic_target(u.path) + ".tmp";
      if (u.output_dir)
        for (const std::string& e : series_entries(u.path))
          if (is_stream(e)) hit = e;
      if (hit.empty()) continue;
      keep_stderr_out_of(so);
      throw InputError(u.what + " " + u.path + ": " + stream + " goes to " + hit + ", which " +
                       (u.output ? "this output writes" : "is an input") + "; send " + stream + " elsewhere");
    }
  }
  for (std::size_t i = 0; i < paths.size(); ++i)
    for (std::size_t j = 0; j < paths.size(); ++j) {
      const PathUse &a = paths[i], &b = paths[j];
      if (i == j || !a.output || !comparable(a) || !comparable(b)) continue;
      const std::string both = a.what + " " + a.path + " and " + b.what + " " + b.path;
      const std::string other = b.output ? "the other output" : "the input";
      // A replaced file is written to PATH.tmp first (write_file_atomic), beside a
      // symlink's target: that name is taken too.
      if (!a.output_dir && !a.in_place && same_file(atomic_target(a.path) + ".tmp", b.path))
        throw InputError(both + ": " + a.what + " is written to " + atomic_target(a.path) + ".tmp first, which is " +
                         other);
      if (b.output && j < i) continue;
      if (same_file(a.path, b.path))
        throw InputError(both + " are the same file: the " + (b.output ? "second output would overwrite the first"
                                                                        : "output would overwrite the input"));
      // A directory output's files: those of its names already there, by device and inode
      // (a hard link to the scene), and any of its names the other path is or resolves to.
      for (const auto& [dir, file, file_is] : {std::tuple<const PathUse*, const PathUse*, std::string>{&a, &b, other},
                                               {&b, &a, "the other output"}}) {
        if (!dir->output_dir || file->output_dir) continue;
        std::string hit = written_in_dir(file->path, dir->path);
        if (hit.empty())
          for (const std::string& e : series_entries(dir->path))
            if (same_file(e, file->path)) hit = e;
        if (!hit.empty())
          throw InputError(both + ": " + dir->what + " writes " + std::filesystem::path(hit).filename().string() +
                           " in that directory, overwriting " + file_is);
      }
    }
}

}  // namespace softtled
