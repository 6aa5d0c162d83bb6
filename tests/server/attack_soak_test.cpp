// The attacks of the attack round together, for SWEETSPOT_SOAK_SECONDS (default 30 s) against
// one real sweetspot-server with its defaults: while they run, /health and a closed-form
// sweet-spot probe answer within 250 ms, every legitimate request gets its correct answer or
// a 4xx/503 with Retry-After, and the server's resident memory stays under a stated bound.
#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/sanitizers.hpp"
#include "tests/server/attack_client.hpp"
#include "tests/server/server_process.hpp"
#include "tests/server/wire.hpp"

namespace sweetspot::testing {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace attack_soak_test {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// One attack: sends its requests in a loop until `stop`, on its own connections.
struct Attack {
  const char* name;
  std::function<void(int port, const std::atomic<bool>& stop)> run;
};

// Sends `raw` on a new connection from 127.0.0.1 and reads the answer for at most 5 s.
void Hit(int port, const std::string& raw) { Exchange(port, raw, 5.0); }

std::vector<Attack> Attacks() {
  std::vector<Attack> attacks;
  // 1: unique long methods of requests the loop refuses (a metrics label before).
  attacks.push_back({"methods", [](int port, const std::atomic<bool>& stop) {
                       for (int i = 0; !stop; ++i) {
                         Hit(port, std::string(4000, 'M') + std::to_string(i) +
                                       " /health HTTP/1.1\r\nContent-Length: bad\r\n\r\n");
                       }
                     }});
  // 2: 2000 ranges of /openapi.json, from clients that do not read their answer.
  attacks.push_back({"ranges", [](int port, const std::atomic<bool>& stop) {
                       std::string ranges = "bytes=0-";
                       for (int i = 0; i < 2000; ++i) ranges += ",0-";
                       while (!stop) {
                         std::vector<int> fds;
                         for (int i = 0; i < 5; ++i) {
                           const int fd = Connect(port);
                           if (fd < 0) continue;
                           SendAll(fd, "GET /openapi.json HTTP/1.1\r\nRange: " + ranges +
                                           "\r\n\r\n");
                           fds.push_back(fd);
                         }
                         std::this_thread::sleep_for(std::chrono::milliseconds(500));
                         for (const int fd : fds) close(fd);
                       }
                     }});
  // 4: a 200-byte synchronous explore of 100,000 designs x 10,000 curve samples.
  attacks.push_back(
      {"explore", [](int port, const std::atomic<bool>& stop) {
         const std::string body =
             R"({"bat": {"preset": "paper-wood"}, "outputs": ["exit_speed_curve"],
                 "options": {"curve_samples": 10000},
                 "parameters": [{"path": "cor", "min": 0.4, "max": 0.6, "count": 100000}]})";
         while (!stop) Hit(port, RawPost("/v1/explore", body));
       }});
  // 3: CSV explore jobs of 20,000 designs (5 MB results each), their results read back.
  attacks.push_back({"jobs", [](int port, const std::atomic<bool>& stop) {
                       const std::string job =
                           R"({"path": "/v1/explore", "body": {"bat": {"preset": "paper-wood"},
                               "outputs": ["max_exit_speed", "properties"], "format": "csv",
                               "parameters": [{"path": "cor", "min": 0.4, "max": 0.6,
                                               "count": 20000}]}})";
                       std::vector<std::string> ids;
                       while (!stop) {
                         const std::string answer = Exchange(port, RawPost("/v1/jobs", job), 5.0);
                         if (StatusOf(answer) == 202) {
                           const Json created = Json::parse(BodyOf(answer), nullptr, false);
                           if (created.is_object() && created.contains("id")) {
                             ids.push_back(created["id"].get<std::string>());
                           }
                         }
                         if (ids.size() > 2) {
                           Hit(port, "GET /v1/jobs/" + ids[ids.size() - 3] +
                                         "/result HTTP/1.1\r\nConnection: close\r\n\r\n");
                         }
                         std::this_thread::sleep_for(std::chrono::milliseconds(500));
                       }
                     }});
  // 5: 10,000-point flexible curves whose clients leave after 200 ms.
  attacks.push_back({"abandoned", [](int port, const std::atomic<bool>& stop) {
                       while (!stop) {
                         const int fd = Connect(port);
                         if (fd < 0) continue;
                         SendAll(fd, RawPost("/v1/sweet-spot", kLongFlexibleCurve));
                         std::this_thread::sleep_for(std::chrono::milliseconds(200));
                         close(fd);
                       }
                     }});
  // 6: percent-encoded explore paths (the light pool before).
  attacks.push_back({"encoded", [](int port, const std::atomic<bool>& stop) {
                       const std::string body =
                           R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
                               "options": {"model": "hertz"},
                               "parameters": [{"path": "cor", "min": 0.4, "max": 0.6, "count": 200}]})";
                       while (!stop) Hit(port, RawPost("/v1/%65xplore", body));
                     }});
  // 10: one address (127.0.0.2) holding 256 connections that sent a request line only.
  attacks.push_back({"slots", [](int port, const std::atomic<bool>& stop) {
                       std::vector<int> held;
                       while (!stop) {
                         while (held.size() < 256 && !stop) {
                           const int fd = ConnectFrom(port, "127.0.0.2");
                           if (fd < 0) break;
                           SendAll(fd, "GET /health HTTP/1.1\r\n");
                           held.push_back(fd);
                         }
                         std::this_thread::sleep_for(std::chrono::milliseconds(100));
                         // Replace the ones the server closed (refused or timed out).
                         for (int& fd : held) {
                           pollfd p{fd, POLLIN, 0};
                           if (poll(&p, 1, 0) == 1) {
                             close(fd);
                             fd = -1;
                           }
                         }
                         held.erase(std::remove(held.begin(), held.end(), -1), held.end());
                       }
                       for (const int fd : held) close(fd);
                     }});
  // 11: heads with lines over 8 KB, URLs over 8 KB and bare LFs.
  attacks.push_back({"heads", [](int port, const std::atomic<bool>& stop) {
                       while (!stop) {
                         Hit(port, "GET /health HTTP/1.1\r\nX: " + std::string(9000, 'a') +
                                       "\r\n\r\n");
                         Hit(port, "GET /health?" + std::string(9000, 'a') + " HTTP/1.1\r\n\r\n");
                         Hit(port, "GET /health HTTP/1.1\nHost: a\n\nGET /health HTTP/1.1\r\n\r\n");
                       }
                     }});
  return attacks;
}

