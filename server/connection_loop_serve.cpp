// The connection loop serving a connection (c.mutex held): reading and framing a request,
// answering it on a light or compute worker, and writing what the socket did not take at once.
#include "server/connection_loop_internal.hpp"

namespace sweetspot::server {

// The loop's helpers and types (this file is compiled alone: server/CMakeLists.txt).
using namespace loop_internal;  // NOLINT(build/namespaces)

bool ConnectionLoop::Impl::Receive(Connection& c, Clock::time_point now) {
  const std::size_t cap = options.max_head_bytes + options.max_body_bytes + kReadChunk;
  for (;;) {
    if (c.state != State::kLingering && c.in.size() >= cap) return true;
    char buffer[kReadChunk];
    const ssize_t n = ::recv(c.fd, buffer, sizeof buffer, 0);
    if (n > 0) {
      if (c.state != State::kLingering) c.in.append(buffer, static_cast<std::size_t>(n));
      c.last_read = now;
      if (static_cast<std::size_t>(n) < sizeof buffer) return true;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
    return false;  // 0: the peer closed (at least its side); < 0: reset or another error
  }
}

ConnectionLoop::Impl::Step ConnectionLoop::Impl::AwaitMore(Connection& c) {
  if (c.peer_closed) {
    Close(c);
  } else {
    Arm(c);
  }
  return Step::kWait;
}

ConnectionLoop::Impl::Step ConnectionLoop::Impl::Advance(Connection& c, Clock::time_point now) {
  if (c.state == State::kIdle) {
    if (c.in.empty()) return AwaitMore(c);
    c.state = State::kReadingHead;
    c.started = now;
  }
  if (c.state == State::kReadingHead) {
    const HeadScan scan = ScanRequestHead(c.in, options.max_head_bytes, &c.scanned, &c.head);
    if (scan == HeadScan::kIncomplete) return AwaitMore(c);
    if (scan == HeadScan::kTooLarge) {
      Refuse(c, 431, api::ErrorCode::kTooBig, Reason::kHeadTooLarge,
             "the request head is over max_head_bytes = " +
                 std::to_string(options.max_head_bytes) + " bytes",
             now);
      return Step::kWait;
    }
    if (scan == HeadScan::kLineTooLong) {
      Refuse(c, 431, api::ErrorCode::kTooBig, Reason::kHeadTooLarge,
             "a header line is over " + std::to_string(kMaxHeaderLineBytes) +
                 " bytes (its CRLF included)",
             now);
      return Step::kWait;
    }
    if (scan == HeadScan::kTargetTooLong) {
      Refuse(c, 414, api::ErrorCode::kTooBig, Reason::kHeadTooLarge,
             "the request line is over " + std::to_string(kMaxRequestLineBytes) +
                 " bytes (its CRLF included): the URL is too long",
             now);
      return Step::kWait;
    }
    if (scan == HeadScan::kBareLineFeed) {
      Refuse(c, 400, api::ErrorCode::kInvalidValue, Reason::kBadRequest,
             "a line of the request head ends in a bare LF: every line must end in CRLF", now);
      return Step::kWait;
    }
    RequestHead& head = c.head;
    if (head.bad_content_length) {
      Refuse(c, 400, api::ErrorCode::kInvalidValue, Reason::kBadRequest,
             "header Content-Length: must be one decimal number of bytes", now);
      return Step::kWait;
    }
    // Lines httplib must not see, dropped from the last to the first: Expect ("100
    // Continue" is sent here when the body is awaited; httplib must not send another), and
    // Range (every answer is whole: httplib would build a multi-range body in memory, and
    // cut a JSON answer to a 200 of the range's bytes).
    std::vector<std::pair<std::size_t, std::size_t>> dropped = head.range_lines;
    if (head.expects_continue) dropped.emplace_back(head.expect_line_begin, head.expect_line_end);
    std::sort(dropped.begin(), dropped.end());
    for (auto it = dropped.rbegin(); it != dropped.rend(); ++it) {
      c.in.erase(it->first, it->second - it->first);
      head.head_bytes -= it->second - it->first;
    }
    c.continue_sent = false;
    if (head.has_transfer_encoding || head.content_length > options.max_body_bytes) {
      // httplib answers these from the head alone (411, 413); the body is never read.
      c.request_bytes = head.head_bytes;
      c.close_after = true;
      return Framed(c);
    }
    c.state = State::kReadingBody;
    c.body_deadline =
        now + Seconds(options.header_timeout_s) +
        Seconds(static_cast<double>(head.content_length) / options.body_min_rate_bytes_per_s);
  }
  // kReadingBody
  const std::size_t needed = c.head.head_bytes + c.head.content_length;
  if (c.in.size() >= needed) {
    c.request_bytes = needed;
    return Framed(c);
  }
  if (c.head.expects_continue && !c.continue_sent) {
    static constexpr char kContinue[] = "HTTP/1.1 100 Continue\r\n\r\n";
    [[maybe_unused]] const ssize_t n =
        ::send(c.fd, kContinue, sizeof kContinue - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
    c.continue_sent = true;
  }
  return AwaitMore(c);
}

ConnectionLoop::Impl::Step ConnectionLoop::Impl::Framed(Connection& c) {
  if (c.peer_closed) c.close_after = true;
  c.state = State::kWorking;
  return Step::kRequest;
}

void ConnectionLoop::Impl::Answer(Connection& c, BusyCounter& busy, RequestCancel* cancel) {
  busy.Enter();
  bool keep_open = false;
  try {
    const std::string_view request(c.in.data(), c.request_bytes);
    RequestStream stream(c.fd, request, options.write_timeout_s, c.remote_ip, c.remote_port,
                         c.local_ip, c.local_port);
    stream.set_cancel(cancel);
    stream.set_framing(c.head.head_bytes, c.head.content_length);
    stream.set_parsed_body(std::move(c.parsed_body));
    const bool last = c.close_after || c.served + 1 >= options.keep_alive_max_requests ||
                      stopping.load(std::memory_order_relaxed) ||
                      draining.load(std::memory_order_relaxed);
    bool closed = false;
    const bool ok = hooks.serve(stream, last, &closed);
    // What the socket does not take now is sent as the client reads (kWriting).
    const bool sent = stream.SendWithoutWaiting(&c.unsent);
    c.source = stream.TakeDeferred(&c.source_at, &c.source_end);
    if (!sent) c.source.reset();
    keep_open = ok && sent && !last && !closed;
    if (!sent) c.unsent.clear();
  } catch (...) {
    keep_open = false;  // httplib catches the handlers' exceptions; this is out of memory
  }
  busy.Leave();
  ++c.served;
  c.keep_open = keep_open;
}

bool ConnectionLoop::Impl::GraceOver(Clock::time_point now) const {
  if (!stopping.load()) return false;
  if (grace_ended.load()) return true;
  return now.time_since_epoch().count() - stop_ns.load() >=
         std::chrono::duration_cast<Clock::duration>(
             std::chrono::duration<double>(options.shutdown_grace_s))
             .count();
}

void ConnectionLoop::Impl::AnswerCompute(Connection& c) {
  if (GraceOver(Clock::now())) {
    Refuse(c, 503, api::ErrorCode::kTooBusy, Reason::kOverLimit,
           "the server is shutting down; retry on another replica or later", Clock::now());
    c.keep_open = false;
    return;
  }
  if (PeerGone(c.fd)) {
    closed_by[static_cast<int>(Reason::kClientGone)].fetch_add(1, std::memory_order_relaxed);
    Close(c);
    return;
  }
  RequestCancel cancel;
  {
    std::lock_guard<std::mutex> lock(c.cancel_mutex);
    c.cancel = &cancel;
    c.cancel_deadline = Clock::now() + Seconds(options.max_request_time_s);
  }
  Answer(c, compute_busy, &cancel);
  {
    std::lock_guard<std::mutex> lock(c.cancel_mutex);
    c.cancel = nullptr;
  }
  if (cancel.Reason() == CancelReason::kClientGone) {
    closed_by[static_cast<int>(Reason::kClientGone)].fetch_add(1, std::memory_order_relaxed);
  }
}

void ConnectionLoop::Impl::CheckWorking(Connection& c, Clock::time_point now, bool shutting_down) {
  std::lock_guard<std::mutex> lock(c.cancel_mutex);
  if (c.cancel == nullptr || c.cancel->Reason() != CancelReason::kNone) return;
  if (shutting_down) {
    c.cancel->Cancel(CancelReason::kShutdown);
  } else if (now >= c.cancel_deadline) {
    c.cancel->Cancel(CancelReason::kDeadline);
  } else if (PeerGone(c.fd)) {  // the fd stays open while c.cancel is set
    c.cancel->Cancel(CancelReason::kClientGone);
  }
}

bool ConnectionLoop::Impl::AfterAnswer(Connection& c, Clock::time_point now) {
  if (c.request_bytes > 0) {
    c.in.erase(0, c.request_bytes);
    c.request_bytes = 0;
    c.scanned = 0;
    c.head = RequestHead{};
  }
  c.parsed_body.reset();
  if (!c.unsent.empty() || c.source) {
    // The client reads slower than the answer: send the rest as it reads,
    // holding no worker (Writable), within the write timeout, and within its
    // address's budget of unsent bytes (else the answer is cut: closed).
    if (!Park(c)) {
      closed_by[static_cast<int>(Reason::kUnsentOverLimit)].fetch_add(
          1, std::memory_order_relaxed);
      c.unsent.clear();
      c.unsent.shrink_to_fit();
      Close(c);
      return false;
    }
    c.state = State::kWriting;
    c.write_deadline = now + Seconds(options.write_timeout_s);
    Arm(c);
    return false;
  }
  if (!c.keep_open || stopping.load(std::memory_order_relaxed)) {
    Linger(c, now);
    return false;
  }
  c.state = State::kIdle;
  c.idle_since = now;
  return true;
}

bool ConnectionLoop::Impl::Writable(Connection& c, Clock::time_point now) {
  for (;;) {
    if (c.unsent.empty() && c.source) {
      if (c.source_at >= c.source_end) {
        c.source.reset();
        break;
      }
      // The next piece of a sourced body: one read chunk held per connection.
      std::string piece;
      const auto n = static_cast<std::size_t>(
          std::min<std::uint64_t>(kReadChunk, c.source_end - c.source_at));
      if (!c.source->read(c.source_at, n, &piece) || piece.empty()) {
        Close(c);  // the source is gone (the job deleted): the answer is cut
        return false;
      }
      c.source_at += piece.size();
      c.unsent = std::move(piece);
      std::lock_guard<std::mutex> lock(map_mutex);
      parked_by_client[c.remote_ip] += c.unsent.size();
      c.parked += c.unsent.size();
    }
    if (c.unsent.empty()) break;
    std::size_t at = 0;
    bool blocked = false;
    for (;;) {
      const ssize_t n = ::send(c.fd, c.unsent.data() + at, c.unsent.size() - at,
                               MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        at += static_cast<std::size_t>(n);
        if (at == c.unsent.size()) break;
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        blocked = true;
        break;
      }
      c.unsent.clear();
      Close(c);  // the client is gone
      return false;
    }
    c.unsent.erase(0, at);
    {
      std::lock_guard<std::mutex> lock(map_mutex);
      Unpark(c, at);
    }
    if (at > 0) c.write_deadline = now + Seconds(options.write_timeout_s);  // it took some
    if (blocked) {
      Arm(c);
      return false;
    }
  }
  c.unsent.shrink_to_fit();
  c.state = State::kWorking;  // as after an answer
  return AfterAnswer(c, now);
}

void ConnectionLoop::Impl::Drive(const ConnectionPtr& c, std::unique_lock<std::mutex>& lock, Clock::time_point now,
           Pool pool) {
  while (Advance(*c, now) == Step::kRequest) {
    if (pool == Pool::kLight && hooks.classify &&
        hooks.classify(c->head.method, c->head.path,
                       std::string_view(c->in).substr(c->head.head_bytes,
                                                      c->request_bytes - c->head.head_bytes),
                       &c->parsed_body) == Pool::kCompute) {
      lock.unlock();
      compute->Push(c);
      return;
    }
    if (pool == Pool::kLight) {
      Answer(*c, light_busy);
    } else {
      AnswerCompute(*c);
      if (c->closed || c->state == State::kLingering) return;
    }
    now = Clock::now();
    if (!AfterAnswer(*c, now)) return;
  }
}

}  // namespace sweetspot::server
