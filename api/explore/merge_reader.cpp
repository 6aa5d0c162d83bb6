#include "api/explore/merge_reader.hpp"

#include <algorithm>

namespace sweetspot::api::merge_detail {

void RecordReader::Count(std::size_t bytes) {
  const std::uint64_t before = *total_read_;
  *total_read_ += bytes;
  if (progress_ != nullptr && *progress_ && before / every_ != *total_read_ / every_) {
    (*progress_)(*total_read_);
  }
}

bool RecordReader::Line(std::string* line, bool* cut) {
  *cut = false;
  if (!std::getline(*in_, *line)) return false;
  ++line_number_;
  // getline stops at the end without a '\n' only on the file's last line: eof is then set.
  *cut = in_->eof();
  Count(line->size() + (*cut ? 0 : 1));
  return true;
}

bool RecordReader::CsvRecord(std::string* record, bool* cut) {
  if (!Line(record, cut)) return false;
  // A quoted field's quotes come in pairs (its own doubled), so an odd count means a field
  // is still open and the record goes on after the line end.
  std::size_t quotes = static_cast<std::size_t>(std::count(record->begin(), record->end(), '"'));
  std::string more;
  while (quotes % 2 == 1 && !*cut) {
    if (!Line(&more, cut)) {
      *cut = true;
      return true;
    }
    record->push_back('\n');
    record->append(more);
    quotes += static_cast<std::size_t>(std::count(more.begin(), more.end(), '"'));
  }
  if (quotes % 2 == 1) *cut = true;
  return true;
}

bool OutputBuffer::Line(std::string_view bytes) {
  text_.append(bytes.data(), bytes.size());
  text_.push_back('\n');
  if (text_.size() >= chunk_) return Flush();
  return ok_;
}

bool OutputBuffer::Flush() {
  if (ok_ && !text_.empty()) ok_ = (*sink_)(text_);
  text_.clear();
  return ok_;
}

std::string IndexRun::Take(std::uint64_t i) {
  if (rows == 0) {
    first = i;
  } else if (i <= last) {
    const bool seen = rows == 1 ? i == first : i >= first && (i - first) % step == 0;
    return seen ? "repeats row index " + std::to_string(i)
                : "row index " + std::to_string(i) + " comes after " + std::to_string(last) +
                      ": the rows are not in index order";
  } else if (rows == 1) {
    step = i - first;
  } else if (i - last != step) {
    return "row index " + std::to_string(i) + " follows " + std::to_string(last) +
           ", but the shard's rows step by " + std::to_string(step) +
           ": a row is missing or does not belong to the shard";
  }
  last = i;
  ++rows;
  return "";
}

std::vector<std::string> SplitCsv(std::string_view record) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < record.size(); ++i) {
    const char c = record[i];
    if (quoted) {
      if (c == '"' && i + 1 < record.size() && record[i + 1] == '"') {
        fields.back().push_back('"');
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back().push_back(c);
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back().push_back(c);
    }
  }
  return fields;
}

bool ParseUnsigned(std::string_view text, std::uint64_t* value) {
  if (text.empty() || text.size() > 20) return false;
  std::uint64_t v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (v > (UINT64_MAX - digit) / 10) return false;
    v = v * 10 + digit;
  }
  *value = v;
  return true;
}

}  // namespace sweetspot::api::merge_detail