// What the probes and the legitimate client saw.
struct Record {
  std::mutex mutex;
  std::vector<double> health_s, probe_s;
  std::vector<std::string> wrong;  // unexpected answers, described
  int legit_ok = 0, legit_refused = 0;
  void Wrong(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (wrong.size() < 10) wrong.push_back(what);
  }
};

TEST(AttackSoakTest, AttacksTogetherLeaveTheProbesAnsweredAndMemoryBounded) {
  const char* seconds_env = std::getenv("SWEETSPOT_SOAK_SECONDS");
  const double seconds = seconds_env != nullptr ? std::atof(seconds_env) : 30.0;
  // The defaults' job store, a SQLite file, in a folder of the test's own.
  char folder[] = "/tmp/sweetspot-soak-XXXXXX";
  ASSERT_NE(mkdtemp(folder), nullptr);
  const std::string jobs_db = std::string(folder) + "/jobs.db";
  ServerProcess server;
  ASSERT_TRUE(server.Start({"--no-access-log", "--jobs-db", jobs_db})) << server.log();
  const int port = server.port();
  const std::string probe_body = R"({"bat": {"preset": "paper-wood"}})";
  const std::string legit_body =
      R"({"bat": {"preset": "wood-34-ash"}, "outputs": ["max_exit_speed"],
          "options": {"model": "hertz"}})";
  // The correct answers, before any attack.
  httplib::Client before("127.0.0.1", port);
  const auto probe_ref = before.Post("/v1/sweet-spot", probe_body, "application/json");
  const auto legit_ref = before.Post("/v1/sweet-spot", legit_body, "application/json");
  ASSERT_TRUE(probe_ref && legit_ref);
  ASSERT_EQ(probe_ref->status, 200);
  ASSERT_EQ(legit_ref->status, 200);
  const double probe_speed = Json::parse(probe_ref->body)["max_exit_speed"]["exit_speed_mps"];
  const double legit_speed = Json::parse(legit_ref->body)["max_exit_speed"]["exit_speed_mps"];
  const long long rss_start = ResidentBytes(server.pid());

  std::atomic<bool> stop{false};
  Record record;
  std::vector<std::thread> threads;
  for (const Attack& attack : Attacks()) {
    threads.emplace_back([&stop, port, run = attack.run] { run(port, stop); });
  }
  // The probes: /health and a closed-form sweet spot, each on a new connection every 100 ms
  // (a new connection: admission and the first byte are part of what is measured).
  threads.emplace_back([&] {
    while (!stop) {
      httplib::Client client("127.0.0.1", port);
      client.set_read_timeout(5, 0);
      auto start = Clock::now();
      const auto health = client.Get("/health");
      const double health_s = SecondsSince(start);
      if (!health || health->status != 200) record.Wrong("/health failed");
      start = Clock::now();
      const auto probe = client.Post("/v1/sweet-spot", probe_body, "application/json");
      const double probe_s = SecondsSince(start);
      if (!probe || probe->status != 200 ||
          Json::parse(probe->body)["max_exit_speed"]["exit_speed_mps"] != probe_speed) {
        record.Wrong("sweet-spot probe: " + (probe ? probe->body.substr(0, 200) : "no answer"));
      }
      {
        std::lock_guard<std::mutex> lock(record.mutex);
        record.health_s.push_back(health_s);
        record.probe_s.push_back(probe_s);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  // A legitimate client of the compute pool: the right answer, or 503 with Retry-After.
  threads.emplace_back([&] {
    httplib::Client client("127.0.0.1", port);
    client.set_read_timeout(150, 0);
    while (!stop) {
      const auto res = client.Post("/v1/sweet-spot", legit_body, "application/json");
      if (res && res->status == 200 &&
          Json::parse(res->body)["max_exit_speed"]["exit_speed_mps"] == legit_speed) {
        std::lock_guard<std::mutex> lock(record.mutex);
        ++record.legit_ok;
      } else if (res && res->status == 503 && res->has_header("Retry-After")) {
        std::lock_guard<std::mutex> lock(record.mutex);
        ++record.legit_refused;
      } else {
        record.Wrong("hertz sweet spot: " +
                     (res ? std::to_string(res->status) + " " + res->body.substr(0, 200)
                          : std::string("no answer")));
      }
    }
  });
  long long rss_max = rss_start;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    rss_max = std::max(rss_max, ResidentBytes(server.pid()));
  }
  stop = true;
  for (auto& t : threads) t.join();

  const double health_max = *std::max_element(record.health_s.begin(), record.health_s.end());
  const double probe_max = *std::max_element(record.probe_s.begin(), record.probe_s.end());
  std::ostringstream report;
  report << "soak: " << seconds << " s, " << record.health_s.size() << " probes; /health max "
         << health_max * 1e3 << " ms, sweet-spot probe max " << probe_max * 1e3
         << " ms; legitimate hertz requests " << record.legit_ok << " answered, "
         << record.legit_refused << " 503; RSS " << rss_start / 1048576 << " -> max "
         << rss_max / 1048576 << " MiB";
  std::cout << report.str() << std::endl;
  RecordProperty("report", report.str());
  for (const std::string& what : record.wrong) ADD_FAILURE() << what;
  EXPECT_TRUE(record.wrong.empty());
  EXPECT_LE(health_max, 0.250) << report.str();
  EXPECT_LE(probe_max, 0.250) << report.str();
  EXPECT_GT(record.legit_ok, 0) << report.str();
  // The bound README "Security" states for one server under these attacks: 512 MiB resident
  // (before the fixes the ranges alone took 1.65 GB, an explore 4 GB and more). Under
  // AddressSanitizer freed memory sits in its 256 MiB quarantine plus its shadow: twice that.
  const long long bound = (SWEETSPOT_UNDER_ASAN ? 1024LL : 512LL) * 1048576;
  EXPECT_LT(rss_max, bound) << report.str();
  EXPECT_EQ(server.Stop(SIGTERM), 0);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace attack_soak_test
}  // namespace sweetspot::testing
