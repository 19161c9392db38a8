// Atomic outputs (output_file.h): replacing a file through PATH.tmp keeps what the user set
// up around it (a symlink stays a symlink, a private file stays private), never writes
// through or removes a PATH.tmp it did not create (a FIFO there had blocked the command in
// open(2) beyond any signal, a directory there was deleted), and a .node/.ele pair whose
// second file fails leaves the old pair and no temporary.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>

#include "sim/core/input_error.h"
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
