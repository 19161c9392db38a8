#include "sim/io/output_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "sim/core/input_error.h"

namespace softtled {

OutputFile::OutputFile(std::string path, Mode mode) : path_(std::move(path)) {
  if (path_ == "-" && mode == kDirect) {
    f_ = stdout;
    return;
  }
  // Atomic only for a regular file or a new name: a device (/dev/null, /dev/full) or FIFO
  // is written in place, never replaced by a renamed temporary.
  struct stat st;
  if (mode == kAtomic && (::stat(path_.c_str(), &st) != 0 || S_ISREG(st.st_mode))) tmp_ = path_ + ".tmp";
  const std::string& open_path = tmp_.empty() ? path_ : tmp_;
  f_ = std::fopen(open_path.c_str(), "wb");
  if (!f_) throw ResourceError(open_path + ": cannot write: " + std::strerror(errno));
}

OutputFile::~OutputFile() {
  if (!f_) return;
  if (f_ != stdout) std::fclose(f_);
  if (!tmp_.empty()) std::remove(tmp_.c_str());
}

void OutputFile::fail(const char* what) {
  const int e = errno;
  std::string msg = (f_ == stdout ? std::string("standard output") : path_) + ": " + what + (e ? std::string(": ") + std::strerror(e) : std::string());
  if (f_ && f_ != stdout) std::fclose(f_);
  f_ = nullptr;
  if (!tmp_.empty()) std::remove(tmp_.c_str());
  throw ResourceError(msg);
}

void OutputFile::write(const char* data, std::size_t n) {
  if (!f_) throw ResourceError(path_ + ": write after close");
  errno = 0;
  if (n && std::fwrite(data, 1, n, f_) != n) fail("write failed");
}

void OutputFile::flush() {
  if (!f_) return;
  errno = 0;
  if (std::fflush(f_) != 0 || std::ferror(f_)) fail("write failed");
}

void OutputFile::close() {
  if (!f_) return;
  flush();
  if (f_ == stdout) {
    f_ = nullptr;
    return;
  }
  errno = 0;
  std::FILE* f = f_;
  f_ = nullptr;
  if (std::fclose(f) != 0) {
    f_ = nullptr;
    const int e = errno;
    if (!tmp_.empty()) std::remove(tmp_.c_str());
    throw ResourceError(path_ + ": write failed: " + std::strerror(e));
  }
  if (!tmp_.empty()) {
    if (std::rename(tmp_.c_str(), path_.c_str()) != 0) {
      const int e = errno;
      std::remove(tmp_.c_str());
      throw ResourceError(path_ + ": cannot rename " + tmp_ + " onto it: " + std::strerror(e));
    }
    tmp_.clear();
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  OutputFile f(path, OutputFile::kAtomic);
  f.write(content);
  f.close();
}

namespace {
std::string parent_of(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string parent = p.parent_path().string();
  return parent.empty() ? "." : parent;
}
}  // namespace

void check_output_file(const std::string& path, const std::string& what, bool allow_stdout) {
  if (path == "-" && allow_stdout) return;
  const std::string where = what + " " + path + ": ";
  if (path.empty()) throw InputError(what + ": empty path");
  if (path.back() == '/') throw InputError(where + "is a directory name; give a file name");
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw InputError(where + "is a directory; give a file name");
    if (::access(path.c_str(), W_OK) != 0) throw InputError(where + "cannot write: " + std::strerror(errno));
    return;
  }
  if (errno != ENOENT) throw InputError(where + "cannot write: " + std::strerror(errno));
  const std::string dir = parent_of(path);
  if (::stat(dir.c_str(), &st) != 0)
    throw InputError(where + "directory " + dir + " does not exist: " + std::strerror(errno));
  if (!S_ISDIR(st.st_mode)) throw InputError(where + dir + " is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(where + "cannot write in directory " + dir + ": " + std::strerror(errno));
}

void check_output_dir(const std::string& path, const std::string& what) {
  const std::string where = what + " " + path + ": ";
  if (path.empty()) throw InputError(what + ": empty path");
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
