#include "server/connection_loop.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <vector>

#include "server/request_head.hpp"

namespace sweetspot::server {
namespace {

using Clock = std::chrono::steady_clock;

// How often deadlines are checked, and so how late past its deadline a slow
// connection may be closed.
constexpr auto kSweepInterval = std::chrono::milliseconds(25);
// Bytes read from a socket per recv.
constexpr std::size_t kReadChunk = 64 * 1024;

Clock::duration Seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

const char* StatusText(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 408:
      return "Request Timeout";
    case 431:
      return "Request Header Fields Too Large";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

// "ip" and port of a socket address.
void AddressOf(const sockaddr_storage& addr, std::string* ip, int* port) {
  char text[INET6_ADDRSTRLEN] = "";
  if (addr.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<const sockaddr_in*>(&addr);
    inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
    *port = ntohs(in->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* in6 = reinterpret_cast<const sockaddr_in6*>(&addr);
    inet_ntop(AF_INET6, &in6->sin6_addr, text, sizeof text);
    *port = ntohs(in6->sin6_port);
  }
  *ip = text;
}

std::string FormatSeconds(double s) {
  std::ostringstream out;
  out << s;
  return out.str();
}

}  // namespace

// Why the loop closed or refused a connection (metrics label).
enum class Reason {
  kOverLimit,
  kHeaderTimeout,
  kBodyTooSlow,
  kReadTimeout,
  kHeadTooLarge,
  kBadRequest,
  kIdle,
  kCount
};

constexpr std::array<const char*, static_cast<int>(Reason::kCount)> kReasonNames = {
    "over_limit", "header_timeout", "body_too_slow", "read_timeout",
    "head_too_large", "bad_request", "keep_alive_idle"};

enum class State {
  kReadingHead,  // loop: waiting for the rest of a head
  kReadingBody,  // loop: waiting for the rest of a body
  kIdle,         // loop: keep-alive, between requests
  kLingering,    // loop: answered and half-closed, draining until the client closes
  kWorking,      // a worker's: queued or being served
};

struct Connection {
  int fd = -1;
  State state = State::kReadingHead;
  std::string in;            // received bytes not yet consumed (the current request first)
  std::size_t scanned = 0;   // how much of `in` the head scan has seen
  RequestHead head;          // the current request's framing (once its head is complete)
  std::size_t request_bytes = 0;  // head + body of the current request
  Clock::time_point started;      // the current head's first byte (the accept for a new one)
  Clock::time_point last_read;    // the last byte received
  Clock::time_point body_deadline;
  Clock::time_point idle_since;
  Clock::time_point linger_until;
  bool continue_sent = false;     // "100 Continue" sent for the current request
  bool close_after = false;       // close once the current request is answered
  bool keep_open = false;         // the worker's verdict
  bool peer_closed = false;       // the client shut its side: nothing more will arrive
  int served = 0;                 // requests answered on this connection
  std::string remote_ip, local_ip;
  int remote_port = 0, local_port = 0;
};

// A FIFO of connections with complete requests and the threads that serve them.
class WorkerPool {
 public:
  WorkerPool(const char* name, int threads, std::function<void(Connection*)> serve)
      : name_(name), serve_(std::move(serve)) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Work(); });
  }
  ~WorkerPool() { Shutdown(); }

