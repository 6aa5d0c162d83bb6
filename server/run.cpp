// The server's main loop, shared by sweetspot-server and `sweetspot serve`.
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>

#include "core/version.hpp"
#include "server/config.hpp"
#include "server/jobs/postgres_job_service.hpp"
#include "server/run.hpp"
#include "server/server.hpp"

namespace sweetspot::server {

namespace {

// Waits up to `seconds` for one of `signals`; true when one arrived.
bool SignalWithin(const sigset_t& signals, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (true) {
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::steady_clock::duration::zero()) return false;
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
    const timespec wait{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
    if (sigtimedwait(&signals, nullptr, &wait) > 0) return true;
    if (errno != EINTR && errno != EAGAIN) return false;
  }
}

// The signal thread. The first signal starts the drain: for drain_s the server keeps accepting
// and answering while GET /ready answers 503 (a load balancer takes it out meanwhile); then it
// stops accepting, and the requests and jobs in flight get their grace (Server::Stop, then
// main's Server::Shutdown). A second signal at any point ends the drain and the grace at once,
// and the process soon after.
void HandleStopSignals(Server& server, double drain_s, const sigset_t& stop_signals,
                       const std::atomic<bool>& run_returned, const std::atomic<bool>& finished) {
  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  if (finished.load()) return;
  // Each message is written whole, in one call: the access log writes from other threads.
  const std::string received = std::string("sweetspot-server: received ") +
                               (signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  bool second = false;
  if (drain_s > 0) {
    server.BeginDrain();
    std::ostringstream line;
    line << received << ", draining for " << drain_s
         << " s (GET /ready answers 503, requests are still answered), then stopping\n";
    std::cerr << line.str() << std::flush;
    second = SignalWithin(stop_signals, drain_s);
    if (finished.load()) return;
    if (!second) std::cerr << "sweetspot-server: drain over, stopping\n" << std::flush;
  } else {
    std::cerr << received + ", stopping\n" << std::flush;
  }
  // Stop() is a no-op before the listen loop starts: repeat until it returns, listening
  // for a second signal meanwhile.
  while (!run_returned.load() && !second) {
    server.Stop();
    second = SignalWithin(stop_signals, 0.01);
  }
  // A second signal ends the running jobs' grace period at once, and the process soon
  // after: whatever still runs 2 s later (a job that ignores its cancel flag, an answer
  // a client reads slowly) is abandoned. Jobs are kept in their store as they are, and a
  // job that was running is resumed by the next start (or another replica).
  if (!second) sigwait(&stop_signals, &signal_number);
  if (finished.load()) return;
  server.Stop();
  std::cerr << "sweetspot-server: received a second signal, interrupting the running jobs; "
               "exiting within 2 s\n";
  server.EndShutdownGrace();
  for (int i = 0; i < 200 && !finished.load(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (finished.load()) return;
  std::cerr << "sweetspot-server: still busy 2 s after the second signal: exiting now"
            << std::endl;
  std::_Exit(3);
}

}  // namespace

int RunServerMain(const std::vector<std::string>& args) {
  const auto parsed = ParseCommandLine(args, [](const std::string& name) -> std::optional<std::string> {
    const char* value = std::getenv(name.c_str());
    if (value == nullptr) return std::nullopt;
    return std::string(value);
  });
  if (parsed.show_help) {
    std::cout << Usage("sweetspot-server");
    return 0;
  }
  if (!parsed.error.empty()) {
    std::cerr << "sweetspot-server: " << parsed.error << "\n";
    return 2;
  }

  // Block the stop signals in every thread; one thread waits for them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a client that disconnects must not kill the server

  // Every open connection is a descriptor: raise the soft limit to the hard
  // one, so that max_connections (and the connections refused past it) fit.
  if (rlimit files{}; getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
  }

  Server server(parsed.config);
  std::string error;
  if (!server.Bind(&error)) {
    std::cerr << "sweetspot-server: " << error << "\n";
    return 1;
  }
  std::atomic<bool> run_returned{false};
  std::atomic<bool> finished{false};  // Set before main wakes the signal thread to leave.
  std::thread signal_thread([&] {
    HandleStopSignals(server, parsed.config.drain_s, stop_signals, run_returned, finished);
  });

  std::cerr << "sweetspot-server: jobs "
            << (parsed.config.jobs_db == kNoJobsDb
                    ? std::string("are kept in memory only (--jobs-db none)")
                : IsPostgresUri(parsed.config.jobs_db)
                    ? "are kept in PostgreSQL \"" + RedactedUri(parsed.config.jobs_db) +
                          "\", one store and one queue for every replica"
                    : "are kept in \"" + parsed.config.jobs_db + "\"")
            << "\n";
  std::cerr << "sweetspot-server " << sweetspot::core::SweetspotVersion() << " listening on "
            << parsed.config.host << ":" << server.port() << " with " << parsed.config.threads
            << " threads for requests and " << server.compute_threads()
            << " for models, up to " << parsed.config.max_connections << " connections"
            << std::endl;
  const bool ok = server.Run();  // Returns once in-flight requests are answered.
  run_returned.store(true);
  server.Shutdown();  // Running jobs: the grace period, then interrupted and kept.
  finished.store(true);
  // Wake the signal thread (whichever sigwait it is in) so that it leaves.
  pthread_kill(signal_thread.native_handle(), SIGTERM);
  signal_thread.join();
  std::cerr << "sweetspot-server: stopped" << std::endl;
  return ok ? 0 : 1;
}

}  // namespace sweetspot::server
