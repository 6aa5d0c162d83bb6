// The reason phrases the direct answer path writes (http::StatusText) are httplib 0.11.4's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "server/server_http.hpp"

namespace sweetspot::server::http {
namespace {

// A request's bytes in, the answer's bytes out, in memory.
class MemoryStream : public httplib::Stream {
 public:
  explicit MemoryStream(std::string in) : in_(std::move(in)) {}
  bool is_readable() const override { return at_ < in_.size(); }
  bool is_writable() const override { return true; }
  ssize_t read(char* ptr, size_t size) override {
    const std::size_t n = std::min(size, in_.size() - at_);
    std::memcpy(ptr, in_.data() + at_, n);
    at_ += n;
    return static_cast<ssize_t>(n);
  }
  ssize_t write(const char* ptr, size_t size) override {
    out.append(ptr, size);
    return static_cast<ssize_t>(size);
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 1;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 2;
  }
  socket_t socket() const override { return 0; }
  std::string out;

 private:
  std::string in_;
  std::size_t at_ = 0;
};

TEST(StatusTextTest, EveryKnownStatusLineIsHttplibs) {
  HttpServer server;
  server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    res.status = std::stoi(req.path.substr(1));
    res.set_content("x", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  int known = 0;
  for (int status = 100; status < 600; ++status) {
    const char* text = StatusText(status);
    if (text == nullptr) continue;
    ++known;
    MemoryStream stream("GET /" + std::to_string(status) + " HTTP/1.1\r\nHost: x\r\n\r\n");
    bool closed = false;
    server.ServeOne(stream, false, &closed);
    const std::string line = stream.out.substr(0, stream.out.find("\r\n"));
    EXPECT_EQ(line, "HTTP/1.1 " + std::to_string(status) + " " + text);
  }
  EXPECT_GE(known, 20);
}

}  // namespace
}  // namespace sweetspot::server::http
