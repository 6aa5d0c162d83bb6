// Serving under real load, against the real sweetspot-server with its defaults
// (issue 14): many keep-alive clients are served fairly, slow clients are cut
// off at their deadlines while others are answered at once, connections past
// the limit get their 503 at once and are closed, and model work stays in its
// bounded pool while cheap requests pass. Each test prints its figures.
//
// Durations: the full ones of the issue (10 s of fairness, 30 s of slow
// clients) unless SWEETSPOT_LOAD_SECONDS is lower (the sanitizer pass sets 5);
// the slow-client test never runs shorter than 13 s, so that the default 10 s
// head deadline is seen to expire. These tests run alone (ctest RUN_SERIAL):
// their latency bounds are about the server, not about a neighbouring test.
#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <iostream>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "server/cpu_quota.hpp"
#include "tests/sanitizers.hpp"
#include "tests/server/server_process.hpp"
#include "tests/server/wire.hpp"

namespace sweetspot::testing {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace serving_test {
namespace {

using Clock = std::chrono::steady_clock;

// The contract's example scene (bench/http_bench.sh posts the same body).
const char* const kSweetSpotBody =
    R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366, )"
    R"("speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0, )"
    R"("hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]})";

// A latency bound of the issue (100 ms, 1 s) as asserted here. The issue's
// numbers are for the Release build a user runs, and are asserted unchanged
// there. Under AddressSanitizer (or ThreadSanitizer) the same server answers
// about 10 times fewer requests (the 64-client run: 2.0k/s against 20k/s,
// measured), and a first answer took 147 ms once, so there the bound is 5 times
// the issue's: still far below what a starved client waits (seconds), but not a
// measure of the instrumentation. ThreadSanitizer slows this server more (its
// documented slowdown is 5-15x): 16 new clients beside 200 idle connections were
// answered within 15 ms in Release and 472-567 ms under TSan (four runs of the
// same tree), so under TSan the bound is 10 times the issue's (1 s).
#if SWEETSPOT_UNDER_TSAN
constexpr double kLatencyScale = 10.0;
#elif SWEETSPOT_UNDER_ASAN
constexpr double kLatencyScale = 5.0;
#else
constexpr double kLatencyScale = 1.0;
#endif
constexpr double Bound(double issue_s) { return issue_s * kLatencyScale; }

// `full_s`, or SWEETSPOT_LOAD_SECONDS when that is lower (never below `floor_s`).
double Seconds(double full_s, double floor_s = 1.0) {
  const char* env = std::getenv("SWEETSPOT_LOAD_SECONDS");
  const double cap = env != nullptr ? std::atof(env) : full_s;
  return std::max(floor_s, std::min(full_s, cap > 0 ? cap : full_s));
}

// The server with its defaults; only what a test cannot share is set: an
// ephemeral port, no jobs file (ServerProcess adds both), so that the test
// log does not hold a line per request, no access log, and no per-address
// connection limit: these tests play up to 256 clients, which would come from
// as many addresses, all from 127.0.0.1 (the limit has its own tests,
// attack_test.cpp).
bool StartWithDefaults(ServerProcess* server, std::vector<std::string> extra = {}) {
  extra.push_back("--no-access-log");
  extra.insert(extra.end(), {"--max-connections-per-client", "100000"});
  return server->Start(extra);
}

// A value of the server's /metrics, e.g. Metric(text, "sweetspot_workers{pool=\"light\"}").
double Metric(const std::string& text, const std::string& series) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  return -1;
}

std::string MetricsOf(int port) {
  httplib::Client client("127.0.0.1", port);
  const auto res = client.Get("/metrics");
  return res ? res->body : std::string();
}

// What one keep-alive client saw.
struct ClientRecord {
  long answers = 0;     // 200 answers
  long failures = 0;    // transport errors and non-200 answers
  double first_s = -1;  // from the start to its first answer
  double worst_s = 0;   // its slowest request
};