  void Push(Connection* connection) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(connection);
    }
    cv_.notify_one();
  }
  // Serves what is queued, then joins the threads.
  void Shutdown() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (shutdown_) return;
      shutdown_ = true;
    }
    cv_.notify_all();
    for (auto& thread : threads_) thread.join();
  }

  const char* name() const { return name_; }
  int size() const { return static_cast<int>(threads_.size()); }
  long long busy() const { return busy_.load(std::memory_order_relaxed); }
  long long peak_busy() const { return peak_busy_.load(std::memory_order_relaxed); }
  unsigned long long served() const { return served_.load(std::memory_order_relaxed); }
  std::size_t queued() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }

 private:
  void Work() {
    for (;;) {
      Connection* connection = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return shutdown_ || !queue_.empty(); });
        if (queue_.empty()) return;
        connection = queue_.front();
        queue_.pop_front();
      }
      const long long now_busy = busy_.fetch_add(1, std::memory_order_relaxed) + 1;
      long long peak = peak_busy_.load(std::memory_order_relaxed);
      while (now_busy > peak &&
             !peak_busy_.compare_exchange_weak(peak, now_busy, std::memory_order_relaxed)) {
      }
      serve_(connection);
      served_.fetch_add(1, std::memory_order_relaxed);
      busy_.fetch_sub(1, std::memory_order_relaxed);
    }
  }

  const char* name_;
  std::function<void(Connection*)> serve_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Connection*> queue_;
  std::vector<std::thread> threads_;
  bool shutdown_ = false;
  std::atomic<long long> busy_{0};
  std::atomic<long long> peak_busy_{0};
  std::atomic<unsigned long long> served_{0};
};

struct ConnectionLoop::Impl {
  Impl(int listen, ConnectionLoopOptions o, ConnectionLoopHooks h)
      : listen_fd(listen), options(o), hooks(std::move(h)) {}

  // ---- the loop thread's state
  int listen_fd;
  int epoll_fd = -1;
  int wake_fd = -1;
  ConnectionLoopOptions options;
  ConnectionLoopHooks hooks;
  std::unordered_map<Connection*, std::unique_ptr<Connection>> connections;
  int admitted = 0;   // open connections that count against max_connections
  int lingering = 0;  // half-closed connections being drained
  int working = 0;    // connections queued or being served
  bool accept_paused = false;
  Clock::time_point accept_resume;
  char listen_tag = 0;
  char wake_tag = 0;

  // ---- shared with the workers and other threads
  std::atomic<bool> stopping{false};
  std::mutex returned_mutex;
  std::vector<Connection*> returned;
  std::unique_ptr<WorkerPool> light;
  std::unique_ptr<WorkerPool> compute;
  std::array<std::atomic<unsigned long long>, static_cast<int>(Reason::kCount)> closed_by{};
  std::atomic<int> open_gauge{0};
  std::atomic<int> idle_gauge{0};
  std::atomic<int> reading_gauge{0};
  std::atomic<int> lingering_gauge{0};
  std::atomic<unsigned long long> accepted{0};

  // ------------------------------------------------------------ epoll helpers
  void Arm(Connection* c) {
    epoll_event event{};
    event.events = EPOLLIN | EPOLLRDHUP | EPOLLONESHOT;
    event.data.ptr = c;
    epoll_ctl(epoll_fd, EPOLL_CTL_MOD, c->fd, &event);
  }

