// ScanRequestHead: the framing the connection loop does before a worker sees a request.
#include "server/request_head.hpp"

#include <gtest/gtest.h>

#include <string>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace request_head_test {
namespace {

TEST(RequestHeadTest, FramesAPostWithItsContentLength) {
  const std::string bytes =
      "POST /v1/sweet-spot?x=1 HTTP/1.1\r\nHost: a\r\ncontent-length:  12 \r\n\r\n{\"bat\": {}}";
  std::size_t scanned = 0;
  RequestHead head;
  ASSERT_EQ(ScanRequestHead(bytes, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_EQ(head.method, "POST");
  EXPECT_EQ(head.path, "/v1/sweet-spot");
  EXPECT_EQ(head.content_length, 12u);
  EXPECT_EQ(head.head_bytes, bytes.find("{"));
  EXPECT_FALSE(head.has_transfer_encoding);
  EXPECT_FALSE(head.bad_content_length);
  EXPECT_FALSE(head.expects_continue);
}

TEST(RequestHeadTest, AHeadArrivingByteByByteIsFoundOnceComplete) {
  const std::string bytes = "GET /health HTTP/1.1\r\nHost: a\r\n\r\n";
  std::size_t scanned = 0;
  RequestHead head;
  for (std::size_t n = 1; n < bytes.size(); ++n) {
    ASSERT_EQ(ScanRequestHead(std::string_view(bytes).substr(0, n), 65536, &scanned, &head),
              HeadScan::kIncomplete)
        << n;
    EXPECT_EQ(scanned, n);
  }
  ASSERT_EQ(ScanRequestHead(bytes, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_EQ(head.head_bytes, bytes.size());
  EXPECT_EQ(head.content_length, 0u);
}

TEST(RequestHeadTest, OverTheLimitWithoutABlankLineIsTooLarge) {
  const std::string bytes = "GET / HTTP/1.1\r\nX: " + std::string(300, 'a');
  std::size_t scanned = 0;
  RequestHead head;
  EXPECT_EQ(ScanRequestHead(bytes, 256, &scanned, &head), HeadScan::kTooLarge);
  // A complete head longer than the limit is too large as well.
  const std::string whole = bytes + "\r\n\r\n";
  scanned = 0;
  EXPECT_EQ(ScanRequestHead(whole, 256, &scanned, &head), HeadScan::kTooLarge);
}

TEST(RequestHeadTest, BadOrConflictingContentLengthsAreFlagged) {
  for (const char* value : {"-1", "12a", "", "0x10", "1234567890123456789"}) {
    const std::string bytes =
        std::string("POST / HTTP/1.1\r\nContent-Length: ") + value + "\r\n\r\n";
    std::size_t scanned = 0;
    RequestHead head;
    ASSERT_EQ(ScanRequestHead(bytes, 65536, &scanned, &head), HeadScan::kComplete);
    EXPECT_TRUE(head.bad_content_length) << value;
  }
  const std::string twice = "POST / HTTP/1.1\r\nContent-Length: 5\r\nContent-Length: 6\r\n\r\n";
  std::size_t scanned = 0;
  RequestHead head;
  ASSERT_EQ(ScanRequestHead(twice, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_TRUE(head.bad_content_length);
  const std::string same = "POST / HTTP/1.1\r\nContent-Length: 5\r\nContent-Length: 5\r\n\r\n";
  scanned = 0;
  ASSERT_EQ(ScanRequestHead(same, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_FALSE(head.bad_content_length);
  EXPECT_EQ(head.content_length, 5u);
}

TEST(RequestHeadTest, TransferEncodingAndExpectContinueAreSeen) {
  const std::string bytes =
      "POST /v1/explore HTTP/1.1\r\nTransfer-Encoding: chunked\r\nEXPECT: 100-Continue\r\n\r\n";
  std::size_t scanned = 0;
  RequestHead head;
  ASSERT_EQ(ScanRequestHead(bytes, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_TRUE(head.has_transfer_encoding);
  ASSERT_TRUE(head.expects_continue);
  EXPECT_EQ(bytes.substr(head.expect_line_begin, head.expect_line_end - head.expect_line_begin),
            "EXPECT: 100-Continue\r\n");
}

TEST(RequestHeadTest, GarbageIsFramedAndLeftToHttplibToRefuse) {
  const std::string bytes = "\x16\x03\x01 not http\r\n\r\n";
  std::size_t scanned = 0;
  RequestHead head;
  ASSERT_EQ(ScanRequestHead(bytes, 65536, &scanned, &head), HeadScan::kComplete);
  EXPECT_EQ(head.content_length, 0u);
  EXPECT_EQ(head.head_bytes, bytes.size());
}

}  // namespace
}  // namespace request_head_test
}  // namespace sweetspot::server
