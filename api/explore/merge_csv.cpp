// The streamed merge of CSV shards (api/explore/merge_stream.hpp). A CSV body is rows only
// (docs/api.md: the summary is not in the CSV), so a shard says which shard it is by its
// rows' indices: shard s of N holds s, s + N, s + 2N, ...; N is that step.
#include <algorithm>
#include <string>
#include <vector>

#include "api/explore/merge_reader.hpp"

namespace sweetspot::api::merge_detail {
namespace {

// One CSV shard as its first reading found it.
struct CsvScan {
  std::string name;
  std::string header;
  IndexRun run;
};

// The first reading of a CSV shard: the header, every record's field count and index.
std::string ScanCsv(RecordReader* reader, CsvScan* scan) {
  const std::string who = scan->name + ": ";
  bool cut = false;
  if (!reader->CsvRecord(&scan->header, &cut) || cut) {
    return who + "has no header line: the shard did not finish, or it is not the CSV output "
                 "of /v1/explore";
  }
  const std::vector<std::string> columns = SplitCsv(scan->header);
  const auto at = std::find(columns.begin(), columns.end(), "index");
  if (at == columns.end()) {
    return who + "its header has no index column, so its rows cannot be merged: run the "
                 "shards with \"index\" among the columns";
  }
  const std::size_t index_column = static_cast<std::size_t>(at - columns.begin());
  std::string record;
  while (reader->CsvRecord(&record, &cut)) {
    const std::string line = who + "line " + std::to_string(reader->line_number());
    if (cut) return line + " is cut short (no line end): the shard did not finish";
    const std::vector<std::string> fields = SplitCsv(record);
    if (fields.size() != columns.size()) {
      return line + " has " + std::to_string(fields.size()) + " fields, the header " +
             std::to_string(columns.size());
    }
    std::uint64_t index = 0;
    if (!ParseUnsigned(fields[index_column], &index)) {
      return line + ": index \"" + fields[index_column] + "\" is not a design index";
    }
    if (std::string why = scan->run.Take(index); !why.empty()) return line + ": " + why;
  }
  return "";
}

// The shard count: the step of every shard with two rows or more (or, when none has, the
// number of shards given).
std::string ShardCount(const std::vector<CsvScan>& scans, std::uint64_t* count) {
  const CsvScan* stepped = nullptr;
  for (const CsvScan& scan : scans) {
    if (scan.run.rows < 2) continue;
    if (stepped == nullptr) {
      stepped = &scan;
    } else if (scan.run.step != stepped->run.step) {
      return scan.name + ": its rows step by " + std::to_string(scan.run.step) + ", " +
             stepped->name + "'s by " + std::to_string(stepped->run.step) +
             ": shards of sweeps split in different counts";
    }
  }
  *count = stepped != nullptr ? stepped->run.step : scans.size();
  if (*count > (1u << 24)) return "more than 2^24 shards cannot be merged";
  return "";
}

// Which file is which shard, checked; `shard_file[s]` names shard s's file.
std::string PlanCsv(const std::vector<CsvScan>& scans, std::vector<std::size_t>* shard_file,
                    std::uint64_t* total) {
  std::uint64_t count = 0;
  if (std::string why = ShardCount(scans, &count); !why.empty()) return why;
  const std::size_t unset = SIZE_MAX;
  shard_file->assign(count, unset);
  std::vector<std::size_t> empty;  // shards with no rows: the last ones of a small sweep
  *total = 0;
  for (std::size_t f = 0; f < scans.size(); ++f) {
    const CsvScan& scan = scans[f];
    if (scan.header != scans[0].header) {
      return scan.name + ": its header differs from " + scans[0].name +
             "'s: the shards of one sweep have the same columns";
    }
    *total += scan.run.rows;
    if (scan.run.rows == 0) {
      empty.push_back(f);
      continue;
    }
    const std::uint64_t s = scan.run.first;
    if (s >= count) {
      return scan.name + ": its first row is design " + std::to_string(s) +
             ", not one of the first " + std::to_string(count) + " (shard s of " +
             std::to_string(count) + " starts with design s)";
    }
    if ((*shard_file)[s] != unset) {
      return scan.name + ": repeats shard " + std::to_string(s) + " of " + std::to_string(count) +
             " (" + scans[(*shard_file)[s]].name + " is shard " + std::to_string(s) + " too)";
    }
    (*shard_file)[s] = f;
  }
  for (std::uint64_t s = count; s-- > 0 && !empty.empty();) {
    if ((*shard_file)[s] != unset) continue;
    (*shard_file)[s] = empty.back();
    empty.pop_back();
  }
  if (!empty.empty()) {
    return scans[empty.back()].name + ": one shard too many (" + std::to_string(scans.size()) +
           " given for " + std::to_string(count) + " shards)";
  }
  std::vector<std::uint64_t> missing;
  for (std::uint64_t s = 0; s < count; ++s) {
    if ((*shard_file)[s] == unset) missing.push_back(s);
  }
  if (!missing.empty()) {
    return "the shards are incomplete: " + MissingShardsMessage(missing, count) + " (" +
           std::to_string(scans.size()) + " of " + std::to_string(count) + " given)";
  }
  // Shard s of N holds ceil((total - s) / N) rows: as many as shard 0 or one fewer, never
  // more than shard s - 1. (Without a summary, a shard 0 that lost exactly its last row
  // cannot be told from a sweep one design shorter.)
  const CsvScan& first = scans[(*shard_file)[0]];
  for (std::uint64_t s = 1; s < count; ++s) {
    const CsvScan& scan = scans[(*shard_file)[s]];
    const std::uint64_t rows = scan.run.rows, most = first.run.rows;
    if (rows > scans[(*shard_file)[s - 1]].run.rows || rows + 1 < most) {
      return scan.name + ": has " + std::to_string(rows) + " rows and " + first.name +
             " (shard 0) has " + std::to_string(most) + ": shard " + std::to_string(s) + " of " +
             std::to_string(count) + " has as many or one fewer, and no more than shard " +
             std::to_string(s - 1) + " (a shard cut short?)";
    }
  }
  return "";
}

// The second reading: the header once, then the rows of the shards in index order.
StreamedMerge WriteCsv(const std::vector<std::string>& names, const ShardOpener& open,
                       const std::vector<std::size_t>& shard_file, std::uint64_t total,
                       RecordReader::Context context, const MergeSink& sink,
                       const MergeStreamOptions& options, StreamedMerge* out) {
  const std::size_t count = shard_file.size();
  std::vector<std::unique_ptr<std::istream>> streams(count);
  std::vector<RecordReader> readers;
  readers.reserve(count);
  OutputBuffer output(&sink, options.sink_chunk_bytes);
  std::string record;
  bool cut = false;
  for (std::size_t s = 0; s < count; ++s) {
    streams[s] = open(shard_file[s]);
    if (!streams[s]) return Stop(out, MergeStatus::kUnreadable, "cannot read " + names[shard_file[s]]);
    readers.emplace_back(streams[s].get(), context);
    if (!readers[s].CsvRecord(&record, &cut)) {
      return Stop(out, MergeStatus::kRefused, names[shard_file[s]] + ": changed while it was merged");
    }
    if (s == 0 && !output.Line(record)) return Stop(out, MergeStatus::kOutputFailed, "the output failed");
  }
  for (std::uint64_t i = 0; i < total; ++i) {
    RecordReader& reader = readers[i % count];
    if (!reader.CsvRecord(&record, &cut) || cut) {
      return Stop(out, MergeStatus::kRefused,
                  names[shard_file[i % count]] + ": changed while it was merged (it ends early)");
    }
    if (!output.Line(record)) return Stop(out, MergeStatus::kOutputFailed, "the output failed");
    ++out->rows;
  }
  if (!output.Flush()) return Stop(out, MergeStatus::kOutputFailed, "the output failed");
  out->status = MergeStatus::kMerged;
  return *out;
}

}  // namespace

StreamedMerge MergeCsvShards(const std::vector<std::string>& names, const ShardOpener& open,
                             const MergeSink& sink, RecordReader::Context context,
                             const MergeStreamOptions& options) {
  StreamedMerge out;
  out.format = "csv";
  std::vector<CsvScan> scans(names.size());
  for (std::size_t f = 0; f < names.size(); ++f) {
    scans[f].name = names[f];
    const std::unique_ptr<std::istream> in = open(f);
    if (!in) return Stop(&out, MergeStatus::kUnreadable, "cannot read " + names[f]);
    RecordReader reader(in.get(), context);
    std::string why = ScanCsv(&reader, &scans[f]);
    if (reader.failed()) return Stop(&out, MergeStatus::kUnreadable, "cannot read " + names[f]);
    if (!why.empty()) return Stop(&out, MergeStatus::kRefused, std::move(why));
  }
  std::vector<std::size_t> shard_file;
  std::uint64_t total = 0;
  if (std::string why = PlanCsv(scans, &shard_file, &total); !why.empty()) {
    return Stop(&out, MergeStatus::kRefused, std::move(why));
  }
  out.shards = shard_file.size();
  return WriteCsv(names, open, shard_file, total, context, sink, options, &out);
}

}  // namespace sweetspot::api::merge_detail