  void Wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_fd, &one, sizeof one);
  }

  // ------------------------------------------------------------ closing
  void Close(Connection* c) {
    if (c->state == State::kLingering) {
      --lingering;
    } else {
      --admitted;
    }
    ::close(c->fd);  // also removes it from the epoll set
    connections.erase(c);
  }

  // Half-closes `c` and drains it until the client closes or linger_s passes,
  // so that the client reads what was sent instead of a reset.
  void Linger(Connection* c, Clock::time_point now) {
    ::shutdown(c->fd, SHUT_WR);
    if (c->state != State::kLingering) {
      --admitted;
      ++lingering;
    }
    c->state = State::kLingering;
    c->in.clear();
    c->in.shrink_to_fit();
    c->linger_until = now + Seconds(options.linger_s);
    if (lingering > std::max(64, options.max_connections)) {
      Close(c);  // too many already: no draining for this one
      return;
    }
    Arm(c);
  }

  // Answers `c` with an error envelope of the loop's own, then lingers.
  void Refuse(Connection* c, int status, const char* code, Reason reason,
              const std::string& message, Clock::time_point now) {
    closed_by[static_cast<int>(reason)].fetch_add(1, std::memory_order_relaxed);
    const std::string body = hooks.error_body ? hooks.error_body(status, code, message) : "";
    std::string response = "HTTP/1.1 " + std::to_string(status) + " " + StatusText(status) +
                           "\r\nContent-Type: application/json\r\nContent-Length: " +
                           std::to_string(body.size()) + "\r\nConnection: close\r\n";
    if (status == 503) response += "Retry-After: 1\r\n";
    response += "\r\n" + body;
    // Best effort: a fresh socket's buffer takes a few hundred bytes at once.
    [[maybe_unused]] const ssize_t n =
        ::send(c->fd, response.data(), response.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (hooks.refused) hooks.refused(status, code, c->head.method, c->head.path);
    Linger(c, now);
  }

  // ------------------------------------------------------------ accepting
  void Accept(Clock::time_point now) {
    for (;;) {
      sockaddr_storage peer{};
      socklen_t peer_len = sizeof peer;
      const int fd = ::accept4(listen_fd, reinterpret_cast<sockaddr*>(&peer), &peer_len,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) {
        if (errno == EINTR || errno == ECONNABORTED) continue;
        if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
          // Out of descriptors: stop accepting for a moment instead of spinning.
          epoll_event event{};
          event.data.ptr = &listen_tag;
          epoll_ctl(epoll_fd, EPOLL_CTL_MOD, listen_fd, &event);
          accept_paused = true;
          accept_resume = now + std::chrono::milliseconds(100);
        }
        return;
      }
      const int yes = 1;
      setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);  // pitfalls.md: Nagle
      auto owned = std::make_unique<Connection>();
      Connection* c = owned.get();
      c->fd = fd;
      c->started = c->last_read = now;
      AddressOf(peer, &c->remote_ip, &c->remote_port);
      sockaddr_storage local{};
      socklen_t local_len = sizeof local;
      if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_len) == 0) {
        AddressOf(local, &c->local_ip, &c->local_port);
      }
      epoll_event event{};
      event.events = EPOLLIN | EPOLLRDHUP | EPOLLONESHOT;
      event.data.ptr = c;
      if (epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &event) != 0) {
        ::close(fd);
        continue;
      }
      connections.emplace(c, std::move(owned));
      accepted.fetch_add(1, std::memory_order_relaxed);
      ++admitted;
      if (admitted > options.max_connections) {
        Refuse(c, 503, "TooBusy", Reason::kOverLimit,
               "the server has " + std::to_string(options.max_connections) +
                   " connections open (limit max_connections); retry later",
               now);
      }
    }
  }

  // ------------------------------------------------------------ reading
  // Reads what the socket has (up to what the current request still needs,
  // plus one chunk). Returns false when the peer closed its side or failed.
  bool Receive(Connection* c, Clock::time_point now) {
    const std::size_t cap = options.max_head_bytes + options.max_body_bytes + kReadChunk;
    for (;;) {
      if (c->state != State::kLingering && c->in.size() >= cap) return true;
      char buffer[kReadChunk];
      const ssize_t n = ::recv(c->fd, buffer, sizeof buffer, 0);
      if (n > 0) {
        if (c->state != State::kLingering) c->in.append(buffer, static_cast<std::size_t>(n));
        c->last_read = now;
        if (static_cast<std::size_t>(n) < sizeof buffer) return true;
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
      return false;  // 0: the peer closed (at least its side); < 0: reset or another error
    }
  }

  void OnEvent(Connection* c, std::uint32_t events, Clock::time_point now) {
    const bool open = Receive(c, now);
    if (c->state == State::kLingering) {
      if (!open || (events & (EPOLLHUP | EPOLLERR)) != 0) {
        Close(c);
      } else {
        Arm(c);
      }
      return;
    }
    if (!open) {
      // The client closed its side: a request it completed first is still
      // answered (then the connection closes); otherwise nobody is listening.
      c->peer_closed = true;
      if (c->in.empty()) {
        Close(c);
        return;
      }
    }
    Advance(c, now);
  }

  // Waits for more of the current request, unless the client can send no more.
  void AwaitMore(Connection* c) {
    if (c->peer_closed) {
      Close(c);
    } else {
      Arm(c);
    }
  }

  // Moves `c` on with what it has received: frames the head, waits for the
  // body, hands a complete request to the light pool.
  void Advance(Connection* c, Clock::time_point now) {
    if (c->state == State::kIdle) {
      if (c->in.empty()) {
        AwaitMore(c);
        return;
      }
      c->state = State::kReadingHead;
      c->started = now;
    }
    if (c->state == State::kReadingHead) {
      const HeadScan scan = ScanRequestHead(c->in, options.max_head_bytes, &c->scanned, &c->head);
      if (scan == HeadScan::kIncomplete) {
        AwaitMore(c);
        return;
      }
      if (scan == HeadScan::kTooLarge) {
        Refuse(c, 431, "TooBig",
               Reason::kHeadTooLarge,
               "the request head is over max_head_bytes = " +
                   std::to_string(options.max_head_bytes) + " bytes",
               now);
        return;
      }
      RequestHead& head = c->head;
      if (head.bad_content_length) {
        Refuse(c, 400, "InvalidValue", Reason::kBadRequest,
               "header Content-Length: must be one decimal number of bytes", now);
        return;
      }
      if (head.expects_continue) {
        // The loop answers "100 Continue" itself; httplib must not send another.
        const std::size_t n = head.expect_line_end - head.expect_line_begin;
        c->in.erase(head.expect_line_begin, n);
        head.head_bytes -= n;
      }
      c->continue_sent = false;
      if (head.has_transfer_encoding || head.content_length > options.max_body_bytes) {
        // httplib answers these from the head alone (411, 413); the body is never read.
        c->request_bytes = head.head_bytes;
        c->close_after = true;
        Dispatch(c);
        return;
      }
      c->state = State::kReadingBody;
      c->body_deadline = now + Seconds(options.header_timeout_s) +
                         Seconds(static_cast<double>(head.content_length) /
                                 options.body_min_rate_bytes_per_s);
    }
    // kReadingBody
    const std::size_t needed = c->head.head_bytes + c->head.content_length;
    if (c->in.size() >= needed) {
      c->request_bytes = needed;
      Dispatch(c);
      return;
    }
    if (c->head.expects_continue && !c->continue_sent) {
      static constexpr char kContinue[] = "HTTP/1.1 100 Continue\r\n\r\n";
      [[maybe_unused]] const ssize_t n =
          ::send(c->fd, kContinue, sizeof kContinue - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
      c->continue_sent = true;
    }
    AwaitMore(c);
  }

  void Dispatch(Connection* c) {
    if (c->peer_closed) c->close_after = true;
    c->state = State::kWorking;
    ++working;
    light->Push(c);
  }

  // ------------------------------------------------------------ workers
  void Serve(Connection* c, Pool pool) {
    const std::string_view request(c->in.data(), c->request_bytes);
    if (pool == Pool::kLight && hooks.classify) {
      const std::string_view body = request.substr(c->head.head_bytes);
      if (hooks.classify(c->head.method, c->head.path, body) == Pool::kCompute) {
        compute->Push(c);
        return;
      }
    }
    bool keep_open = false;
    try {
      RequestStream stream(c->fd, request, options.write_timeout_s, c->remote_ip, c->remote_port,
                           c->local_ip, c->local_port);
      const bool last = c->close_after || c->served + 1 >= options.keep_alive_max_requests ||
                        stopping.load(std::memory_order_relaxed);
      bool closed = false;
      const bool ok = hooks.serve(stream, last, &closed);
      const bool flushed = stream.Flush();
      keep_open = ok && flushed && stream.healthy() && !last && !closed;
    } catch (...) {
      keep_open = false;  // httplib catches the handlers' exceptions; this is out of memory
    }
    ++c->served;
    c->keep_open = keep_open;
    {
      std::lock_guard<std::mutex> lock(returned_mutex);
      returned.push_back(c);
    }
    Wake();
  }

  // Takes back the connections the workers are done with.
  void TakeReturned(Clock::time_point now) {
    std::vector<Connection*> done;
    {
      std::lock_guard<std::mutex> lock(returned_mutex);
      done.swap(returned);
    }
    for (Connection* c : done) {
      --working;
      c->in.erase(0, c->request_bytes);
      c->request_bytes = 0;
      c->scanned = 0;
      c->head = RequestHead{};
      if (!c->keep_open || stopping.load(std::memory_order_relaxed)) {
        Linger(c, now);
        continue;
      }
      c->state = State::kIdle;
      c->idle_since = now;
      Advance(c, now);  // a pipelined request may be there already
    }
  }

  // ------------------------------------------------------------ deadlines
  void Sweep(Clock::time_point now) {
    int idle = 0, reading = 0;
    std::vector<Connection*> expired;
    for (const auto& [c, owned] : connections) {
      switch (c->state) {
        case State::kIdle:
          ++idle;
          if (now - c->idle_since >= Seconds(options.keep_alive_timeout_s)) expired.push_back(c);
          break;
        case State::kReadingHead:
          ++reading;
          if (now - c->started >= Seconds(options.header_timeout_s) ||
              now - c->last_read >= Seconds(options.read_timeout_s)) {
            expired.push_back(c);
          }
          break;
        case State::kReadingBody:
          ++reading;
          if (now >= c->body_deadline || now - c->last_read >= Seconds(options.read_timeout_s)) {
            expired.push_back(c);
          }
          break;
        case State::kLingering:
          if (now >= c->linger_until) expired.push_back(c);
          break;
        case State::kWorking:
          break;
      }
    }
    for (Connection* c : expired) Expire(c, now);
    open_gauge.store(admitted, std::memory_order_relaxed);
    idle_gauge.store(idle, std::memory_order_relaxed);
    reading_gauge.store(reading, std::memory_order_relaxed);
    lingering_gauge.store(lingering, std::memory_order_relaxed);
  }

  void Expire(Connection* c, Clock::time_point now) {
    switch (c->state) {
      case State::kIdle:
        closed_by[static_cast<int>(Reason::kIdle)].fetch_add(1, std::memory_order_relaxed);
        Close(c);
        return;
      case State::kLingering:
        Close(c);
        return;
      case State::kReadingHead:
        if (c->in.empty() && c->served == 0 &&
            now - c->last_read >= Seconds(options.read_timeout_s)) {
          // A connection that never sent a byte: nothing to answer.
          closed_by[static_cast<int>(Reason::kReadTimeout)].fetch_add(1,
                                                                       std::memory_order_relaxed);
          Close(c);
          return;
        }
        if (now - c->last_read >= Seconds(options.read_timeout_s) &&
            now - c->started < Seconds(options.header_timeout_s)) {
          Refuse(c, 408, "Timeout", Reason::kReadTimeout,
                 "no byte of the request head arrived for read_timeout_s = " +
                     FormatSeconds(options.read_timeout_s) + " s (read timeout)",
                 now);
          return;
        }
        Refuse(c, 408, "Timeout", Reason::kHeaderTimeout,
               "the request head did not arrive within header_timeout_s = " +
                   FormatSeconds(options.header_timeout_s) + " s",
               now);
        return;
      case State::kReadingBody:
        if (now >= c->body_deadline) {
          Refuse(c, 408, "Timeout", Reason::kBodyTooSlow,
                 "the request body of " + std::to_string(c->head.content_length) +
                     " bytes did not arrive within header_timeout_s + bytes / "
                     "body_min_rate_bytes_per_s = " +
                     FormatSeconds(options.header_timeout_s) + " s + " +
                     std::to_string(c->head.content_length) + " / " +
                     FormatSeconds(options.body_min_rate_bytes_per_s) + " s",
                 now);
          return;
        }
        Refuse(c, 408, "Timeout", Reason::kReadTimeout,
               "no byte of the request body arrived for read_timeout_s = " +
                   FormatSeconds(options.read_timeout_s) + " s (read timeout)",
               now);
        return;
      case State::kWorking:
        return;
    }
  }
};

ConnectionLoop::ConnectionLoop(int listen_fd, ConnectionLoopOptions options,
                               ConnectionLoopHooks hooks)
    : impl_(std::make_unique<Impl>(listen_fd, options, std::move(hooks))) {
  Impl* impl = impl_.get();
  impl->light = std::make_unique<WorkerPool>("light", std::max(1, options.light_workers),
                                             [impl](Connection* c) { impl->Serve(c, Pool::kLight); });
  impl->compute = std::make_unique<WorkerPool>(
      "compute", std::max(1, options.compute_workers),
      [impl](Connection* c) { impl->Serve(c, Pool::kCompute); });
  impl->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
}

ConnectionLoop::~ConnectionLoop() {
  Stop();
  impl_->light->Shutdown();
  impl_->compute->Shutdown();
  for (auto& [c, owned] : impl_->connections) ::close(c->fd);
  if (impl_->listen_fd >= 0) ::close(impl_->listen_fd);
  if (impl_->epoll_fd >= 0) ::close(impl_->epoll_fd);
  if (impl_->wake_fd >= 0) ::close(impl_->wake_fd);
}

void ConnectionLoop::Stop() {
  impl_->stopping.store(true);
  if (impl_->wake_fd >= 0) impl_->Wake();
}

bool ConnectionLoop::Run() {
  Impl& m = *impl_;
  if (m.epoll_fd < 0) m.epoll_fd = epoll_create1(EPOLL_CLOEXEC);
  if (m.epoll_fd < 0 || m.wake_fd < 0 || m.listen_fd < 0) return false;
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.ptr = &m.wake_tag;
  if (epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.wake_fd, &event) != 0) return false;
  event.data.ptr = &m.listen_tag;
  if (epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.listen_fd, &event) != 0) return false;

  std::array<epoll_event, 256> events{};
  Clock::time_point last_sweep = Clock::now();
  bool draining = false;  // stopping: no new requests; waiting for the workers
  for (;;) {
    const int timeout_ms = static_cast<int>(
        std::chrono::duration_cast<std::chrono::milliseconds>(kSweepInterval).count());
    const int n = epoll_wait(m.epoll_fd, events.data(), static_cast<int>(events.size()),
                             timeout_ms);
    const Clock::time_point now = Clock::now();
    for (int i = 0; i < n; ++i) {
      void* tag = events[i].data.ptr;
      if (tag == &m.listen_tag) {
        if (!draining) m.Accept(now);
      } else if (tag == &m.wake_tag) {
        std::uint64_t count = 0;
        [[maybe_unused]] const ssize_t r = ::read(m.wake_fd, &count, sizeof count);
      } else if (m.connections.count(static_cast<Connection*>(tag)) != 0) {
        m.OnEvent(static_cast<Connection*>(tag), events[i].events, now);
      }
    }
    m.TakeReturned(now);
    if (m.accept_paused && now >= m.accept_resume && !draining) {
      event.events = EPOLLIN;
      event.data.ptr = &m.listen_tag;
      epoll_ctl(m.epoll_fd, EPOLL_CTL_MOD, m.listen_fd, &event);
      m.accept_paused = false;
    }
    if (!draining && m.stopping.load()) {
      // Stop: no new connections; close those that wait for a request; the
      // requests already read are answered (with Connection: close).
      draining = true;
      epoll_ctl(m.epoll_fd, EPOLL_CTL_DEL, m.listen_fd, nullptr);
      ::close(m.listen_fd);
      m.listen_fd = -1;
      std::vector<Connection*> waiting;
      for (const auto& [c, owned] : m.connections) {
        if (c->state != State::kWorking) waiting.push_back(c);
      }
      for (Connection* c : waiting) m.Close(c);
    }
    if (draining) {
      // Connections the workers return are lingering now: close them at once.
      std::vector<Connection*> done;
      for (const auto& [c, owned] : m.connections) {
        if (c->state == State::kLingering) done.push_back(c);
      }
      for (Connection* c : done) m.Close(c);
      if (m.working == 0) break;
      continue;
    }
    if (now - last_sweep >= kSweepInterval) {
      m.Sweep(now);
      last_sweep = now;
    }
  }
  m.light->Shutdown();
  m.compute->Shutdown();
  return true;
}

