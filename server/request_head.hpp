// The little the connection loop must know of an HTTP/1.1 request head before a
// worker sees the request: where the head ends, how long the body is, and
// whether the client waits for "100 Continue". cpp-httplib parses the request
// for real on the worker; this scan only frames it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sweetspot::server {

/// What ScanRequestHead found.
enum class HeadScan {
  kIncomplete,  ///< No blank line yet, and the bytes are within the head limit.
  kComplete,    ///< The head ends within the bytes: see RequestHead.
  kTooLarge,    ///< No blank line within max_head_bytes: answer 431 and close.
  kBareLineFeed,     ///< A line ends in LF without CR: answer 400 and close (one framing only).
  kLineTooLong,      ///< A header line over kMaxHeaderLineBytes: answer 431 and close.
  kTargetTooLong,    ///< The request line over kMaxRequestLineBytes: answer 414 and close.
};

/// Longest request line (method, target, version), bytes, its CRLF included: httplib's
/// CPPHTTPLIB_REQUEST_URI_MAX_LENGTH, so that the loop refuses what httplib would.
inline constexpr std::size_t kMaxRequestLineBytes = 8192;
/// Longest header line, bytes, its CRLF included: httplib's CPPHTTPLIB_HEADER_MAX_LENGTH
/// (httplib itself answers a longer one with a bare 400).
inline constexpr std::size_t kMaxHeaderLineBytes = 8192;

/// The framing of one request head.
struct RequestHead {
  std::size_t head_bytes = 0;          ///< Bytes of the head, the closing blank line included.
  std::string method;                  ///< From the request line, e.g. "POST" ("" if malformed).
  std::string path;                    ///< The target without its query, e.g. "/v1/sweet-spot".
  std::uint64_t content_length = 0;    ///< Body bytes (0 without a Content-Length header).
  bool has_transfer_encoding = false;  ///< A Transfer-Encoding header: the body cannot be framed.
  bool bad_content_length = false;     ///< Content-Length not a decimal number, or two that differ.
  bool expects_continue = false;       ///< "Expect: 100-continue" (case-insensitive).
  std::size_t expect_line_begin = 0;   ///< Byte range of the Expect line, CRLF included,
  std::size_t expect_line_end = 0;     ///< so that the loop can answer it and drop it.
  /// Byte ranges [begin, end) of the Range header lines, CRLF included: the loop drops them,
  /// so every answer is whole (200), never a multi-range body built in memory.
  std::vector<std::pair<std::size_t, std::size_t>> range_lines;
};

/// `text` with every %XX escape decoded, as httplib decodes a request's path ('+' kept):
/// the path the router sees. An incomplete or non-hex escape is kept as it is.
std::string PercentDecoded(std::string_view text);

/// Scans `bytes` (what arrived of a connection, starting at a request) for a
/// complete head. `*scanned` is where the previous scan of the same request
/// stopped (0 at first; updated), so a head that trickles in is searched once.
/// On kComplete fills `*head`. Never throws.
HeadScan ScanRequestHead(std::string_view bytes, std::size_t max_head_bytes, std::size_t* scanned,
                         RequestHead* head);

}  // namespace sweetspot::server
