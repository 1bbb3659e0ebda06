#include "tests/support/server_process.hpp"

#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill and signal numbers
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

namespace galpha::testing {

namespace {

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int PortAfter(const std::string& text, const std::string& marker) {
  const size_t at = text.find(marker);
  return at == std::string::npos ? 0 : std::atoi(text.c_str() + at + marker.size());
}

}  // namespace

pid_t SpawnShell(const std::string& command) {
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

int WaitChild(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  return -1;
}

ServerProcess::ServerProcess(const std::string& binary, const std::string& flags) {
  static std::atomic<int> counter{0};
  log_path_ = std::filesystem::temp_directory_path() /
              ("galpha_server_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + ".log");
  // exec: the pid is the server's own, so signals and /proc reach it.
  pid_ = SpawnShell("exec " + binary + " --listen 127.0.0.1:0 --metrics_listen 127.0.0.1:0 --backend cpu " + flags +
                    " >" + log_path_ + " 2>&1");
  for (int i = 0; i < 1000 && (port_ == 0 || metrics_port_ == 0); ++i) {
    const std::string text = Slurp(log_path_);
    port_ = PortAfter(text, "listening on port ");
    metrics_port_ = PortAfter(text, "metrics on port ");
    if (!Running()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0 && !exited_) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::filesystem::remove(log_path_);
}

std::string ServerProcess::log() const { return Slurp(log_path_); }

size_t ServerProcess::ResidentBytes() const {
  std::ifstream status("/proc/" + std::to_string(pid_) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  }
  return 0;
}

int ServerProcess::Signal(int signal, double seconds) {
  kill(pid_, signal);
  const int status = WaitChild(pid_, seconds);
  exited_ = true;
  return status;
}

bool ServerProcess::Running() {
  if (exited_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) exited_ = true;
  return !exited_;
}

}  // namespace galpha::testing
