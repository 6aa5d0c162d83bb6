// Test helper: runs the real sweetspot-server executable on 127.0.0.1 with an
// ephemeral port, captures its stderr, and stops it with a signal.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace sweetspot::testing {

class ServerProcess {
 public:
  ServerProcess() = default;
  ~ServerProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (reader_.joinable()) reader_.join();
  }

  /// Sets `name` = `value` in the server's environment (before Start).
  void SetEnvironment(std::string name, std::string value) {
    environment_.emplace_back(std::move(name), std::move(value));
  }
  /// Caps the server's address space (RLIMIT_AS, as `prlimit --as`), bytes (before Start).
  void SetAddressSpaceLimit(rlim_t bytes) { address_space_limit_ = bytes; }

  /// Starts the server with `args` (port 0 and host 127.0.0.1 are added, and
  /// --jobs-db none unless `args` name a jobs database: a shared default file
  /// would couple tests) and waits up to 20 s for its "listening on" line.
  /// Returns false on failure.
  bool Start(std::vector<std::string> args = {}) {
    int fds[2];
    // Close-on-exec: a server started at the same time from another thread must
    // not inherit this pipe, or its reader would wait for that server's exit too.
    if (pipe2(fds, O_CLOEXEC) != 0) return false;
    const std::string binary = std::string(SWEETSPOT_BINARY_DIR) + "/server/sweetspot-server";
    bool names_jobs_db = false;
    for (const std::string& arg : args) names_jobs_db |= arg.rfind("--jobs-db", 0) == 0;
    if (!names_jobs_db) args.insert(args.begin(), {"--jobs-db", "none"});
    args.insert(args.begin(), {binary, "--host", "127.0.0.1", "--port", "0"});
    pid_ = fork();
    if (pid_ == 0) {
      for (const auto& [name, value] : environment_) setenv(name.c_str(), value.c_str(), 1);
      if (address_space_limit_ > 0) {
        const rlimit limit{address_space_limit_, address_space_limit_};
        if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(126);
      }
      dup2(fds[1], STDERR_FILENO);
      close(fds[0]);
      close(fds[1]);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(binary.c_str(), argv.data());
      _exit(127);
    }
    close(fds[1]);
    reader_ = std::thread([this, fd = fds[0]] {
      char buffer[4096];
      ssize_t n;
      while ((n = read(fd, buffer, sizeof buffer)) > 0) {
        std::lock_guard<std::mutex> lock(mutex_);
        log_.append(buffer, static_cast<size_t>(n));
      }
      close(fd);
    });
    const std::string listening = "listening on 127.0.0.1:";
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        const auto at = log_.find(listening);
        if (at != std::string::npos) {
          const auto digits = at + listening.size();
          const auto end = log_.find_first_not_of("0123456789", digits);
          if (end != std::string::npos && end > digits) {
            port_ = std::stoi(log_.substr(digits, end - digits));
            return true;
          }
        }
      }
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        // The server exited: its last words may still be in the pipe; the reader ends at the
        // pipe's end (no other process holds it: close-on-exec), so log() has them all.
        if (reader_.joinable()) reader_.join();
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  /// Sends `signal_number` and waits up to 20 s; returns the exit status
  /// (or -1 if it did not exit normally, -2 on time-out).
  int Stop(int signal_number = SIGTERM) {
    if (pid_ <= 0) return -1;
    kill(pid_, signal_number);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    int status = 0;
    while (waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) return -2;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    pid_ = -1;
    if (reader_.joinable()) reader_.join();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  int port() const { return port_; }
  /// The server's process id (-1 when not running).
  pid_t pid() const { return pid_; }
  std::string log() {
    std::lock_guard<std::mutex> lock(mutex_);
    return log_;
  }

 private:
  pid_t pid_ = -1;
  int port_ = -1;
  std::thread reader_;
  std::mutex mutex_;
  std::string log_;
  std::vector<std::pair<std::string, std::string>> environment_;
  rlim_t address_space_limit_ = 0;
};

}  // namespace sweetspot::testing
