// A throw-away PostgreSQL server for tests: Debian's `postgresql` package,
// `initdb` in a temporary folder and `pg_ctl` on a free loopback port, stopped
// and removed at the end. The server refuses to run as root, so as root (CI)
// every command runs as the unprivileged `postgres` user the package creates
// (../shared/docs/pitfalls.md has the recipe).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

namespace sweetspot::testing {

class PostgresCluster {
 public:
  PostgresCluster() = default;
  ~PostgresCluster() {
    Stop();
    std::error_code ignored;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ignored);
  }
  PostgresCluster(const PostgresCluster&) = delete;
  PostgresCluster& operator=(const PostgresCluster&) = delete;

  /// Creates the cluster and starts it; false (with the reason in why()) when
  /// PostgreSQL is not installed or does not start.
  bool Start() {
    bin_ = FindBin();
    if (bin_.empty()) return Fail("no /usr/lib/postgresql/*/bin/initdb: install Debian's postgresql");
    char pattern[] = "/tmp/sweetspot-pg-XXXXXX";
    if (mkdtemp(pattern) == nullptr) return Fail("mkdtemp failed");
    dir_ = pattern;
    if (geteuid() == 0 && Shell("chown postgres " + dir_) != 0) return Fail("chown postgres failed");
    port_ = FreePort();
    if (As("'" + bin_ + "/initdb' -D '" + dir_ + "/data' -A trust -U postgres --no-sync -E UTF8 >'" +
           dir_ + "/initdb.log' 2>&1") != 0) {
      return Fail("initdb failed: see " + dir_ + "/initdb.log");
    }
    return Resume();
  }

  /// Starts the stopped cluster again on the same port (its data kept).
  bool Resume() {
    const std::string options = "-p " + std::to_string(port_) + " -k " + dir_ +
                                " -c listen_addresses=127.0.0.1 -c fsync=off "
                                "-c max_connections=200";
    if (As("'" + bin_ + "/pg_ctl' -D '" + dir_ + "/data' -w -t 60 -l '" + dir_ +
           "/server.log' start -o '" + options + "' >/dev/null 2>&1") != 0) {
      return Fail("pg_ctl start failed: see " + dir_ + "/server.log");
    }
    running_ = true;
    return true;
  }

  /// Stops the server (fast: open connections are cut, as when a database goes away).
  void Stop() {
    if (!running_) return;
    As("'" + bin_ + "/pg_ctl' -D '" + dir_ + "/data' -w -t 60 -m fast stop >/dev/null 2>&1");
    running_ = false;
  }

  /// A libpq URI of database `db` (as the superuser `postgres`).
  std::string Uri(const std::string& db = "postgres") const {
    return "postgresql://postgres@127.0.0.1:" + std::to_string(port_) + "/" + db;
  }

  /// Runs `sql` with psql in database `db`; its output (unaligned, tuples only),
  /// or "ERROR" when psql failed.
  std::string Psql(const std::string& sql, const std::string& db = "postgres") const {
    const std::string command = "psql -X -q -A -t -h 127.0.0.1 -p " + std::to_string(port_) +
                                " -U postgres -d " + db + " -c \"" + sql + "\" 2>&1";
    std::string out;
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) return "ERROR";
    char buffer[4096];
    std::size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
    const int status = pclose(pipe);
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return status == 0 ? out : "ERROR: " + out;
  }

  int port() const { return port_; }
  const std::string& why() const { return why_; }

 private:
  static std::string FindBin() {
    std::error_code ignored;
    for (const auto& entry : std::filesystem::directory_iterator("/usr/lib/postgresql", ignored)) {
      const auto bin = entry.path() / "bin";
      if (std::filesystem::exists(bin / "initdb", ignored)) return bin.string();
    }
    return "";
  }

  static int FreePort() {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
    socklen_t len = sizeof addr;
    getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    const int port = ntohs(addr.sin_port);
    close(fd);
    return port;
  }

  static int Shell(const std::string& command) { return std::system(command.c_str()); }

  // Runs `command` as the postgres user when root, else as the caller.
  int As(const std::string& command) const {
    if (geteuid() != 0) return Shell(command);
    std::string quoted;
    for (char c : command) quoted += c == '"' ? std::string("\\\"") : std::string(1, c);
    return Shell("runuser -u postgres -- sh -c \"" + quoted + "\"");
  }

  bool Fail(const std::string& why) {
    why_ = why;
    return false;
  }

  std::string bin_;
  std::string dir_;
  std::string why_;
  int port_ = 0;
  bool running_ = false;
};

}  // namespace sweetspot::testing
