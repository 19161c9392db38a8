#include "app/video_encoder.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <vector>

#include "sim/core/input_error.h"
#include "sim/io/abrupt_exit.h"
#include "sim/io/output_file.h"

extern char** environ;

namespace softtled {

namespace {
// The -f container for a file name's extension, "" when not supported.
std::string container_for(const std::string& path) {
  auto ends = [&](const char* e) {
    const std::size_t n = std::strlen(e);
    if (path.size() <= n) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (std::tolower(static_cast<unsigned char>(path[path.size() - n + i])) != e[i]) return false;
    return true;
  };
  if (ends(".mp4")) return "mp4";
  if (ends(".mov")) return "mov";
  if (ends(".mkv")) return "matroska";
  return "";
}

// "" when the MP4/MOV file's top-level boxes run exactly to its end and include the
// 'moov' index (written last, as the trailer: a write failure there leaves it out or cut).
std::string mp4_incomplete(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::string("cannot read it back: ") + std::strerror(errno);
  f.seekg(0, std::ios::end);
  const std::uint64_t size = std::uint64_t(f.tellg());
  std::uint64_t pos = 0;
  bool moov = false;
  while (pos < size) {
    unsigned char hd[16];
    if (size - pos < 8) return "a box header cut at byte " + std::to_string(pos);
    f.seekg(std::streamoff(pos));
    if (!f.read(reinterpret_cast<char*>(hd), 8)) return "read error at byte " + std::to_string(pos);
    std::uint64_t len = (std::uint64_t(hd[0]) << 24) | (std::uint64_t(hd[1]) << 16) | (std::uint64_t(hd[2]) << 8) | hd[3];
    const std::string type(reinterpret_cast<const char*>(hd + 4), 4);
    if (len == 1) {
      if (size - pos < 16 || !f.read(reinterpret_cast<char*>(hd + 8), 8)) return "a box header cut at byte " + std::to_string(pos);
      len = 0;
      for (int i = 8; i < 16; ++i) len = (len << 8) | hd[i];
    } else if (len == 0) {
      len = size - pos;
    }
    if (len < 8 || len > size - pos) return "box '" + type + "' at byte " + std::to_string(pos) + " runs past the end of the file";
    if (type == "moov") moov = true;
    pos += len;
  }
  return moov ? "" : "no 'moov' index (the trailer was not written)";
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}
}  // namespace

std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream in(path);
  std::string dir;
  while (std::getline(in, dir, ':')) {
    const std::string p = (dir.empty() ? "." : dir) + "/ffmpeg";
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

void check_video_output(const std::string& path, const std::string& what) {
  if (container_for(path).empty())
    throw InputError(what + " " + path + ": the file name must end in .mp4, .mov or .mkv (H.264 video)");
  check_output_file(path, what);
  // The video is written to NAME.tmp and renamed onto NAME (an MP4's index is written last,
  // so it cannot stream into a pipe): a FIFO or device at NAME, or a symlink to one, was
  // replaced by a regular file, its reader left waiting.
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(what + " " + path + ": is " + (S_ISFIFO(st.st_mode) ? "a FIFO" : "a special file") +
                     "; a video is written to a regular file (its index comes last), so give a file name");
  if (find_ffmpeg().empty())
    throw ResourceError(what + " " + path + ": ffmpeg not found on PATH; install Debian's ffmpeg package (scripts/setup.sh does)");
}

VideoEncoder::VideoEncoder(std::string path, int w, int h, double fps)
    : path_(std::move(path)), target_(atomic_target(path_)), tmp_(target_ + ".tmp"), w_(w), h_(h), fps_(fps) {
  check_video_output(path_, "video");
  const std::string ffmpeg = find_ffmpeg();
  char log_name[] = "/tmp/softtled-ffmpeg-XXXXXX";
  const int log_fd = ::mkstemp(log_name);
  if (log_fd < 0) throw ResourceError(std::string("cannot create a log file for ffmpeg: ") + std::strerror(errno));
  log_ = log_name;
  int pipe_fd[2];
  if (::pipe2(pipe_fd, O_CLOEXEC) != 0) {
    const int e = errno;
    ::close(log_fd);
    std::remove(log_.c_str());
    throw ResourceError(std::string("cannot create a pipe to ffmpeg: ") + std::strerror(e));
  }
  const std::string size = std::to_string(w) + "x" + std::to_string(h);
  std::vector<std::string> args = {ffmpeg, "-hide_banner", "-loglevel", "error", "-y",
                                   // input: raw RGBA frames on standard input
                                   "-f", "rawvideo", "-pix_fmt", "rgba", "-s", size, "-framerate", number(fps), "-i", "-",
                                   // yuv420p needs even sides: pad odd ones by a pixel
                                   "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-preset", "veryfast",
                                   "-crf", "18", "-pix_fmt", "yuv420p", "-f", container_for(path_), tmp_};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, pipe_fd[0], 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, log_fd, 2);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setpgroup(&attr, 0);  // its own process group: Ctrl-C reaches softtled only
  sigset_t def;
  sigemptyset(&def);
  sigaddset(&def, SIGPIPE);
  sigaddset(&def, SIGINT);
  sigaddset(&def, SIGTERM);
  posix_spawnattr_setsigdefault(&attr, &def);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
  const int rc = posix_spawn(&pid_, ffmpeg.c_str(), &fa, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  ::close(pipe_fd[0]);
  ::close(log_fd);
  if (rc != 0) {
    pid_ = -1;
    ::close(pipe_fd[1]);
    std::remove(log_.c_str());
    throw ResourceError("cannot start " + ffmpeg + ": " + std::strerror(rc));
  }
  fd_ = pipe_fd[1];
  // A second Ctrl-C ends softtled at once: ffmpeg's group is killed and its files removed.
  group_slot_ = track_abrupt_exit_group(pid_);  // its own group: pgid = pid
  tmp_slot_ = track_abrupt_exit_file(tmp_);
  log_slot_ = track_abrupt_exit_file(log_);
}

void VideoEncoder::reaped() {
  pid_ = -1;
  untrack_abrupt_exit_group(group_slot_);  // the pid may be reused from now on
  group_slot_ = -1;
}

VideoEncoder::~VideoEncoder() {
  abort_child();
  if (!log_.empty()) std::remove(log_.c_str());
  untrack_abrupt_exit_file(tmp_slot_);
  untrack_abrupt_exit_file(log_slot_);
}

void VideoEncoder::abort_child() {
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int st = 0;
    while (::waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
    }
    reaped();
    std::remove(tmp_.c_str());
  }
}

std::string VideoEncoder::ffmpeg_log() const {
  std::ifstream f(log_);
  std::string line, text;
  std::vector<std::string> lines;
  while (std::getline(f, line))
    if (!line.empty()) lines.push_back(line);
  for (std::size_t i = lines.size() > 4 ? lines.size() - 4 : 0; i < lines.size(); ++i) text += (text.empty() ? "" : "; ") + lines[i];
  return text.empty() ? "no message" : text;
}

bool VideoEncoder::ffmpeg_logged_errors() const {
  std::ifstream f(log_);
  std::string line;
  while (std::getline(f, line))
    for (char c : line)
      if (!std::isspace(static_cast<unsigned char>(c))) return true;
  return false;
}

void VideoEncoder::fail(const std::string& what) {
  // ffmpeg may still be writing its message: close its input and wait before reading it.
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
  if (pid_ > 0) {
    int st = 0;
    while (::waitpid(pid_, &st, 0) < 0 && errno == EINTR) {
    }
    reaped();
  }
  std::remove(tmp_.c_str());
  throw ResourceError(path_ + ": " + what + " (ffmpeg: " + ffmpeg_log() + ")");
}

void VideoEncoder::write(const Image& im) {
  if (fd_ < 0) throw std::logic_error("VideoEncoder::write after finish");
  if (im.w != w_ || im.h != h_)
    throw std::logic_error("video frame " + std::to_string(im.w) + "x" + std::to_string(im.h) + " in a " +
                           std::to_string(w_) + "x" + std::to_string(h_) + " video");
  // A dead ffmpeg must show up as EPIPE from write(), not kill softtled with SIGPIPE. The
  // signal is blocked around these writes only (and a pending one taken back), so that
  // standard output's reader going away still ends softtled with SIGPIPE (exit 141) as
  // everywhere else; ignoring it process-wide made that exit 5.
  sigset_t pipe_only, old_mask;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_only, &old_mask);
  const char* p = reinterpret_cast<const char*>(im.rgba.data());
  std::size_t left = im.rgba.size();
  int e = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      e = errno;
      break;
    }
    p += n, left -= std::size_t(n);
  }
  if (e == EPIPE) {
    sigset_t pending;
    const struct timespec zero = {0, 0};
    if (sigpending(&pending) == 0 && sigismember(&pending, SIGPIPE)) sigtimedwait(&pipe_only, nullptr, &zero);
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  if (e) fail(std::string("ffmpeg stopped taking frames: ") + std::strerror(e));
  ++frames_;
}

