#include "server/cli_progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sweetspot::server {
namespace {

// 1234567 -> "1.2M", 12345 -> "12.3k", 123 -> "123".
std::string ShortNumber(double value) {
  char text[32];
  if (value >= 1e9) {
    std::snprintf(text, sizeof text, "%.1fG", value / 1e9);
  } else if (value >= 1e6) {
    std::snprintf(text, sizeof text, "%.1fM", value / 1e6);
  } else if (value >= 1e4) {
    std::snprintf(text, sizeof text, "%.1fk", value / 1e3);
  } else {
    std::snprintf(text, sizeof text, "%.0f", value);
  }
  return text;
}

// 75 -> "1:15", 3725 -> "1:02:05".
std::string ClockText(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  if (s >= 3600) {
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
  }
  return text;
}

void WriteAll(int fd, const std::string& text) {
  std::size_t sent = 0;
  while (sent < text.size()) {
    const ssize_t n = ::write(fd, text.data() + sent, text.size() - sent);
    if (n <= 0) return;  // progress is best effort: a closed stderr loses it
    sent += static_cast<std::size_t>(n);
  }
}

}  // namespace

bool ParseProgressMode(std::string_view text, ProgressMode* mode) {
  if (text == "auto") *mode = ProgressMode::kAuto;
  else if (text == "on") *mode = ProgressMode::kOn;
  else if (text == "off") *mode = ProgressMode::kOff;
  else if (text == "lines") *mode = ProgressMode::kLines;
  else return false;
  return true;
}

std::string FormatProgress(std::string_view label, std::string_view unit,
                           const ProgressSample& sample, double elapsed_s, bool plain, int width) {
  const double f = std::clamp(sample.fraction, 0.0, 1.0);
  const double rate = elapsed_s > 0 ? static_cast<double>(sample.done) / elapsed_s : 0.0;
  const bool eta_known = f > 0 && elapsed_s > 0;
  const double eta_s = eta_known ? elapsed_s * (1 - f) / f : 0.0;
  char percent[16];
  std::snprintf(percent, sizeof percent, "%5.1f%%", 100 * f);
  // Without a unit (an optimisation's starts), the fraction and the times only.
  const std::string counts =
      unit.empty() ? std::string()
                   : (plain ? std::to_string(sample.done) + " " + std::string(unit) + " " +
                                  std::to_string(std::llround(rate)) + " " + std::string(unit) +
                                  "/s "
                            : ShortNumber(static_cast<double>(sample.done)) + " " +
                                  std::string(unit) + "  " + ShortNumber(rate) + " " +
                                  std::string(unit) + "/s  ");
  if (plain) {
    char text[256];
    std::snprintf(text, sizeof text, "%.*s: %.1f%% %selapsed %.1f s ETA %s",
                  static_cast<int>(label.size()), label.data(), 100 * f, counts.c_str(), elapsed_s,
                  eta_known ? (std::to_string(std::lround(eta_s)) + " s").c_str() : "unknown");
    return text;
  }
  const int filled = static_cast<int>(std::floor(f * width));
  std::string bar = std::string(label) + " [" + std::string(static_cast<std::size_t>(filled), '#') +
                    std::string(static_cast<std::size_t>(width - filled), '-') + "] " + percent +
                    "  " + counts;
  bar += f >= 1 ? "in " + ClockText(elapsed_s) : "ETA " + (eta_known ? ClockText(eta_s) : "?");
  return bar;
}

ProgressReporter::ProgressReporter(std::string label, std::string unit, ProgressOptions options,
                                   std::function<ProgressSample()> sample)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      options_(options),
      sample_(std::move(sample)),
      start_(std::chrono::steady_clock::now()) {
  const bool terminal = ::isatty(options_.fd) == 1;
  active_ = options_.mode == ProgressMode::kOn || options_.mode == ProgressMode::kLines ||
            (options_.mode == ProgressMode::kAuto && terminal);
  bar_ = options_.mode != ProgressMode::kLines;
  if (active_) thread_ = std::thread([this] { Run(); });
}

ProgressReporter::~ProgressReporter() { Finish(); }

void ProgressReporter::Run() {
  const double period = bar_ ? options_.bar_interval_s : options_.lines_interval_s;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, std::chrono::duration<double>(std::max(0.01, period)));
    if (stop_) break;
    lock.unlock();
    Show(false);
    lock.lock();
  }
}

void ProgressReporter::Show(bool last) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::string text = FormatProgress(label_, unit_, sample_(), elapsed, !bar_);
  // The bar is redrawn in place (\r, then clear to the line's end); lines each get their own.
  WriteAll(options_.fd, bar_ ? "\r" + text + "\x1b[K" + (last ? "\n" : "") : text + "\n");
}

void ProgressReporter::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (active_) Show(true);
}

}  // namespace sweetspot::server
