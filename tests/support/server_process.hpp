// galpha_server as a child process, as operators run it: started with flags on free loopback
// ports (read back from its "listening on port N" lines), signalled, waited for, its resident
// memory read from /proc. For the tests of the real process (alphactl --server, faults).
#pragma once

#include <sys/types.h>

#include <string>

namespace galpha::testing {

class ServerProcess {
 public:
  /// Starts `binary` with --listen/--metrics_listen on 127.0.0.1 port 0, --backend cpu, and
  /// `flags`; waits up to 10 s for its ports. port() is 0 when it did not start.
  ServerProcess(const std::string& binary, const std::string& flags);
  /// SIGKILLs a process still running.
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  pid_t pid() const { return pid_; }
  int port() const { return port_; }
  int metrics_port() const { return metrics_port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  /// Everything it printed so far (stdout and stderr).
  std::string log() const;
  /// VmRSS of the process in bytes (0 when it is gone).
  size_t ResidentBytes() const;
  /// Sends `signal`, then waits up to `seconds` for the exit: its status, or -1 on timeout.
  int Signal(int signal, double seconds);
  /// Whether the process is still running.
  bool Running();

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int metrics_port_ = 0;
  bool exited_ = false;
  std::string log_path_;
};

/// Starts `command` with /bin/sh in the background; its pid.
pid_t SpawnShell(const std::string& command);
/// Waits up to `seconds` for `pid`: its exit status, or -1 on timeout (then SIGKILLs it).
int WaitChild(pid_t pid, double seconds);

}  // namespace galpha::testing
