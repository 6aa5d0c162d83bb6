// The lean path's header handling against httplib's own: what ParseFramedHead notes of a
// request's headers (FramedHeaders) is what httplib's lookups in the parsed request give, and
// UsualAnswerHead (ResponseHead with headers added) writes the head that set_header then
// ResponseHead writes.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "server/server_http.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace framed_head_test {
namespace {

using http::FramedHeaders;
using http::ParseFramedHead;
using http::ResponseHead;
using http::UsualAnswerHead;

TEST(FramedHeadTest, NotedHeadersAreHttplibsLookups) {
  const std::vector<std::string> heads = {
      "POST /v1/sweet-spot HTTP/1.1\r\nHost: a\r\nContent-Type: application/json\r\n"
      "Content-Length: 2\r\n\r\n",
      // Names in any case, a header given twice (the first value is the one looked up).
      "POST /v1/x HTTP/1.1\r\ncontent-type: multipart/form-data; b=1\r\nCONTENT-TYPE: "
      "text/plain\r\n"
      "connection: close\r\nConnection: keep-alive\r\naccept-ENCODING: gzip\r\n\r\n",
      "GET /health HTTP/1.0\r\nConnection: Keep-Alive\r\nContent-Encoding: br\r\n"
      "Transfer-encoding: chunked\r\n\r\n",
      "GET /health HTTP/1.1\r\nAccept-Encodings: x\r\nConnectio: close\r\n\r\n",  // near misses
      "POST /v1/x HTTP/1.1\r\nContent-Type: application/x-www-form-urlencoded\r\n\r\n",
  };
  for (const std::string& head : heads) {
    httplib::Request req;
    FramedHeaders noted;
    ASSERT_TRUE(ParseFramedHead(head, &req, &noted)) << head;
    EXPECT_EQ(noted.accept_encoding, req.has_header("Accept-Encoding")) << head;
    EXPECT_EQ(noted.content_encoding, req.has_header("Content-Encoding")) << head;
    EXPECT_EQ(noted.transfer_encoding, req.has_header("Transfer-Encoding")) << head;
    EXPECT_EQ(noted.connection, req.get_header_value("Connection")) << head;
    EXPECT_EQ(noted.content_type, req.get_header_value("Content-Type")) << head;
    // The path a request takes is the same with the noted headers as with the lookups.
    EXPECT_EQ(noted.content_type.rfind("multipart/form-data", 0) == 0, req.is_multipart_form_data())
        << head;
  }
}

TEST(FramedHeadTest, AddedHeadersAreWrittenWhereSetHeaderPutsThem) {
  // Answers as the handlers leave them: a type, a retry hint, CORS, a header named in
  // lower case, one named like an added one.
  std::vector<httplib::Response> answers(5);
  answers[0].set_header("Content-Type", "application/json");
  answers[1].set_header("Content-Type", "application/json");
  answers[1].set_header("Retry-After", "1");
  answers[2].set_header("Access-Control-Allow-Origin", "*");
  answers[2].set_header("Vary", "Origin");
  answers[2].set_header("Content-Type", "text/csv");
  answers[3].set_header("content-type", "application/x-ndjson");
  answers[3].set_header("keep-alive", "x");
  answers[4].set_header("Content-Length", "9");
  answers[4].set_header("Connection", "upgrade");
  answers[4].set_header("X-Accel-Buffering", "no");
  for (std::size_t i = 0; i < answers.size(); ++i) {
    answers[i].status = 200;
    answers[i].body = std::string(1800, 'x');
    for (const bool keep_alive : {true, false}) {
      httplib::Response expected = answers[i];  // as ServeDirect did before: set_header
      expected.set_header("Content-Length", "1800");
      if (keep_alive) {
        expected.set_header("Keep-Alive", "timeout=5, max=100");
      } else {
        expected.set_header("Connection", "close");
      }
      EXPECT_EQ(UsualAnswerHead(answers[i], "OK", keep_alive, "timeout=5, max=100"),
                ResponseHead(expected, "OK"))
          << i << " keep-alive " << keep_alive;
    }
  }
  // A spot check of the order: httplib's, names compared without case.
  EXPECT_EQ(ResponseHead(answers[1], "OK", {{"Content-Length", "2"}, {"Keep-Alive", "k"}}),
            "HTTP/1.1 200 OK\r\nContent-Length: 2\r\nContent-Type: application/json\r\n"
            "Keep-Alive: k\r\nRetry-After: 1\r\n\r\n");
}

}  // namespace
}  // namespace framed_head_test
}  // namespace sweetspot::server
