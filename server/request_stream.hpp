// The cpp-httplib Stream a worker hands to httplib for one request: reads come
// from the request bytes already received (the whole head and body, so a
// handler never waits on a slow client). An answer is collected whole and the
// worker sends what the socket takes at once (TakeAnswer); the rest is sent as
// the client reads, without a worker. A streamed answer (NDJSON) goes out as it
// is produced, each write waiting at most the write timeout.
#pragma once

#include <httplib.h>

#include <chrono>
#include <string>
#include <string_view>

namespace sweetspot::server {

/// One request's bytes in, the answer out. Not thread-safe (one worker uses it).
class RequestStream : public httplib::Stream {
 public:
  /// `request` (head and body, kept alive by the caller) is what reads return;
  /// writes go to the non-blocking socket `fd`, each waiting at most
  /// `write_timeout_s` for the socket to take more. The addresses are the peer's
  /// and ours, as the loop read them when it accepted the connection.
  RequestStream(int fd, std::string_view request, double write_timeout_s,
                const std::string& remote_ip, int remote_port, const std::string& local_ip,
                int local_port);
  ~RequestStream() override;
  RequestStream(const RequestStream&) = delete;
  RequestStream& operator=(const RequestStream&) = delete;

  bool is_readable() const override;
  bool is_writable() const override;
  ssize_t read(char* ptr, size_t size) override;
  ssize_t write(const char* ptr, size_t size) override;
  void get_remote_ip_and_port(std::string& ip, int& port) const override;
  void get_local_ip_and_port(std::string& ip, int& port) const override;
  /// The socket. httplib answers 500 for descriptors >= FD_SETSIZE because its
  /// own stream uses select(); this one uses poll(), so such descriptors report 0.
  socket_t socket() const override;

  /// Sends what is buffered, waiting up to the write timeout; false when the
  /// socket failed or the deadline passed.
  bool Flush();
  /// Sends what the socket takes now of the collected answer, without waiting,
  /// and moves the rest to *unsent. False when the socket failed.
  bool SendWithoutWaiting(std::string* unsent);
  /// From now on every write goes out at once (a streamed answer's chunks).
  void WriteThrough();
  /// False once a write failed: the connection must be closed.
  bool healthy() const { return healthy_; }

  /// The stream of the request the calling thread is handling, or null: lets
  /// the handler that starts a streamed answer call WriteThrough().
  static RequestStream* Current();

 private:
  bool Send(const char* data, std::size_t size);

  int fd_;
  std::string_view request_;
  std::size_t read_at_ = 0;
  std::chrono::duration<double> write_timeout_;
  const std::string& remote_ip_;
  int remote_port_;
  const std::string& local_ip_;
  int local_port_;
  std::string out_;
  bool write_through_ = false;
  bool healthy_ = true;
  RequestStream* previous_current_;
};

}  // namespace sweetspot::server
