#include "server/request_head.hpp"

#include <algorithm>

namespace sweetspot::server {
namespace {

// ASCII case folding (header names and these values are ASCII; no locale lookup).
char Lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(),
                                            [](char x, char y) { return Lower(x) == Lower(y); });
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

// A Content-Length value: 1 to 18 decimal digits (a larger body is over any limit anyway).
bool ParseLength(std::string_view text, std::uint64_t* out) {
  if (text.empty() || text.size() > 18) return false;
  std::uint64_t value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<std::uint64_t>(c - '0');
  }
  *out = value;
  return true;
}

// True when a byte of bytes[begin, end) is an LF without the CR before it.
bool HasBareLineFeed(std::string_view bytes, std::size_t begin, std::size_t end) {
  for (std::size_t at = bytes.find('\n', begin); at < end; at = bytes.find('\n', at + 1)) {
    if (at == 0 || bytes[at - 1] != '\r') return true;
  }
  return false;
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string PercentDecoded(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size()) {
      const int hi = HexValue(text[i + 1]);
      const int lo = HexValue(text[i + 2]);
      if (hi >= 0 && lo >= 0) {
        out += static_cast<char>(hi * 16 + lo);
        i += 2;
        continue;
      }
    }
    out += text[i];
  }
  return out;
}

HeadScan ScanRequestHead(std::string_view bytes, std::size_t max_head_bytes, std::size_t* scanned,
                         RequestHead* head) {
  // Search from 3 bytes before where the last scan stopped: the blank line may straddle.
  const std::size_t from = *scanned > 3 ? *scanned - 3 : 0;
  const std::size_t end = bytes.find("\r\n\r\n", from);
  // An LF alone ends a line for some parsers and not for others (httplib skips such a line):
  // one framing only, so a head with one is refused, also before it is complete.
  if (HasBareLineFeed(bytes, *scanned, end == std::string_view::npos ? bytes.size() : end + 4)) {
    return HeadScan::kBareLineFeed;
  }
  if (end == std::string_view::npos) {
    *scanned = bytes.size();
    return bytes.size() > max_head_bytes ? HeadScan::kTooLarge : HeadScan::kIncomplete;
  }
  if (end + 4 > max_head_bytes) return HeadScan::kTooLarge;
  *head = RequestHead{};
  head->head_bytes = end + 4;
  const std::string_view text = bytes.substr(0, end + 2);  // every line ends with CRLF
  std::size_t line_begin = 0;
  bool first = true;
  bool has_length = false;
  while (line_begin < text.size()) {
    const std::size_t line_end = text.find("\r\n", line_begin);
    const std::string_view line = text.substr(line_begin, line_end - line_begin);
    if (first) {
      first = false;
      if (line.size() + 2 > kMaxRequestLineBytes) return HeadScan::kTargetTooLong;
      const std::size_t sp1 = line.find(' ');
      const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
      if (sp2 != std::string_view::npos) {
        head->method = std::string(line.substr(0, sp1));
        const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
        head->path = std::string(target.substr(0, target.find('?')));
      }
    } else if (line.size() + 2 > kMaxHeaderLineBytes) {
      return HeadScan::kLineTooLong;
    } else if (const std::size_t colon = line.find(':'); colon != std::string_view::npos) {
      const std::string_view name = line.substr(0, colon);
      const std::string_view value = Trim(line.substr(colon + 1));
      if (EqualsIgnoreCase(name, "Content-Length")) {
        std::uint64_t length = 0;
        if (!ParseLength(value, &length) || (has_length && length != head->content_length)) {
          head->bad_content_length = true;
        } else {
          head->content_length = length;
          has_length = true;
        }
      } else if (EqualsIgnoreCase(name, "Transfer-Encoding")) {
        head->has_transfer_encoding = true;
      } else if (EqualsIgnoreCase(name, "Expect") && EqualsIgnoreCase(value, "100-continue")) {
        head->expects_continue = true;
        head->expect_line_begin = line_begin;
        head->expect_line_end = line_end + 2;
      } else if (EqualsIgnoreCase(name, "Range")) {
        head->range_lines.emplace_back(line_begin, line_end + 2);
      }
    }
    line_begin = line_end + 2;
  }
  return HeadScan::kComplete;
}

}  // namespace sweetspot::server