// `clients` keep-alive clients post the example scene in a loop for
// `duration_s`, all starting together. Returns one record per client.
std::vector<ClientRecord> RunKeepAliveClients(int port, int clients, double duration_s) {
  std::vector<ClientRecord> records(static_cast<std::size_t>(clients));
  std::mutex mutex;
  std::condition_variable cv;
  int ready = 0;
  bool go = false;
  std::vector<std::thread> threads;
  for (int i = 0; i < clients; ++i) {
    threads.emplace_back([&, i] {
      httplib::Client client("127.0.0.1", port);
      client.set_keep_alive(true);
      client.set_tcp_nodelay(true);
      client.set_read_timeout(20, 0);
      {
        std::unique_lock<std::mutex> lock(mutex);
        ++ready;
        cv.notify_all();
        cv.wait(lock, [&] { return go; });
      }
      ClientRecord& record = records[static_cast<std::size_t>(i)];
      const auto start = Clock::now();
      const auto end = start + std::chrono::duration<double>(duration_s);
      while (Clock::now() < end) {
        const auto sent = Clock::now();
        const auto res = client.Post("/v1/sweet-spot", kSweetSpotBody, "application/json");
        const double took = SecondsSince(sent);
        record.worst_s = std::max(record.worst_s, took);
        if (!res || res->status != 200) {
          ++record.failures;
          continue;
        }
        if (record.answers++ == 0) record.first_s = SecondsSince(start);
      }
    });
  }
  {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait(lock, [&] { return ready == clients; });
    go = true;
  }
  cv.notify_all();
  for (auto& t : threads) t.join();
  return records;
}

struct FairnessFigures {
  long total = 0, least = 0, most = 0, failures = 0;
  double mean = 0, worst_first_s = 0, worst_wait_s = 0;
  int never_answered = 0;
};

FairnessFigures Summarise(const std::vector<ClientRecord>& records) {
  FairnessFigures f;
  f.least = records.empty() ? 0 : records.front().answers;
  for (const ClientRecord& r : records) {
    f.total += r.answers;
    f.failures += r.failures;
    f.least = std::min(f.least, r.answers);
    f.most = std::max(f.most, r.answers);
    f.worst_wait_s = std::max(f.worst_wait_s, r.worst_s);
    if (r.answers == 0) {
      ++f.never_answered;
    } else {
      f.worst_first_s = std::max(f.worst_first_s, r.first_s);
    }
  }
  f.mean = records.empty() ? 0 : static_cast<double>(f.total) / records.size();
  return f;
}

// `clients` keep-alive clients against a server with its defaults for the
// issue's 10 s: their figures, printed and recorded as the test's report. The
// server must stop cleanly afterwards.
FairnessFigures RunFairness(int clients, std::string* report) {
  ServerProcess server;
  EXPECT_TRUE(StartWithDefaults(&server)) << server.log();
  const double seconds = Seconds(10);
  const FairnessFigures f = Summarise(RunKeepAliveClients(server.port(), clients, seconds));
  std::ostringstream out;
  out << clients << " keep-alive clients for " << seconds << " s: " << f.total << " answers ("
      << f.total / seconds << "/s); per client least " << f.least << ", mean " << f.mean
      << ", most " << f.most << " (least/mean " << (f.mean > 0 ? f.least / f.mean : 0)
      << "); slowest first answer " << f.worst_first_s * 1e3 << " ms; slowest request "
      << f.worst_wait_s * 1e3 << " ms; never answered " << f.never_answered << "; failures "
      << f.failures;
  *report = out.str();
  std::cout << "fairness: " << *report << std::endl;
  ::testing::Test::RecordProperty("report", *report);
  EXPECT_EQ(f.never_answered, 0) << *report;
  EXPECT_EQ(f.failures, 0) << *report;
  EXPECT_EQ(server.Stop(SIGTERM), 0);
  return f;
}

// Issue 14, 1: 64 keep-alive clients for 10 s with the server's defaults.
TEST(ServingTest, SixtyFourKeepAliveClientsAreServedFairly) {
  std::string report;
  const FairnessFigures f = RunFairness(64, &report);
  // The issue's numbers: every first answer within 100 ms, the least served
  // client at least a quarter of the mean.
  EXPECT_LE(f.worst_first_s, Bound(0.100)) << report;
  EXPECT_GE(static_cast<double>(f.least), f.mean / 4) << report;
}

// Issue 14, 1: 256 clients, the default connection limit: every client served,
// no request waits more than 1 s.
TEST(ServingTest, TwoHundredFiftySixKeepAliveClientsAreAllServedWithinASecond) {
  std::string report;
  const FairnessFigures f = RunFairness(256, &report);
  EXPECT_LE(f.worst_wait_s, Bound(1.0)) << report;
  EXPECT_LE(f.worst_first_s, Bound(1.0)) << report;
}

