// The server's main loop, shared by sweetspot-server and `sweetspot serve`.
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "core/version.hpp"
#include "server/config.hpp"
#include "server/jobs/postgres_job_service.hpp"
#include "server/run.hpp"
#include "server/server.hpp"

namespace sweetspot::server {

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
    int signal_number = 0;
    sigwait(&stop_signals, &signal_number);
    if (finished.load()) return;
    std::cerr << "sweetspot-server: received " << (signal_number == SIGTERM ? "SIGTERM" : "SIGINT")
              << ", stopping\n";
    // Stop() is a no-op before the listen loop starts: repeat until it returns, listening
    // for a second signal meanwhile.
    bool second = false;
    while (!run_returned.load() && !second) {
      server.Stop();
      const timespec wait{0, 10 * 1000 * 1000};
      second = sigtimedwait(&stop_signals, nullptr, &wait) > 0;
    }
    // A second signal ends the running jobs' grace period at once, and the process soon
    // after: whatever still runs 2 s later (a job that ignores its cancel flag, an answer
    // a client reads slowly) is abandoned. Jobs are kept in their store as they are, and a
    // job that was running is resumed by the next start (or another replica).
    if (!second) sigwait(&stop_signals, &signal_number);
    if (finished.load()) return;
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
