// Atomic outputs (output_file.h): replacing a file through PATH.tmp keeps what the user set
// up around it (a symlink stays a symlink, a private file stays private), never writes
// through or removes a PATH.tmp it did not create (a FIFO there had blocked the command in
// open(2) beyond any signal, a directory there was deleted), and a .node/.ele pair whose
// second file fails leaves the old pair and no temporary. A write blocked on its reader
// ends with a stop signal; outputs are compared by the file they name; paths past PATH_MAX
// are refused before the work.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <thread>

#include "sim/core/input_error.h"
#include "sim/core/stop_request.h"
#include "sim/io/output_file.h"

using namespace softtled;
namespace fs = std::filesystem;

namespace {
std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("softtled_output_file_" + std::to_string(::getpid()));
  fs::create_directories(d);
  const fs::path p = d / name;
  std::error_code ec;  // (a name too long to exist is fine)
  fs::remove_all(p, ec);
  fs::remove_all(p.string() + ".tmp", ec);
  return p.string();
}
std::string read(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
}  // namespace

TEST(OutputFile, ReplacingKeepsASymlinkAndThePermissions) {
  const std::string real = scratch("real.json"), link = scratch("link.json");
  write_file_atomic(real, "old");
  ASSERT_EQ(::chmod(real.c_str(), 0640), 0);
  fs::create_symlink(real, link);
  write_file_atomic(link, "new");
  EXPECT_TRUE(fs::is_symlink(link)) << "the symlink was replaced by a file";
  EXPECT_EQ(read(real), "new") << "the link's target was not rewritten";
  struct stat st;
  ASSERT_EQ(::stat(real.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u) << "a private file came back with other permissions";
  EXPECT_FALSE(fs::exists(real + ".tmp"));
  EXPECT_FALSE(fs::exists(link + ".tmp"));
}

TEST(OutputFile, ATemporaryNameTakenByAFifoOrADirectoryIsLeftAloneAndRefused) {
  const std::string out = scratch("f.json");
  ASSERT_EQ(::mkfifo((out + ".tmp").c_str(), 0600), 0);
  // Before the work: an input error naming the temporary.
  try {
    check_output_file(out, "--json");
    ADD_FAILURE() << "a FIFO named f.json.tmp passed the output check";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("it is written to " + out + ".tmp first, which is a special file"), std::string::npos)
        << e.what();
  }
  // Writing anyway (the FIFO made after the check): an error at once, not a blocked open.
  auto w = std::async(std::launch::async, [&] {
    try {
      write_file_atomic(out, "x");
      return std::string("no error");
    } catch (const ResourceError& e) {
      return std::string(e.what());
    }
  });
  ASSERT_EQ(w.wait_for(std::chrono::seconds(10)), std::future_status::ready) << "blocked opening the FIFO";
  const std::string msg = w.get();
  EXPECT_NE(msg.find(out + ": cannot write its temporary " + out + ".tmp"), std::string::npos) << msg;
  EXPECT_TRUE(fs::is_fifo(out + ".tmp")) << "the user's FIFO was removed";
  EXPECT_FALSE(fs::exists(out));
  fs::remove(out + ".tmp");

  // A .node/.ele pair with the .ele's temporary a directory: the old pair stays, the
  // directory too, and no .node.tmp is left.
  const std::string base = scratch("m");
  write_files_atomic({{base + ".node", "old node"}, {base + ".ele", "old ele"}});
  fs::create_directory(base + ".ele.tmp");
  EXPECT_THROW(write_files_atomic({{base + ".node", "new node"}, {base + ".ele", "new ele"}}), ResourceError);
  EXPECT_EQ(read(base + ".node"), "old node");
  EXPECT_EQ(read(base + ".ele"), "old ele");
  EXPECT_TRUE(fs::is_directory(base + ".ele.tmp")) << "a directory the writer did not create was removed";
  EXPECT_FALSE(fs::exists(base + ".node.tmp"));
  fs::remove(base + ".ele.tmp");
}

