// The shards of a /v1/explore sweep merged as streams, in memory that does not grow with the
// sweep: a k-way merge by design index (design i is the next row of shard i mod N), each
// shard read twice from its beginning: once to check it (every line, the summary, the rows'
// indices), once to copy its rows, byte for byte, into the merged output. What is kept is a
// few numbers per shard and the shards' Pareto fronts (the whole sweep's front is the front
// of their union: a row dominated in its shard is dominated in the sweep, and a row on the
// sweep's front is on its shard's). NDJSON shards give the sweep's NDJSON (rows, then its
// summary); CSV shards (`explore --shard` of a csv request) give the sweep's CSV (the
// header once, then the rows). Nothing is written unless every check passes.
#pragma once

#include <cstdint>
#include <functional>
#include <istream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace sweetspot::api {

/// Opens shard `k` (an index into the names given) from its beginning: a fresh stream at
/// each call (the merge reads every shard twice), or nullptr when it cannot be read.
using ShardOpener = std::function<std::unique_ptr<std::istream>(std::size_t k)>;

/// Takes the next bytes of the merged output; false stops the merge (the output failed).
using MergeSink = std::function<bool(std::string_view)>;

/// Told how many bytes of the shards have been read so far, over both readings (so the
/// whole merge reads twice the shards' total size). May be empty.
using MergeProgress = std::function<void(std::uint64_t bytes_read)>;

/// Settings of a streamed merge.
struct MergeStreamOptions {
  /// Bytes of merged output gathered before they are handed to the sink (default 1 MiB):
  /// fewer, larger writes. At least 1.
  std::size_t sink_chunk_bytes = 1u << 20;
  /// Bytes read between two calls of the progress callback (default 4 MiB). At least 1.
  std::uint64_t progress_every_bytes = 4u << 20;
};

/// Why a streamed merge stopped.
enum class MergeStatus {
  kMerged,      ///< Every check passed and the whole sweep was written.
  kUnreadable,  ///< A shard could not be opened or read (the CLI's exit 1).
  kRefused,     ///< The shards do not make one complete sweep (exit 2); nothing was written,
                ///< unless a shard changed between the two readings.
  kOutputFailed ///< The sink refused bytes (exit 1).
};

/// What MergeShardStreams gives.
struct StreamedMerge {
  MergeStatus status = MergeStatus::kRefused;
  std::string error;        ///< Why it stopped: which shard, what, and the rule.
  std::string format;       ///< "ndjson" or "csv" (what the shards are), once known.
  std::uint64_t rows = 0;   ///< Rows written.
  std::uint64_t shards = 0; ///< The sweep's shard count, once known.
  bool ok() const { return status == MergeStatus::kMerged; }
};

/// Merges the shards named `names` (labels for messages; shard k is opened by `open(k)`),
/// writing the merged sweep to `sink`. The checks of MergeExploreShards
/// (api/explore/shards.hpp) for NDJSON shards (same provenance, count, designs, sampling,
/// seed, objectives and report_units; every shard once; every row once and in its shard;
/// no error line, a summary line last). CSV shards carry no summary: they must have the same
/// header, with an `index` column, each shard's rows the indices s, s + N, s + 2N, … (N is
/// found from that step), every shard once and each shard's row count the one N shards of
/// the total give. Missing shards are named ("shards 1 and 3 of 4 missing"; 0-based, as
/// `--shard I/N`). The merged NDJSON summary is the unsharded sweep's but for timing_s (the
/// shards' sum: a measurement, not a property of the sweep). Never throws.
StreamedMerge MergeShardStreams(const std::vector<std::string>& names, const ShardOpener& open,
                                const MergeSink& sink, const MergeProgress& progress = {},
                                const MergeStreamOptions& options = {});

/// "shard 2 of 4 missing", "shards 1 and 3 of 4 missing", "shards 0, 1 and 3 of 4
/// missing" (the first 20, then "and K more"): `missing` in increasing order, not empty.
std::string MissingShardsMessage(const std::vector<std::uint64_t>& missing, std::uint64_t count);

}  // namespace sweetspot::api