void VideoEncoder::finish() {
  if (fd_ < 0 && pid_ < 0) return;
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
  int st = 0;
  while (::waitpid(pid_, &st, 0) < 0) {
    if (errno != EINTR) {
      reaped();
      fail(std::string("waiting for ffmpeg: ") + std::strerror(errno));
    }
  }
  reaped();
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
    fail(WIFEXITED(st) ? "ffmpeg failed with exit code " + std::to_string(WEXITSTATUS(st))
                       : "ffmpeg ended by signal " + std::to_string(WTERMSIG(st)));
  // ffmpeg exits 0 after some write failures ("Error writing trailer ...: File too large"),
  // leaving an unplayable file: with -loglevel error every line it logged is an error.
  if (ffmpeg_logged_errors()) fail("encoding failed although ffmpeg exited 0");
  struct stat tst {};
  if (::stat(tmp_.c_str(), &tst) != 0) fail(std::string("ffmpeg wrote no file: ") + std::strerror(errno));
  if (S_ISREG(tst.st_mode) && tst.st_size == 0) fail("ffmpeg wrote an empty file");
  const std::string container = container_for(path_);
  if (S_ISREG(tst.st_mode) && (container == "mp4" || container == "mov")) {
    const std::string why = mp4_incomplete(tmp_);
    if (!why.empty()) fail("the video ffmpeg wrote is incomplete: " + why);
  }
  // As every atomic output (output_file.h): the replaced file's permissions carry over and
  // a symlink at PATH stays one (target_ is what it names).
  struct stat old;
  if (::stat(target_.c_str(), &old) == 0 && S_ISREG(old.st_mode)) ::chmod(tmp_.c_str(), old.st_mode & 07777);
  if (std::rename(tmp_.c_str(), target_.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp_.c_str());
    throw ResourceError(path_ + ": cannot rename " + tmp_ + " onto it: " + std::strerror(e));
  }
}

}  // namespace softtled
