// The proxy the project ships (docker/nginx.conf), tested as a file: Debian's
// nginx is started with it, its upstream pointed at two real sweetspot-server
// replicas on loopback and its listen line at a free loopback port (nothing
// else of the file is changed), in a temporary folder, and stopped at the end.
// Checked: a streamed explore arrives in chunks as the rows are computed (not
// held in nginx's buffers), a client trickling its head is cut off at nginx's
// 10 s head deadline, a 2 MiB body is refused with 413, and requests are
// shared by both replicas. And the issue's round robin of jobs: with both
// replicas on one PostgreSQL, a job posted through nginx is found by every read.
#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/server/postgres_cluster.hpp"
#include "tests/server/server_process.hpp"
#include "tests/server/wire.hpp"

namespace sweetspot::testing {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace nginx_test {
namespace {

using Clock = std::chrono::steady_clock;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A port nobody listens on now (bound and released; loopback only).
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

// Debian's nginx with docker/nginx.conf, rewritten only where the test must:
// the upstream replicas, the listen address, and (for a private folder) the
// pid, log and temporary paths, which the file leaves at nginx's defaults.
class Nginx {
 public:
  bool Start(const std::vector<int>& replica_ports) {
    char folder[] = "/tmp/sweetspot-nginx-XXXXXX";
    if (mkdtemp(folder) == nullptr) return false;
    dir_ = folder;
    chmod(dir_.c_str(), 0755);  // the workers run as an unprivileged user
    std::string conf = ReadFile(std::string(SWEETSPOT_SOURCE_DIR) + "/docker/nginx.conf");
    const std::regex server_line(R"(server sweetspot:8080([^;]*);)");
    std::smatch match;
    if (!std::regex_search(conf, match, server_line)) {
      error_ = "docker/nginx.conf has no \"server sweetspot:8080 ...;\" line";
      return false;
    }
    std::string servers;
    for (const int port : replica_ports) {
      servers += "server 127.0.0.1:" + std::to_string(port) + match[1].str() + ";\n    ";
    }
    conf = std::regex_replace(conf, server_line, servers);
    port_ = FreePort();
    const std::regex listen_line(R"(listen 8080;)");
    if (!std::regex_search(conf, listen_line)) {
      error_ = "docker/nginx.conf has no \"listen 8080;\" line";
      return false;
    }
    conf = std::regex_replace(conf, listen_line, "listen 127.0.0.1:" + std::to_string(port_) + ";");
    const std::string paths = "http {\n  access_log " + dir_ + "/access.log;\n" +
                              "  client_body_temp_path " + dir_ + "/body;\n" +
                              "  proxy_temp_path " + dir_ + "/proxy;\n" + "  fastcgi_temp_path " +
                              dir_ + "/fastcgi;\n" + "  uwsgi_temp_path " + dir_ + "/uwsgi;\n" +
                              "  scgi_temp_path " + dir_ + "/scgi;\n";
    conf = std::regex_replace(conf, std::regex(R"(http \{)"), paths);
    {
      std::ofstream out(dir_ + "/nginx.conf");
      out << conf;
    }
    pid_ = fork();
    if (pid_ == 0) {
      const std::string globals =
          "daemon off; pid " + dir_ + "/nginx.pid; error_log " + dir_ + "/error.log;";
      execl("/usr/sbin/nginx", "nginx", "-p", dir_.c_str(), "-c", (dir_ + "/nginx.conf").c_str(),
            "-g", globals.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int i = 0; i < 500; ++i) {  // up to 5 s for the listening socket
      const int fd = Connect(port_);
      if (fd >= 0) {
        close(fd);
        return true;
      }
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        error_ = "nginx exited: " + ReadFile(dir_ + "/error.log");
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    error_ = "nginx did not listen within 5 s: " + ReadFile(dir_ + "/error.log");
    return false;
  }
  ~Nginx() {
    if (pid_ > 0) {
      kill(pid_, SIGQUIT);  // graceful stop of the master and its workers
      int status = 0;
      for (int i = 0; i < 500 && waitpid(pid_, &status, WNOHANG) == 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (!dir_.empty()) std::system(("rm -rf " + dir_).c_str());
  }
  int port() const { return port_; }
  const std::string& error() const { return error_; }

 private:
  pid_t pid_ = -1;
  int port_ = -1;
  std::string dir_;
  std::string error_;
};

class NginxTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(first_.Start({"--no-access-log"})) << first_.log();
    ASSERT_TRUE(second_.Start({"--no-access-log"})) << second_.log();
    ASSERT_TRUE(nginx_.Start({first_.port(), second_.port()})) << nginx_.error();
  }
  ServerProcess first_, second_;
  Nginx nginx_;
};

TEST_F(NginxTest, StreamedExploreArrivesInChunksThroughTheProxy) {
  // Forty designs of the flexible model's least-sting sweep: ~20 ms each (issue 17's
  // speed-up; ~0.1 s before), on the server's explore threads, so the rows are produced
  // over about half a second, a few hundred bytes apiece (far less than nginx's buffers:
  // a buffering proxy would hold them to the end).
  const std::string body =
      R"({"bat": {"preset": "paper-wood"}, "cor": 0.5, "outputs": ["least_sting_zone"], "format": "ndjson", )"
      R"("parameters": [{"path": "cor", "min": 0.45, "max": 0.55, "count": 40}]})";
  httplib::Client client("127.0.0.1", nginx_.port());
  client.set_read_timeout(60, 0);
  std::vector<double> arrivals_s;
  std::string streamed;
  int status = 0;
  httplib::Request request;
  request.method = "POST";
  request.path = "/v1/explore";
  request.body = body;
  request.set_header("Content-Type", "application/json");
  const auto start = Clock::now();
  request.response_handler = [&](const httplib::Response& response) {
    status = response.status;
    return true;
  };
  request.content_receiver = [&](const char* data, std::size_t length, std::uint64_t,
                                 std::uint64_t) {
    arrivals_s.push_back(SecondsSince(start));
    streamed.append(data, length);
    return true;
  };
  httplib::Response response;
  httplib::Error error = httplib::Error::Success;
  ASSERT_TRUE(client.send(request, response, error)) << httplib::to_string(error);
  const double total_s = SecondsSince(start);
  ASSERT_EQ(status, 200) << streamed;
  ASSERT_FALSE(arrivals_s.empty());
  int lines = 0;
  for (const char c : streamed) lines += c == '\n';
  std::cout << "through nginx: " << lines << " NDJSON lines in " << arrivals_s.size()
            << " pieces; first at " << arrivals_s.front() << " s, stream done at " << total_s
            << " s" << std::endl;
  EXPECT_EQ(lines, 41) << streamed;  // 40 rows and the summary
  // Streamed, not buffered: the rows came in several pieces, the first long
  // before the end (a buffering proxy delivers everything at the end).
  EXPECT_GE(arrivals_s.size(), 3u);
  EXPECT_LT(arrivals_s.front(), 0.6 * total_s);
}

TEST_F(NginxTest, ClientTricklingItsHeadIsCutOffAtTheProxysDeadline) {
  const int fd = Connect(nginx_.port());
  ASSERT_GE(fd, 0);
  const auto start = Clock::now();
  ASSERT_TRUE(SendAll(fd, "GET /health HTTP/1.1\r\n"));
  bool closed = false;
  std::string answer;
  for (int line = 0; line < 20 && !closed; ++line) {
    const ReadResult read = ReadFor(fd, 1.0, [](const std::string&) { return false; });
    answer += read.bytes;
    closed = read.closed;
    if (!closed && !SendAll(fd, "X-Trickle-" + std::to_string(line) + ": still typing\r\n")) {
      closed = true;
    }
  }
  const double cut_s = SecondsSince(start);
  close(fd);
  std::cout << "through nginx: a trickling head was cut after " << cut_s << " s" << std::endl;
  EXPECT_TRUE(closed);
  // client_header_timeout 10s is a deadline for the whole head, not per line.
  EXPECT_GE(cut_s, 9.5);
  EXPECT_LE(cut_s, 11.5);
  // Meanwhile the proxy answers others.
  httplib::Client client("127.0.0.1", nginx_.port());
  const auto res = client.Get("/health");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
}

TEST_F(NginxTest, TwoMebibyteBodyIsRefusedWith413AndRequestsReachBothReplicas) {
  httplib::Client client("127.0.0.1", nginx_.port());
  const auto big = client.Post("/v1/sweet-spot", std::string(2 << 20, ' '), "application/json");
  ASSERT_TRUE(big);
  EXPECT_EQ(big->status, 413);
  // Round robin over the two replicas, each answering with its own metrics.
  for (int i = 0; i < 20; ++i) {
    const auto res =
        client.Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})", "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
  }
  for (const int port : {first_.port(), second_.port()}) {
    httplib::Client direct("127.0.0.1", port);
    const auto metrics = direct.Get("/metrics");
    ASSERT_TRUE(metrics);
    const std::string series =
        "sweetspot_requests_total{route=\"/v1/sweet-spot\",method=\"POST\",status=\"200\"} ";
    const auto at = metrics->body.find(series);
    ASSERT_NE(at, std::string::npos) << "replica on port " << port << " got no request";
    EXPECT_GE(std::stoi(metrics->body.substr(at + series.size())), 5) << port;
  }
}

TEST(NginxJobsTest, AJobPostedThroughTheProxyIsFoundOnEveryReadWithPostgres) {
  // The issue's reproduction: two replicas behind nginx's round robin, a job
  // posted through nginx, then GET /v1/jobs/{id} six times through nginx. With
  // a SQLite file per replica the reads went 404 200 404 200 404 200.
  PostgresCluster cluster;
  ASSERT_TRUE(cluster.Start()) << cluster.why();
  ServerProcess first, second;
  ASSERT_TRUE(first.Start({"--no-access-log", "--jobs-db", cluster.Uri()})) << first.log();
  ASSERT_TRUE(second.Start({"--no-access-log", "--jobs-db", cluster.Uri()})) << second.log();
  Nginx nginx;
  ASSERT_TRUE(nginx.Start({first.port(), second.port()})) << nginx.error();
  httplib::Client client("127.0.0.1", nginx.port());
  const auto posted = client.Post(
      "/v1/jobs", R"({"path": "/v1/bat/properties", "body": {"bat": {"preset": "paper-wood"}}})",
      "application/json");
  ASSERT_TRUE(posted);
  ASSERT_EQ(posted->status, 202) << posted->body;
  const std::string id = nlohmann::json::parse(posted->body)["id"];
  std::string statuses;
  for (int i = 0; i < 6; ++i) {
    const auto read = client.Get(("/v1/jobs/" + id).c_str());
    statuses += (i > 0 ? " " : "") + (read ? std::to_string(read->status) : std::string("none"));
  }
  EXPECT_EQ(statuses, "200 200 200 200 200 200");
  // The reads reached both replicas (round robin), each of which found the job.
  for (const int port : {first.port(), second.port()}) {
    httplib::Client direct("127.0.0.1", port);
    const auto metrics = direct.Get("/metrics");
    ASSERT_TRUE(metrics);
    EXPECT_NE(metrics->body.find(
                  "sweetspot_requests_total{route=\"/v1/jobs/{id}\",method=\"GET\",status=\"200\"} "),
              std::string::npos)
        << "replica on port " << port << " answered no read";
  }
}

}  // namespace
}  // namespace nginx_test
}  // namespace sweetspot::testing