std::string ConnectionLoop::MetricsText() const {
  const Impl& m = *impl_;
  std::ostringstream out;
  out << "# HELP sweetspot_connections Open connections by state (admitted ones count against "
         "max_connections).\n"
      << "# TYPE sweetspot_connections gauge\n"
      << "sweetspot_connections{state=\"admitted\"} " << m.open_gauge.load() << "\n"
      << "sweetspot_connections{state=\"idle\"} " << m.idle_gauge.load() << "\n"
      << "sweetspot_connections{state=\"reading\"} " << m.reading_gauge.load() << "\n"
      << "sweetspot_connections{state=\"lingering\"} " << m.lingering_gauge.load() << "\n"
      << "# HELP sweetspot_connections_accepted_total Connections accepted.\n"
      << "# TYPE sweetspot_connections_accepted_total counter\n"
      << "sweetspot_connections_accepted_total " << m.accepted.load() << "\n"
      << "# HELP sweetspot_connections_closed_total Connections the server closed or refused, "
         "by reason.\n"
      << "# TYPE sweetspot_connections_closed_total counter\n";
  for (int i = 0; i < static_cast<int>(Reason::kCount); ++i) {
    out << "sweetspot_connections_closed_total{reason=\"" << kReasonNames[i] << "\"} "
        << m.closed_by[i].load() << "\n";
  }
  out << "# HELP sweetspot_workers Worker threads per pool.\n# TYPE sweetspot_workers gauge\n";
  for (const WorkerPool* pool : {m.light.get(), m.compute.get()}) {
    out << "sweetspot_workers{pool=\"" << pool->name() << "\"} " << pool->size() << "\n";
  }
  out << "# HELP sweetspot_workers_busy Workers serving a request now, per pool.\n"
      << "# TYPE sweetspot_workers_busy gauge\n";
  for (const WorkerPool* pool : {m.light.get(), m.compute.get()}) {
    out << "sweetspot_workers_busy{pool=\"" << pool->name() << "\"} " << pool->busy() << "\n";
  }
  out << "# HELP sweetspot_workers_busy_peak The most workers busy at once since the start, per "
         "pool.\n"
      << "# TYPE sweetspot_workers_busy_peak gauge\n";
  for (const WorkerPool* pool : {m.light.get(), m.compute.get()}) {
    out << "sweetspot_workers_busy_peak{pool=\"" << pool->name() << "\"} " << pool->peak_busy()
        << "\n";
  }
  out << "# HELP sweetspot_requests_queued Complete requests waiting for a worker, per pool.\n"
      << "# TYPE sweetspot_requests_queued gauge\n";
  for (const WorkerPool* pool : {m.light.get(), m.compute.get()}) {
    out << "sweetspot_requests_queued{pool=\"" << pool->name() << "\"} " << pool->queued()
        << "\n";
  }
  out << "# HELP sweetspot_pool_requests_total Requests served, per pool (a request the light "
         "pool passes on counts in both).\n"
      << "# TYPE sweetspot_pool_requests_total counter\n";
  for (const WorkerPool* pool : {m.light.get(), m.compute.get()}) {
    out << "sweetspot_pool_requests_total{pool=\"" << pool->name() << "\"} " << pool->served()
        << "\n";
  }
  return out.str();
}

}  // namespace sweetspot::server
