// alphactl --server against the real galpha_server process: a server started as users start it
// (its "listening on port N" line read from its stdout), every query command's output compared
// byte for byte with the local command's, the upload skipped when the server holds the file,
// errors as one line with the local exit codes, and the process's drain on SIGTERM.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "tests/support/data_files.hpp"

namespace {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

CommandResult Alphactl(const std::string& args, const std::string& environment = "") {
  const std::string dir = std::filesystem::temp_directory_path() / ("alphactl_remote_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string command = environment + " " + GALPHA_ALPHACTL + " " + args + " >" + dir + "/out 2>" + dir + "/err";
  const int status = std::system(command.c_str());
  CommandResult run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = Slurp(dir + "/out");
  run.err = Slurp(dir + "/err");
  std::filesystem::remove_all(dir);
  return run;
}

/// galpha_server as a child process on a free port.
class ServerProcess {
 public:
  explicit ServerProcess(const std::string& extra_flags = "") {
    log_ = std::filesystem::temp_directory_path() / ("galpha_server_" + std::to_string(getpid()) + ".log");
    pid_ = fork();
    if (pid_ == 0) {
      const std::string command = std::string("exec ") + GALPHA_SERVER +
                                  " --listen 127.0.0.1:0 --metrics_listen 127.0.0.1:0 --backend cpu "
                                  "--drain_notice_ms 200 " +
                                  extra_flags + " >" + log_ + " 2>&1";
      execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int i = 0; i < 1000 && port_ == 0; ++i) {
      const std::string text = Slurp(log_);
      const size_t at = text.find("listening on port ");
      if (at != std::string::npos) port_ = std::atoi(text.c_str() + at + 18);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  ~ServerProcess() {
    if (pid_ > 0 && !stopped_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    std::filesystem::remove(log_);
  }
  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  std::string log() const { return Slurp(log_); }
  /// SIGTERM, then the exit status (or -1 when it did not exit within `seconds`).
  int Terminate(double seconds) {
    kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        stopped_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  bool stopped_ = false;
  std::string log_;
};

TEST(AlphactlRemoteTest, EveryQueryCommandPrintsWhatTheLocalOnePrints) {
  ServerProcess server;
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const char* commands[] = {
      "spectrum",
      "classify --rank 100",
      "classify --alpha-sq 2.5e-5 --mode regularized --vertex-rule cgal",
      "summary --alpha 0.004",
      "summary --rank 0",
      "shape --rank 300 --format geojson",
      "shape --alpha-sq 1e-4 --format wkt --mode regularized",
      "shape --rank 50 --format svg",
      "masterlist --rank 77",
      "optimal --components 3",
  };
  for (const char* command : commands) {
    SCOPED_TRACE(command);
    const CommandResult local = Alphactl(std::string(command) + " " + file);
    const CommandResult remote = Alphactl(std::string(command) + " " + file + " --server " + server.address());
    EXPECT_EQ(local.exit_code, 0) << local.err;
    EXPECT_EQ(remote.exit_code, 0) << remote.err;
    EXPECT_FALSE(local.out.empty());
    EXPECT_EQ(remote.out, local.out);
  }
  // bench runs on the server: its table names the server's backend and the RPC's time.
  const CommandResult bench = Alphactl("bench " + file + " --server " + server.address());
  EXPECT_EQ(bench.exit_code, 0) << bench.err;
  EXPECT_NE(bench.out.find("rpc_total"), std::string::npos) << bench.out;
  EXPECT_NE(bench.out.find("backend"), std::string::npos);
}

TEST(AlphactlRemoteTest, ErrorsKeepTheLocalExitCodes) {
  ServerProcess server;
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const CommandResult local = Alphactl("masterlist " + file + " --rank 999999999");
  const CommandResult remote = Alphactl("masterlist " + file + " --rank 999999999 --server " + server.address());
  EXPECT_EQ(local.exit_code, 2);
  EXPECT_EQ(remote.exit_code, 2);
  EXPECT_EQ(remote.err, local.err);

  const CommandResult backend = Alphactl("spectrum " + file + " --backend cpu --server " + server.address());
  EXPECT_EQ(backend.exit_code, 2);
  EXPECT_NE(backend.err.find("--backend applies to local builds"), std::string::npos) << backend.err;

  const CommandResult unreachable = Alphactl("spectrum " + file + " --server 127.0.0.1:1");
  EXPECT_EQ(unreachable.exit_code, 1);
  EXPECT_EQ(std::count(unreachable.err.begin(), unreachable.err.end(), '\n'), 1) << unreachable.err;
  EXPECT_EQ(unreachable.err.rfind("alphactl: server 127.0.0.1:1: ", 0), 0u) << unreachable.err;
}

TEST(AlphactlRemoteTest, TokensComeFromTheEnvironment) {
  const std::string tokens = std::filesystem::temp_directory_path() / ("galpha_tokens_" + std::to_string(getpid()));
  std::ofstream(tokens) << "# test tokens\nsecret-1 team-one\n";
  ServerProcess server("--token_file " + tokens);
  ASSERT_GT(server.port(), 0) << server.log();
  const std::string file = galpha::testdata::DataDir() + "/gps_tracks_slovenia_croatia.bin";
  const CommandResult without = Alphactl("summary --rank 1 " + file + " --server " + server.address());
  EXPECT_EQ(without.exit_code, 1);
  EXPECT_NE(without.err.find("Bearer TOKEN"), std::string::npos) << without.err;
  const CommandResult with = Alphactl("summary --rank 1 " + file + " --server " + server.address(), "GALPHA_TOKEN=secret-1");
  EXPECT_EQ(with.exit_code, 0) << with.err;
  std::filesystem::remove(tokens);
}

TEST(AlphactlRemoteTest, SigtermDrainsAndExitsCleanly) {
  ServerProcess server;
  ASSERT_GT(server.port(), 0) << server.log();
  EXPECT_EQ(server.Terminate(30), 0) << server.log();
  const std::string log = server.log();
  EXPECT_NE(log.find("draining"), std::string::npos) << log;
  EXPECT_NE(log.find("stopped"), std::string::npos) << log;
}

}  // namespace
