// The cpp-httplib Stream a worker hands to httplib for one request: reads come
// from the request bytes already received (the whole head and body, so a
// handler never waits on a slow client). An answer is collected whole and the
// worker sends what the socket takes at once (TakeAnswer); the rest is sent as
// the client reads, without a worker. A streamed answer (NDJSON) goes out as it
// is produced, each write waiting at most the write timeout.
#pragma once

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "api/response.hpp"
#include "core/progress.hpp"

namespace sweetspot::server {

/// Why the connection loop stopped a request that runs models.
enum class CancelReason : int {
  kNone = 0,    ///< Not stopped.
  kClientGone,  ///< The client closed its connection: nobody reads the answer.
  kDeadline,    ///< It computed for longer than max_request_time_s.
  kShutdown,    ///< The server is stopping.
};

/// The cancel flag of one request the compute pool answers: its handler polls `progress`
/// (api::Context::progress), the loop's deadline keeper sets it once, with the reason.
struct RequestCancel {
  core::Progress progress;         ///< What the models poll.
  std::atomic<int> reason{0};      ///< A CancelReason; the first one set wins.
  /// Stops the request for `why` (only the first call has an effect). Thread-safe.
  void Cancel(CancelReason why) {
    int none = static_cast<int>(CancelReason::kNone);
    if (reason.compare_exchange_strong(none, static_cast<int>(why))) progress.Cancel();
  }
  /// Why it was stopped (kNone while it runs).
  CancelReason Reason() const { return static_cast<CancelReason>(reason.load()); }
};

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
  /// The whole answer, written by the caller instead of httplib: its head, then its body
  /// (kept as it is, not copied: SendWithoutWaiting sends both in one writev).
  void SetAnswer(std::string head, std::string body);
  /// From now on every write goes out at once (a streamed answer's chunks).
  void WriteThrough();
  /// False once a write failed: the connection must be closed.
  bool healthy() const { return healthy_; }

  /// The answer's body from `offset` on is `source`'s, sent by the connection loop as the
  /// client takes it: the body's next write (of the rest's length) is counted, not copied.
  /// False (nothing deferred) for a streamed answer (WriteThrough).
  bool DeferBody(std::shared_ptr<const api::BodySource> source, std::uint64_t offset);
  /// The deferred body (null when none), and its byte range [*begin, *end) of the source.
  std::shared_ptr<const api::BodySource> TakeDeferred(std::uint64_t* begin, std::uint64_t* end);

  /// The request's bytes, head and body, as received.
  std::string_view request() const { return request_; }
  /// Records the loop's framing of the request: its head's bytes (the closing blank line
  /// included) and the Content-Length it declared (0 without one).
  void set_framing(std::size_t head_bytes, std::uint64_t content_length) {
    head_bytes_ = head_bytes;
    content_length_ = content_length;
    framed_ = true;
  }
  /// True once set_framing() was called (the loop always calls it before serving).
  bool framed() const { return framed_; }
  /// The request's body as received: what follows the head ("" when the loop did not read it:
  /// a Content-Length over max_body_bytes, or a Transfer-Encoding).
  std::string_view body() const {
    return head_bytes_ < request_.size() ? request_.substr(head_bytes_) : std::string_view();
  }
  /// The bytes of the request's head (the closing blank line included).
  std::size_t head_bytes() const { return head_bytes_; }
  /// The Content-Length the head declared (0 without one).
  std::uint64_t content_length() const { return content_length_; }
  /// The body as a JSON object, when the choice of pool already parsed it (else null): the
  /// handler takes it instead of parsing the body again (api::Request::parsed_body).
  const std::shared_ptr<nlohmann::json>& parsed_body() const { return parsed_body_; }
  void set_parsed_body(std::shared_ptr<nlohmann::json> parsed) { parsed_body_ = std::move(parsed); }
  /// The request's cancel flag (requests of the compute pool), or null.
  RequestCancel* cancel() const { return cancel_; }
  /// Gives the request a cancel flag (owned by the caller; outlives the stream).
  void set_cancel(RequestCancel* cancel) { cancel_ = cancel; }

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
  std::string body_;  // the answer's body after out_ (SetAnswer)
  bool write_through_ = false;
  bool healthy_ = true;
  RequestStream* previous_current_;
  RequestCancel* cancel_ = nullptr;
  std::shared_ptr<const api::BodySource> deferred_;  // the rest of the body (DeferBody)
  bool defer_next_write_ = false;                    // the next write is the deferred rest
  std::uint64_t deferred_begin_ = 0, deferred_end_ = 0;
  std::size_t head_bytes_ = 0;
  std::uint64_t content_length_ = 0;
  bool framed_ = false;
  std::shared_ptr<nlohmann::json> parsed_body_;
};

}  // namespace sweetspot::server