TEST(OutputFile, ASymlinksTemporaryIsCheckedBesideItsTarget) {
  // The temporary of a symlinked output is written beside the link's target, so that is
  // the name checked before the work; one beside the link itself is never used.
  const std::string real = scratch("target.vtu"), link = scratch("alias.vtu");
  write_file_atomic(real, "old");
  fs::create_symlink(real, link);
  fs::create_directory(real + ".tmp");
  try {
    check_output_file(link, "--vtu");
    ADD_FAILURE() << "the target's temporary, a directory, passed the check";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("it is written to " + real + ".tmp first, which is a directory"), std::string::npos)
        << e.what();
  }
  fs::remove(real + ".tmp");
  fs::create_directory(link + ".tmp");
  EXPECT_NO_THROW(check_output_file(link, "--vtu")) << "a directory beside the link, never used, was refused";
  fs::remove(link + ".tmp");
}

TEST(OutputFile, ANameWithoutRoomForItsTemporaryIsRefusedBeforeTheWork) {
  const long max = ::pathconf(fs::temp_directory_path().c_str(), _PC_NAME_MAX);
  ASSERT_GT(max, 10);
  const std::string fits = scratch(std::string(std::size_t(max - 4 - 5), 'a') + ".json");
  EXPECT_NO_THROW(check_output_file(fits, "--json"));
  const std::string too_long = scratch(std::string(std::size_t(max - 3 - 5), 'a') + ".json");
  try {
    check_output_file(too_long, "--json");
    ADD_FAILURE() << "a name one character too long for NAME.tmp passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("with the .tmp it is written under first it must fit"), std::string::npos)
        << e.what();
  }
}

namespace {
std::atomic<bool> g_stop_asked{false};
extern "C" void note_signal(int) {}
// Writes 1 MiB into a FIFO whose reader (held open, never reading) takes 64 KiB, while
// another thread sends SIGUSR1 (no SA_RESTART, as install_stop_signals) to the writer every
// 50 ms; with stop, the stop request is raised first. Returns what the write threw ("" if
// nothing) and sets *got to the bytes a reader drained after `drain_after`.
std::string write_blocked(bool stop, std::size_t* got) {
  const std::string fifo = scratch(stop ? "stopped.csv" : "retried.csv");
  EXPECT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int rd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  struct sigaction sa {}, old {};
  sa.sa_handler = note_signal;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGUSR1, &sa, &old);
  g_stop_asked = false;
  set_stop_request_check([] { return g_stop_asked.load(); });
  std::atomic<bool> done{false};
  const pthread_t writer = ::pthread_self();
  std::thread signaller([&] {
    for (int k = 0; !done; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (k == 4 && stop) g_stop_asked = true;
      if (!done) ::pthread_kill(writer, SIGUSR1);
      if (k == 10 && !stop) {  // the reader starts reading: the write goes on and completes
        const int flags = ::fcntl(rd, F_GETFL);
        ::fcntl(rd, F_SETFL, flags & ~O_NONBLOCK);
        break;
      }
    }
  });
  std::thread reader;
  *got = 0;
  if (!stop)
    reader = std::thread([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(600));
      char buf[65536];
      for (ssize_t n; (n = ::read(rd, buf, sizeof buf)) != 0;)
        if (n > 0) *got += std::size_t(n);
        else if (errno != EINTR && errno != EAGAIN) break;
    });
  std::string thrown;
  try {
    OutputFile f(fifo);
    f.write(std::string(1 << 20, 'x'));
    f.close();
  } catch (const StoppedWhileWaiting& e) {
    thrown = std::string("stopped: ") + e.what();
  } catch (const std::exception& e) {
    thrown = e.what();
  }
  done = true;
  signaller.join();
  if (reader.joinable()) reader.join();
  ::close(rd);
  set_stop_request_check(nullptr);
  ::sigaction(SIGUSR1, &old, nullptr);
  fs::remove(fifo);
  return thrown;
}
}  // namespace