// Issue 14, 2: 200 connections trickle one header line a second for 30 s. A
// probe from another client (/health on a new connection, /v1/sweet-spot on a
// keep-alive one) is answered within 100 ms the whole time, and every slow
// connection is answered 408 and closed once its head has taken the default
// 10 s (the whole head, not each read); a closed trickler connects again.
TEST(ServingTest, TwoHundredTricklingClientsAreCutOffAtTheHeadDeadlineAndProbesPass) {
  ServerProcess server;
  ASSERT_TRUE(StartWithDefaults(&server)) << server.log();
  const int port = server.port();
  const double seconds = Seconds(30, 13);
  constexpr int kTricklers = 200;
  constexpr double kHeaderTimeoutS = 10.0;  // the default --header-timeout-s
  std::atomic<bool> done{false};
  std::mutex mutex;
  std::vector<double> cut_after_s;  // head start to the server's close, per cut connection
  long answered_408 = 0, other_answers = 0, connect_failures = 0;
  std::vector<std::thread> tricklers;
  for (int i = 0; i < kTricklers; ++i) {
    tricklers.emplace_back([&, i] {
      // Spread the starts over the first second, as real clients would arrive.
      std::this_thread::sleep_for(std::chrono::milliseconds(5 * i));
      while (!done.load()) {
        const int fd = Connect(port);
        if (fd < 0) {
          std::lock_guard<std::mutex> lock(mutex);
          ++connect_failures;
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          continue;
        }
        const auto start = Clock::now();
        bool closed = false;
        std::string answer;
        SendAll(fd, "GET /health HTTP/1.1\r\n");
        for (int line = 0; !done.load() && !closed; ++line) {
          // One header line a second, well inside the 10 s read timeout.
          const ReadResult read = ReadFor(fd, 1.0, [](const std::string&) { return false; });
          answer += read.bytes;
          if (read.closed) {
            closed = true;
            break;
          }
          if (!SendAll(fd, "X-Trickle-" + std::to_string(line) + ": still typing\r\n")) {
            // The server closed between two lines: read what it said.
            const ReadResult rest = ReadFor(fd, 1.0, [](const std::string&) { return false; });
            answer += rest.bytes;
            closed = true;
          }
        }
        const double lived_s = SecondsSince(start);
        close(fd);
        if (!closed) break;  // the test ended first
        std::lock_guard<std::mutex> lock(mutex);
        cut_after_s.push_back(lived_s);
        if (answer.rfind("HTTP/1.1 408", 0) == 0) {
          ++answered_408;
        } else {
          ++other_answers;
        }
      }
    });
  }
  // The probes: every 100 ms from another client, for the whole run.
  std::vector<double> health_s, sweet_spot_s;
  long probe_failures = 0;
  httplib::Client keep_alive("127.0.0.1", port);
  keep_alive.set_keep_alive(true);
  keep_alive.set_tcp_nodelay(true);
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    {
      httplib::Client fresh("127.0.0.1", port);  // a new connection each time
      fresh.set_tcp_nodelay(true);
      const auto t = Clock::now();
      const auto res = fresh.Get("/health");
      health_s.push_back(SecondsSince(t));
      if (!res || res->status != 200) ++probe_failures;
    }
    {
      const auto t = Clock::now();
      const auto res = keep_alive.Post("/v1/sweet-spot", kSweetSpotBody, "application/json");
      sweet_spot_s.push_back(SecondsSince(t));
      if (!res || res->status != 200) ++probe_failures;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  done = true;
  for (auto& t : tricklers) t.join();
  const std::string metrics = MetricsOf(port);

  std::sort(cut_after_s.begin(), cut_after_s.end());
  const double worst_health = *std::max_element(health_s.begin(), health_s.end());
  const double worst_sweet = *std::max_element(sweet_spot_s.begin(), sweet_spot_s.end());
  std::ostringstream report;
  report << kTricklers << " trickling connections for " << seconds << " s: " << cut_after_s.size()
         << " cut (" << answered_408 << " with 408, " << other_answers << " otherwise), after "
         << (cut_after_s.empty() ? 0 : cut_after_s.front()) << " to "
         << (cut_after_s.empty() ? 0 : cut_after_s.back()) << " s; probes: " << health_s.size()
         << " /health (worst " << worst_health * 1e3 << " ms), " << sweet_spot_s.size()
         << " /v1/sweet-spot (worst " << worst_sweet * 1e3 << " ms), " << probe_failures
         << " failed; connect failures " << connect_failures << "; server header_timeout closes "
         << Metric(metrics, "sweetspot_connections_closed_total{reason=\"header_timeout\"}");
  std::cout << "slow clients: " << report.str() << std::endl;
  RecordProperty("report", report.str());

  EXPECT_EQ(probe_failures, 0) << report.str();
  EXPECT_LE(worst_health, Bound(0.100)) << report.str();
  EXPECT_LE(worst_sweet, Bound(0.100)) << report.str();
  EXPECT_EQ(connect_failures, 0) << report.str();
  // Every trickler that started in the first 2 s was cut once at least.
  ASSERT_GE(cut_after_s.size(), static_cast<std::size_t>(kTricklers)) << report.str();
  EXPECT_EQ(other_answers, 0) << report.str();
  // Cut at the deadline: not before 10 s of head, and at most 0.5 s late (the
  // loop checks deadlines every 25 ms; the trickler notices within its 1 s poll
  // only because the server's close wakes it at once).
  EXPECT_GE(cut_after_s.front(), kHeaderTimeoutS - 0.05) << report.str();
  EXPECT_LE(cut_after_s.back(), kHeaderTimeoutS + 0.5) << report.str();
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

// Issue 14, 2: a body slower than --body-min-rate-bytes-per-s is cut off the
// same way, while a body at a decent rate on another connection is answered.
TEST(ServingTest, BodySlowerThanTheMinimumRateIsCutOffAndAFasterOneIsServed) {
  ServerProcess server;
  // 1 s for the head, then 1000 B/s: a 4000-byte body must be in within 5 s.
  ASSERT_TRUE(StartWithDefaults(&server,
                                {"--header-timeout-s", "1", "--body-min-rate-bytes-per-s", "1000"}))
      << server.log();
  const int port = server.port();
  std::string body = kSweetSpotBody;
  body += std::string(4000 - body.size(), ' ');  // JSON allows trailing spaces
  const std::string head =
      "POST /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nContent-Type: "
      "application/json\r\nContent-Length: 4000\r\n\r\n";
  // Sends the body in 100-byte pieces every `pause_s`; returns the answer and
  // the seconds from the head to the server's answer or close.
  auto post_slowly = [&](double pause_s, std::string* answer) {
    const int fd = Connect(port);
    EXPECT_GE(fd, 0);
    SendAll(fd, head);
    const auto start = Clock::now();
    for (std::size_t at = 0; at < body.size(); at += 100) {
      const ReadResult early =
          ReadFor(fd, pause_s, [](const std::string& s) { return !s.empty(); });
      if (!early.bytes.empty() || early.closed) {
        *answer = early.bytes + ReadFor(fd, 2.0, [](const std::string&) { return false; }).bytes;
        close(fd);
        return SecondsSince(start);
      }
      if (!SendAll(fd, body.substr(at, 100))) break;
    }
    const ReadResult rest = ReadFor(fd, 10.0, [](const std::string& s) {
      return s.find("\r\n\r\n") != std::string::npos && s.find("}\n") != std::string::npos;
    });
    *answer = rest.bytes;
    close(fd);
    return SecondsSince(start);
  };
  std::string slow_answer, fast_answer;
  double slow_s = 0, fast_s = 0;
  std::thread slow([&] { slow_s = post_slowly(0.5, &slow_answer); });   // 200 B/s: 20 s needed
  std::thread fast([&] { fast_s = post_slowly(0.05, &fast_answer); });  // 2000 B/s: 2 s
  slow.join();
  fast.join();
  std::cout << "slow body: cut after " << slow_s << " s; the 2000 B/s body answered after "
            << fast_s << " s" << std::endl;
  EXPECT_EQ(slow_answer.substr(0, 12), "HTTP/1.1 408") << slow_answer;
  EXPECT_NE(slow_answer.find("body_min_rate_bytes_per_s"), std::string::npos) << slow_answer;
  // Deadline 1 + 4000 / 1000 = 5 s after the head; the loop checks every 25 ms.
  EXPECT_GE(slow_s, 4.9);
  EXPECT_LE(slow_s, 5.6);
  EXPECT_EQ(fast_answer.substr(0, 12), "HTTP/1.1 200") << fast_answer;
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

// Issue 14, 2: idle keep-alive connections hold no worker. 200 connections
// that made one request and stay open idle do not delay 16 new clients, with
// the default 8 workers (before, 8 idle connections were an outage).
TEST(ServingTest, IdleKeepAliveConnectionsHoldNoWorker) {
  ServerProcess server;
  ASSERT_TRUE(StartWithDefaults(&server)) << server.log();
  const int port = server.port();
  std::vector<int> idle;
  for (int i = 0; i < 200; ++i) {
    const int fd = Connect(port);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(SendAll(fd, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n"));
    const ReadResult r =
        ReadFor(fd, 5.0, [](const std::string& s) { return s.find("}") != std::string::npos; });
    ASSERT_EQ(r.bytes.substr(0, 12), "HTTP/1.1 200");
    idle.push_back(fd);  // open, idle, keep-alive
  }
  std::vector<double> waits(16);
  std::vector<std::thread> clients;
  for (int i = 0; i < 16; ++i) {
    clients.emplace_back([&, i] {
      httplib::Client client("127.0.0.1", port);
      const auto t = Clock::now();
      const auto res = client.Post("/v1/sweet-spot", kSweetSpotBody, "application/json");
      waits[static_cast<std::size_t>(i)] = res && res->status == 200 ? SecondsSince(t) : 99.0;
    });
  }
  for (auto& c : clients) c.join();
  const std::string metrics = MetricsOf(port);
  const double worst = *std::max_element(waits.begin(), waits.end());
  std::cout << "200 idle keep-alive connections: 16 new clients answered within " << worst * 1e3
            << " ms; idle connections the server counts: "
            << Metric(metrics, "sweetspot_connections{state=\"idle\"}") << std::endl;
  EXPECT_LE(worst, Bound(0.100));
  EXPECT_EQ(Metric(metrics, "sweetspot_workers{pool=\"light\"}"), 8);
  for (const int fd : idle) close(fd);
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

// Slow readers: 16 clients (more than the 8 light workers) ask for a 157 KB
// answer through a 4 KiB receive window and do not read. The rest of each
// answer is sent as its client reads, without holding a worker: probes from
// another client are answered within 100 ms meanwhile, and each slow reader,
// once it reads, gets its whole answer intact.
TEST(ServingTest, ClientsThatDoNotReadHoldNoWorker) {
  ServerProcess server;
  ASSERT_TRUE(StartWithDefaults(&server)) << server.log();
  const int port = server.port();
  std::vector<int> readers;
  for (int i = 0; i < 16; ++i) {
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(fd, 0);
    const int window = 4096;  // before connect: the advertised window stays small
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &window, sizeof window);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    ASSERT_TRUE(SendAll(fd, "GET /v1/speed-vs-error HTTP/1.1\r\nHost: x\r\n\r\n"));
    readers.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the answers are stuck
  std::vector<double> probes_s;
  httplib::Client probe("127.0.0.1", port);
  probe.set_keep_alive(true);
  for (int i = 0; i < 20; ++i) {
    const auto t = Clock::now();
    const auto health = probe.Get("/health");
    const auto sweet = probe.Post("/v1/sweet-spot", kSweetSpotBody, "application/json");
    probes_s.push_back(SecondsSince(t));
    ASSERT_TRUE(health && sweet);
    EXPECT_EQ(health->status, 200);
    EXPECT_EQ(sweet->status, 200);
  }
  const std::string metrics = MetricsOf(port);
  // Now read: every answer arrives whole.
  std::size_t complete = 0;
  for (const int fd : readers) {
    const ReadResult r = ReadFor(fd, 5.0, [](const std::string& s) {
      const auto head_end = s.find("\r\n\r\n");
      if (head_end == std::string::npos) return false;
      const auto at = s.find("Content-Length: ");
      return at != std::string::npos &&
             s.size() - head_end - 4 >= std::stoul(s.substr(at + 16, s.find("\r\n", at) - at - 16));
    });
    const auto body_at = r.bytes.find("\r\n\r\n");
    if (r.bytes.rfind("HTTP/1.1 200", 0) == 0 && body_at != std::string::npos &&
        nlohmann::json::accept(r.bytes.substr(body_at + 4))) {
      ++complete;
    }
    close(fd);
  }
  const double worst = *std::max_element(probes_s.begin(), probes_s.end());
  std::cout << "16 clients not reading 157 KB answers: probes (/health + /v1/sweet-spot) within "
            << worst * 1e3 << " ms; light workers busy at the time "
            << Metric(metrics, "sweetspot_workers_busy{pool=\"light\"}") << "; answers complete "
            << "once read: " << complete << " of 16" << std::endl;
  EXPECT_LE(worst, Bound(0.100));
  EXPECT_EQ(complete, 16u);
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

// Issue 14, 3: connections past --max-connections get their 503 at once and
// are closed even when the client ignores "Connection: close" and keeps
// sending; the admitted connections are served meanwhile.
TEST(ServingTest, ConnectionsPastTheLimitGet503AtOnceAndAreClosedEvenIfTheClientIgnoresIt) {
  ServerProcess server;
  ASSERT_TRUE(StartWithDefaults(&server, {"--max-connections", "4"})) << server.log();
  const int port = server.port();
  std::vector<int> admitted;
  for (int i = 0; i < 4; ++i) {
    const int fd = Connect(port);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(SendAll(fd, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n"));
    ASSERT_EQ(
        ReadFor(fd, 5.0, [](const std::string& s) { return s.find("}") != std::string::npos; })
            .bytes.substr(0, 12),
        "HTTP/1.1 200");
    admitted.push_back(fd);
  }
  // 20 stubborn clients over the limit, at once.
  std::vector<double> answer_s(20), closed_s(20);
  std::vector<std::string> answers(20);
  std::vector<std::thread> stubborn;
  for (int i = 0; i < 20; ++i) {
    stubborn.emplace_back([&, i] {
      const int fd = Connect(port);
      if (fd < 0) return;
      const auto start = Clock::now();
      SendAll(fd, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n");
      const ReadResult first =
          ReadFor(fd, 5.0, [](const std::string& s) { return s.find("}\n") != std::string::npos; });
      answer_s[static_cast<std::size_t>(i)] = SecondsSince(start);
      answers[static_cast<std::size_t>(i)] = first.bytes;
      // Ignore "Connection: close": keep the connection and keep sending. The
      // server half-closes at once (the client reads end of stream) and closes
      // for good after draining 1 s: then the kernel answers with a reset and a
      // send fails. That moment is when the server let go of the connection.
      SendAll(fd, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n");
      closed_s[static_cast<std::size_t>(i)] = 99.0;
      while (SecondsSince(start) < 10.0) {
        if (!SendAll(fd, "X-Still-Here: yes\r\n")) {
          closed_s[static_cast<std::size_t>(i)] = SecondsSince(start);
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      close(fd);
    });
  }
  // The admitted connections are served while the stubborn ones wait.
  for (const int fd : admitted) {
    const auto t = Clock::now();
    ASSERT_TRUE(SendAll(fd, "GET /v1/version HTTP/1.1\r\nHost: x\r\n\r\n"));
    const ReadResult r =
        ReadFor(fd, 5.0, [](const std::string& s) { return s.find("}\n") != std::string::npos; });
    EXPECT_EQ(r.bytes.substr(0, 12), "HTTP/1.1 200");
    EXPECT_LE(SecondsSince(t), Bound(0.100));
  }
  for (auto& t : stubborn) t.join();
  const double worst_answer = *std::max_element(answer_s.begin(), answer_s.end());
  const double worst_close = *std::max_element(closed_s.begin(), closed_s.end());
  std::cout << "20 connections over the limit: 503 within " << worst_answer * 1e3
            << " ms, closed within " << worst_close << " s while ignoring Connection: close"
            << std::endl;
  for (const std::string& a : answers) {
    EXPECT_EQ(a.substr(0, 12), "HTTP/1.1 503") << a;
    EXPECT_NE(a.find("Connection: close"), std::string::npos) << a;
    EXPECT_NE(a.find("Retry-After: 1"), std::string::npos) << a;
    EXPECT_NE(a.find("\"TooBusy\""), std::string::npos) << a;
  }
  EXPECT_LE(worst_answer, Bound(0.100));
  // Closed after the 1 s drain (the reset shows at the send after it, 50 ms
  // apart), not after the 5 s keep-alive timeout nor ever.
  EXPECT_GE(worst_close, 0.9);
  EXPECT_LE(worst_close, 1.5);
  // Once an admitted connection closes, a new one is admitted.
  close(admitted.back());
  admitted.pop_back();
  int status = 0;
  for (int i = 0; i < 100 && status != 200; ++i) {
    httplib::Client next("127.0.0.1", port);
    const auto res = next.Get("/health");
    status = res ? res->status : 0;
    if (status != 200) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(status, 200);
  for (const int fd : admitted) close(fd);
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

// Issue 14, 4: many clients asking for model work at once do not run more
// solver threads than the cores, and cheap requests and /health pass them.
TEST(ServingTest, ModelWorkStaysInItsBoundedPoolAndCheapRequestsPassIt) {
  ServerProcess server;
  ASSERT_TRUE(StartWithDefaults(&server)) << server.log();
  const int port = server.port();
  // The CPUs the server may use (its default compute pool): affinity and cgroup quota.
  const int cores = server::DefaultThreadCount();
  // A sweep of 5000 designs (the cork fill's depth): ~60 ms per request in a
  // Release build, several times that under the sanitizers.
  const std::string explore =
      R"({"bat": {"preset": "paper-wood", "fill": {"material": "cork", "diameter_m": 0.0254, )"
      R"("depth_m": 0.254}}, "outputs": ["max_exit_speed"], "parameters": )"
      R"([{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 5000}]})";
  const double seconds = Seconds(6, 3);
  std::atomic<bool> done{false};
  std::atomic<long> heavy_ok{0}, heavy_failed{0};
  std::vector<std::thread> heavy;
  for (int i = 0; i < 16; ++i) {
    heavy.emplace_back([&] {
      httplib::Client client("127.0.0.1", port);
      client.set_read_timeout(60, 0);
      while (!done.load()) {
        const auto res = client.Post("/v1/explore", explore, "application/json");
        if (res && res->status == 200) {
          ++heavy_ok;
        } else {
          ++heavy_failed;
        }
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the pool is saturated
  std::vector<double> health_s, sweet_s;
  long probe_failures = 0;
  httplib::Client probe("127.0.0.1", port);
  probe.set_keep_alive(true);
  probe.set_tcp_nodelay(true);
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    auto t = Clock::now();
    auto res = probe.Get("/health");
    health_s.push_back(SecondsSince(t));
    if (!res || res->status != 200) ++probe_failures;
    t = Clock::now();
    res = probe.Post("/v1/sweet-spot", kSweetSpotBody, "application/json");
    sweet_s.push_back(SecondsSince(t));
    if (!res || res->status != 200) ++probe_failures;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string metrics = MetricsOf(port);
  done = true;
  for (auto& t : heavy) t.join();
  const double compute_peak = Metric(metrics, "sweetspot_workers_busy_peak{pool=\"compute\"}");
  const double compute_workers = Metric(metrics, "sweetspot_workers{pool=\"compute\"}");
  const double worst_health = *std::max_element(health_s.begin(), health_s.end());
  const double worst_sweet = *std::max_element(sweet_s.begin(), sweet_s.end());
  std::ostringstream report;
  report << "16 clients posting 5000-design sweeps for " << seconds << " s: " << heavy_ok.load()
         << " answered, " << heavy_failed.load() << " failed; compute workers " << compute_workers
         << " (cores " << cores << "), most busy at once " << compute_peak
         << "; probes: " << health_s.size() << " /health worst " << worst_health * 1e3 << " ms, "
         << sweet_s.size() << " closed-form /v1/sweet-spot worst " << worst_sweet * 1e3 << " ms";
  std::cout << "model work: " << report.str() << std::endl;
  EXPECT_EQ(compute_workers, cores) << report.str();
  EXPECT_LE(compute_peak, cores) << report.str();
  EXPECT_EQ(compute_peak, cores) << "the sweeps never filled the pool: " << report.str();
  EXPECT_GT(heavy_ok.load(), 0) << report.str();
  EXPECT_EQ(heavy_failed.load(), 0) << report.str();
  EXPECT_EQ(probe_failures, 0) << report.str();
  EXPECT_LE(worst_health, Bound(0.100)) << report.str();
  EXPECT_LE(worst_sweet, Bound(0.100)) << report.str();
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

}  // namespace
}  // namespace serving_test
}  // namespace sweetspot::testing
