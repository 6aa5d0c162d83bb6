// Progress of a long CLI run (`sweetspot explore`, `explore-merge`) on stderr: a bar with the
// rate and the time left when stderr is a terminal, nothing in a pipe unless asked, or one
// plain line every few seconds for batch logs (Slurm, Kubernetes). stdout is never touched.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

namespace sweetspot::server {

/// `--progress=auto|on|off|lines`.
enum class ProgressMode {
  kAuto,   ///< A bar when stderr is a terminal, else nothing (the default).
  kOn,     ///< A bar, wherever stderr goes.
  kOff,    ///< Nothing.
  kLines,  ///< One plain line every `ProgressOptions::lines_interval_s` (for logs).
};

/// "auto", "on", "off" or "lines" into *mode; false for anything else.
bool ParseProgressMode(std::string_view text, ProgressMode* mode);

/// How progress is shown.
struct ProgressOptions {
  ProgressMode mode = ProgressMode::kAuto;  ///< See ProgressMode.
  double bar_interval_s = 0.25;             ///< Seconds between two redraws of the bar.
  double lines_interval_s = 5.0;            ///< Seconds between two lines in `lines` mode.
  int fd = 2;                               ///< Where it goes: stderr.
};

/// What a run has done at one moment.
struct ProgressSample {
  double fraction = 0.0;   ///< In [0, 1].
  std::uint64_t done = 0;  ///< Units done (rows, bytes), for the rate.
};

/// "explore [#####-----]  42.0%  1.2M rows  310.0k rows/s  ETA 0:07" (the bar `width` wide;
/// "in 0:11" once done; "ETA ?" before any progress), or the plain line "explore: 42.0% 1200000
/// rows 310000 rows/s elapsed 3.9 s ETA 7 s" when `plain`. An empty `unit` leaves out the
/// counts and the rate (a run that reports only its fraction).
std::string FormatProgress(std::string_view label, std::string_view unit,
                           const ProgressSample& sample, double elapsed_s, bool plain,
                           int width = 30);

/// Shows a run's progress from a thread that samples it, until Finish or destruction.
class ProgressReporter {
 public:
  /// Starts showing `label`'s progress (nothing when the mode resolves to off). `sample`
  /// is called from the reporter's thread; it must be thread-safe.
  ProgressReporter(std::string label, std::string unit, ProgressOptions options,
                   std::function<ProgressSample()> sample);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;
  /// Shows the final state once (the bar ends with a line end) and stops.
  void Finish();
  /// Whether anything is shown (the mode, with `auto` resolved against the terminal).
  bool active() const { return active_; }

 private:
  void Run();
  void Show(bool last);
  std::string label_, unit_;
  ProgressOptions options_;
  std::function<ProgressSample()> sample_;
  bool active_ = false;
  bool bar_ = false;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool finished_ = false;
  std::thread thread_;
};

}  // namespace sweetspot::server