// A write blocked on a reader that does not read (run --csv FIFO, --csv - into a stalled
// pipe) ends when a stop signal arrives: it had blocked for ever, restarted after the signal.
// A signal without a stop request is retried, and every byte arrives.
TEST(OutputFile, AStopSignalEndsAWriteBlockedOnItsReader) {
  std::size_t got = 0;
  auto stopped = std::async(std::launch::async, [&] { return write_blocked(true, &got); });
  ASSERT_EQ(stopped.wait_for(std::chrono::seconds(20)), std::future_status::ready)
      << "the blocked write was not stopped";
  const std::string msg = stopped.get();
  EXPECT_EQ(msg.rfind("stopped: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("stopped while the write waited for its reader to read"), std::string::npos) << msg;
  auto retried = std::async(std::launch::async, [&] { return write_blocked(false, &got); });
  ASSERT_EQ(retried.wait_for(std::chrono::seconds(20)), std::future_status::ready) << "the write never completed";
  EXPECT_EQ(retried.get(), "") << "a signal without a stop request failed the write";
  EXPECT_EQ(got, std::size_t(1) << 20) << "bytes lost to an interrupted write";
}

// The names a --vtu directory's series writes are compared by the file they name: a
// symlink there (to the scene) is refused, a hard link to the scene, a dangling link given
// as another output and a scene that is a link into the directory are each the same file.
TEST(OutputFile, SeriesNamesAreComparedByTheFileTheyName) {
  const std::string dir = scratch("series"), scene = scratch("scene.toml");
  fs::create_directories(dir);
  write_file_atomic(scene, "units = \"mm\"\n");
  fs::create_symlink(scene, dir + "/series.pvd");
  EXPECT_THROW(check_series_dir(dir, "--vtu"), InputError) << "series.pvd, a symlink to the scene, passed";
  fs::remove(dir + "/series.pvd");
  EXPECT_NO_THROW(check_series_dir(dir, "--vtu"));
  const PathUse in{scene, "--scene"}, out{dir, "--vtu", true, true};
  fs::create_hard_link(scene, dir + "/frame_00001.vtu");
  EXPECT_THROW(check_distinct_paths({in, out}), InputError) << "a hard link to the scene under a frame's name passed";
  fs::remove(dir + "/frame_00001.vtu");
  EXPECT_NO_THROW(check_distinct_paths({in, out}));
  const std::string csv = scratch("dangling.csv"), alias = scratch("alias.toml");
  fs::create_symlink(dir + "/frame_00002.vtu", csv);
  EXPECT_THROW(check_distinct_paths({in, out, {csv, "--csv", true, false, true}}), InputError)
      << "a CSV that is a dangling link to a frame passed";
  write_file_atomic(dir + "/frame_00003.vtu", "earlier");
  fs::create_symlink(dir + "/frame_00003.vtu", alias);
  EXPECT_THROW(check_distinct_paths({{alias, "--scene"}, out}), InputError)
      << "a scene linked into the directory passed";
  fs::remove(csv);
  fs::remove(alias);
  fs::remove_all(dir);
}

// Paths that fit PATH_MAX but whose NAME.tmp, or a frame of a --vtu directory, does not are
// refused by the checks before the work (they failed when opened, after it: exit 5).
TEST(OutputFile, APathPastPathMaxWithItsTemporaryIsRefusedBeforeTheWork) {
  std::string deep = scratch("deep");
  while (deep.size() < PATH_MAX - 250) deep += "/" + std::string(100, 'd');  // the last name then fits NAME_MAX
  fs::create_directories(deep);
  const std::string file = deep + "/" + std::string(PATH_MAX - 4 - deep.size(), 'f');  // 4093 characters
  ASSERT_EQ(file.size(), std::size_t(PATH_MAX - 3));
  try {
    check_output_file(file, "--write");
    ADD_FAILURE() << "a path whose NAME.tmp is past PATH_MAX passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("(File name too long)"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(check_output_file(file, "--csv", false, true)) << "written in place, it fits";
  // 4076 characters: DIR/frame_00000.vtu.tmp does not fit
  const std::string dir = deep + "/" + std::string(PATH_MAX - 21 - deep.size(), 'v');
  EXPECT_THROW(check_series_dir(dir, "--vtu"), InputError);
  fs::remove_all(scratch("deep"));
}
