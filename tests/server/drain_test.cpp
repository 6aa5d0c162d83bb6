// A rolling stop without refusals: the real sweetspot-server with --drain-s, clients looping
// requests through its SIGTERM. During the drain GET /ready answers 503 and every request is
// still answered (new connections are accepted; keep-alive answers carry Connection: close);
// once the drain is over the listener closes and connections are refused.
#include <httplib.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tests/server/server_process.hpp"

namespace sweetspot {
namespace {

using Clock = std::chrono::steady_clock;

// One request of a looping client: when it was sent (s after the signal; negative before) and
// what came back (an HTTP status, or 0 for a request that failed: refused, reset, no answer).
struct Attempt {
  double sent_s = 0.0;
  int status = 0;
  std::string error;            // httplib's error when status is 0
  std::string connection;       // the answer's Connection header
};

// Loops GET `path` until `stop`, one new connection per request (`keep_alive` false) or one
// kept-alive client, recording every attempt with its time relative to *signal_at.
std::vector<Attempt> Loop(int port, const std::string& path, bool keep_alive,
                          const std::atomic<bool>& stop, const std::atomic<long long>& signal_at) {
  std::vector<Attempt> attempts;
  httplib::Client client("127.0.0.1", port);
  client.set_keep_alive(keep_alive);
  client.set_connection_timeout(1, 0);
  client.set_read_timeout(3, 0);
  while (!stop.load()) {
    Attempt attempt;
    const auto sent = Clock::now();
    attempt.sent_s =
        std::chrono::duration<double>(sent.time_since_epoch()).count() - signal_at.load() * 1e-9;
    const auto res = client.Get(path);
    if (res) {
      attempt.status = res->status;
      attempt.connection = res->get_header_value("Connection");
    } else {
      attempt.error = httplib::to_string(res.error());
    }
    attempts.push_back(attempt);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return attempts;
}

long long NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// The first failed attempt's time (s after the signal), or a large number when none failed.
double FirstFailure(const std::vector<Attempt>& attempts) {
  for (const Attempt& a : attempts) {
    if (a.status == 0) return a.sent_s;
  }
  return 1e9;
}

// Runs looping clients (a new connection per request, and a keep-alive one) through a SIGTERM
// of a server started with `args`, polling /ready meanwhile; stops the clients once both have
// seen a failure or `watch_s` after the signal.
struct RollingStop {
  std::vector<Attempt> fresh, kept, ready;
  int exit_status = -3;
  std::string log;
};

RollingStop RunThroughSigterm(const std::vector<std::string>& args, double watch_s) {
  RollingStop out;
  testing::ServerProcess server;
  if (!server.Start(args)) {
    out.log = server.log();
    return out;
  }
  std::atomic<bool> stop{false};
  std::atomic<long long> signal_at{NowNs() + 3600LL * 1000000000LL};  // "not yet"
  std::thread fresh([&] { out.fresh = Loop(server.port(), "/v1/version", false, stop, signal_at); });
  std::thread kept([&] { out.kept = Loop(server.port(), "/v1/version", true, stop, signal_at); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  httplib::Client probe("127.0.0.1", server.port());
  probe.set_connection_timeout(1, 0);
  Attempt before;  // /ready before the signal
  if (auto res = probe.Get("/ready")) before.status = res->status;
  before.sent_s = -0.3;
  out.ready.push_back(before);
  signal_at.store(NowNs());
  kill(server.pid(), SIGTERM);
  const auto deadline = Clock::now() + std::chrono::duration<double>(watch_s);
  while (Clock::now() < deadline) {
    Attempt attempt;
    attempt.sent_s = (NowNs() - signal_at.load()) * 1e-9;
    if (auto res = probe.Get("/ready")) attempt.status = res->status;
    out.ready.push_back(attempt);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stop.store(true);
  fresh.join();
  kept.join();
  out.exit_status = server.Stop(0);  // signal 0: nothing more is sent, only waited for
  out.log = server.log();
  return out;
}

TEST(DrainTest, SigtermKeepsAnsweringWhileReadyAnswers503ThenStopsAccepting) {
  constexpr double kDrainS = 1.5;
  const RollingStop run = RunThroughSigterm({"--drain-s", "1.5"}, kDrainS + 1.5);
  ASSERT_EQ(run.exit_status, 0) << run.log;
  // Readiness: 200 before the signal, 503 within 200 ms of it and from then on.
  ASSERT_FALSE(run.ready.empty());
  EXPECT_EQ(run.ready.front().status, 200);
  double first_503 = 1e9;
  for (std::size_t i = 1; i < run.ready.size(); ++i) {
    const Attempt& a = run.ready[i];
    if (a.status == 503 && first_503 > 1e8) first_503 = a.sent_s;
    if (first_503 < 1e8 && a.sent_s < kDrainS - 0.1) {
      EXPECT_EQ(a.status, 503) << "/ready at " << a.sent_s << " s after SIGTERM";
    }
  }
  EXPECT_LT(first_503, 0.2) << run.log;
  // Every request sent before the drain's end was answered 200: no refusal, no failure; those
  // sent once /ready said 503 carry Connection: close.
  int in_drain = 0;
  int closing = 0;
  for (const auto* attempts : {&run.fresh, &run.kept}) {
    for (const Attempt& a : *attempts) {
      if (a.sent_s >= kDrainS - 0.05) continue;
      EXPECT_EQ(a.status, 200) << "a request " << a.sent_s << " s after SIGTERM: " << a.error;
      if (a.sent_s > first_503 + 0.01) {
        ++in_drain;
        if (a.connection == "close") ++closing;
      }
    }
  }
  // The clients kept asking throughout the drain (enough requests for the check to mean
  // something), and the drain's answers asked keep-alive clients to reconnect.
  EXPECT_GT(in_drain, 20);
  EXPECT_EQ(closing, in_drain);
  // After the drain the listener closes: the looping clients are refused (so they could
  // have seen a refusal earlier, and did not), never before the drain's end.
  for (const auto* attempts : {&run.fresh, &run.kept}) {
    const double failed_at = FirstFailure(*attempts);
    EXPECT_GE(failed_at, kDrainS - 0.05);
  }
  EXPECT_LT(FirstFailure(run.fresh), kDrainS + 1.0) << "no refusal once the drain was over";
  EXPECT_NE(run.log.find("received SIGTERM, draining for 1.5 s"), std::string::npos) << run.log;
  EXPECT_NE(run.log.find("drain over, stopping"), std::string::npos) << run.log;
}

TEST(DrainTest, WithoutADrainTheListenerClosesAtOnce) {
  // The default (--drain-s 0), for contrast: the same clients are refused within half a
  // second of the signal, which is what the drain above prevents.
  const RollingStop run = RunThroughSigterm({}, 1.0);
  ASSERT_EQ(run.exit_status, 0) << run.log;
  EXPECT_LT(FirstFailure(run.fresh), 0.5);
  EXPECT_NE(run.log.find("received SIGTERM, stopping"), std::string::npos) << run.log;
}

TEST(DrainTest, ReadyNeedsNoTokenAndAnswersReadyWhileServing) {
  testing::ServerProcess server;
  server.SetEnvironment("SWEETSPOT_AUTH_TOKEN", "a-token-of-sixteen-chars");
  ASSERT_TRUE(server.Start()) << server.log();
  httplib::Client client("127.0.0.1", server.port());
  const auto ready = client.Get("/ready");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 200);
  EXPECT_EQ(nlohmann::json::parse(ready->body), nlohmann::json({{"status", "ready"}}));
  const auto version = client.Get("/v1/version");
  ASSERT_TRUE(version);
  EXPECT_EQ(version->status, 401);
  EXPECT_EQ(server.Stop(SIGTERM), 0);
}

}  // namespace
}  // namespace sweetspot
