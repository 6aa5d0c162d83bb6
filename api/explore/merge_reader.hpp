// What the streamed merge's NDJSON and CSV halves share (api/explore/merge_stream.cpp,
// merge_csv.cpp): a record reader that counts the bytes read for progress, and the output
// gathered into chunks for the sink. Internal to the merge.
#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include "api/explore/merge_stream.hpp"

namespace sweetspot::api::merge_detail {

/// Reads a shard line by line (or CSV record by record), counting the bytes read and
/// calling the progress callback every `every` bytes of the merge's whole reading.
class RecordReader {
 public:
  /// What every reader of one merge shares: the bytes read so far, the callback, its step.
  struct Context {
    std::uint64_t* total_read;
    const MergeProgress* progress;
    std::uint64_t every;
  };
  RecordReader(std::istream* in, Context context)
      : in_(in),
        total_read_(context.total_read),
        progress_(context.progress),
        every_(context.every) {}

  /// The next line without its '\n': false at the end. `*cut` is true when the last line
  /// had no '\n' (a file cut short).
  bool Line(std::string* line, bool* cut);

  /// The next CSV record (lines joined while a quoted field is open): false at the end.
  /// `*cut` as Line's, or true when the file ends inside a quoted field.
  bool CsvRecord(std::string* record, bool* cut);

  /// 1-based number of the last line read.
  std::uint64_t line_number() const { return line_number_; }
  /// Whether the stream failed for a reason other than its end (an I/O error).
  bool failed() const { return in_->bad(); }

 private:
  void Count(std::size_t bytes);
  std::istream* in_;
  std::uint64_t* total_read_;
  const MergeProgress* progress_;
  std::uint64_t every_;
  std::uint64_t line_number_ = 0;
};

/// The merged output, handed to the sink in chunks of about `chunk` bytes.
class OutputBuffer {
 public:
  OutputBuffer(const MergeSink* sink, std::size_t chunk) : sink_(sink), chunk_(chunk) {
    text_.reserve(chunk + 4096);
  }
  /// Appends `bytes` and a '\n'; false when the sink refused a chunk.
  bool Line(std::string_view bytes);
  /// Hands over what is left; false when the sink refused it.
  bool Flush();

 private:
  const MergeSink* sink_;
  std::size_t chunk_;
  std::string text_;
  bool ok_ = true;
};

/// A shard's row indices as they are read: first, first + step, first + 2 step, ...
struct IndexRun {
  std::uint64_t rows = 0;
  std::uint64_t first = 0, last = 0, step = 0;
  /// Takes the next row's index: "" or why it does not follow the rows before it.
  std::string Take(std::uint64_t i);
};

/// The fields of a CSV record (RFC 4180: quoted fields, doubled quotes), unquoted.
std::vector<std::string> SplitCsv(std::string_view record);

/// A decimal unsigned integer, all of `text`: false otherwise (or past 2^64 - 1).
bool ParseUnsigned(std::string_view text, std::uint64_t* value);

/// Merges CSV shards (merge_csv.cpp): MergeShardStreams for shards whose first byte is not
/// '{'.
StreamedMerge MergeCsvShards(const std::vector<std::string>& names, const ShardOpener& open,
                             const MergeSink& sink, RecordReader::Context context,
                             const MergeStreamOptions& options);

/// Sets `out`'s status and error and returns a copy of it.
StreamedMerge Stop(StreamedMerge* out, MergeStatus status, std::string why);

}  // namespace sweetspot::api::merge_detail
