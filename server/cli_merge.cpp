#include "server/cli_merge.hpp"

#include <sys/stat.h>

#include <atomic>
#include <fstream>
#include <iostream>
#include <memory>

#include "api/explore/merge_stream.hpp"

namespace sweetspot::server {

int ExploreMergeCommand(const std::vector<std::string>& files, const ProgressOptions& progress) {
  if (files.empty()) {
    std::cerr << "sweetspot explore-merge: give the NDJSON or CSV output of every shard of one "
                 "sweep\n";
    return 2;
  }
  // Progress in bytes read: every shard is read twice (checked, then copied).
  std::uint64_t total_bytes = 0;
  for (const std::string& file : files) {
    struct stat info {};
    if (::stat(file.c_str(), &info) == 0) total_bytes += static_cast<std::uint64_t>(info.st_size);
  }
  std::atomic<std::uint64_t> read{0};
  ProgressReporter reporter(
      "explore-merge", "B", progress, [&read, total_bytes]() {
        const std::uint64_t done = read.load(std::memory_order_relaxed);
        const double whole = 2.0 * static_cast<double>(total_bytes);
        return ProgressSample{whole > 0 ? static_cast<double>(done) / whole : 0.0, done};
      });
  const api::StreamedMerge merged = api::MergeShardStreams(
      files,
      [&files](std::size_t k) -> std::unique_ptr<std::istream> {
        auto in = std::make_unique<std::ifstream>(files[k], std::ios::binary);
        if (!*in) return nullptr;
        return in;
      },
      [](std::string_view bytes) {
        std::cout.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        return static_cast<bool>(std::cout);
      },
      [&read](std::uint64_t bytes) { read.store(bytes, std::memory_order_relaxed); });
  std::cout.flush();
  if (merged.ok()) read.store(2 * total_bytes, std::memory_order_relaxed);
  reporter.Finish();
  if (merged.ok()) return std::cout ? 0 : 1;
  std::cerr << "sweetspot explore-merge: " << merged.error << "\n";
  return merged.status == api::MergeStatus::kRefused ? 2 : 1;
}

}  // namespace sweetspot::server
