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

#include "api/thread_budget.hpp"
#include "server/request_head.hpp"

namespace sweetspot::server {
namespace {

using Clock = std::chrono::steady_clock;

// How often deadlines are checked, and so how late past its deadline a slow
// connection may be closed.
constexpr auto kConnectionSweepInterval = std::chrono::milliseconds(25);
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
    case 414:
      return "URI Too Long";
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

// Why a connection was closed or refused (metrics label).
enum class Reason {
  kOverLimit,
  kHeaderTimeout,
  kBodyTooSlow,
  kReadTimeout,
  kHeadTooLarge,
  kBadRequest,
  kIdle,
  kWriteTimeout,
  kOverClientLimit,
  kFirstByteTimeout,
  kClientGone,
  kUnsentOverLimit,
  kCount
};

constexpr std::array<const char*, static_cast<int>(Reason::kCount)> kReasonNames = {
    "over_limit",        "header_timeout",     "body_too_slow",   "read_timeout",
    "head_too_large",    "bad_request",        "keep_alive_idle", "write_timeout",
    "over_client_limit", "first_byte_timeout", "client_gone",     "unsent_over_limit"};

// True when the client of `fd` closed its side (or the socket failed) and sent nothing
// more that is still unread: nobody will read an answer. Never blocks.
bool PeerGone(int fd) {
  char byte = 0;
  const ssize_t n = ::recv(fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT);
  if (n == 0) return true;
  return n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
}

enum class State {
  kReadingHead,  // armed: waiting for the rest of a head
  kReadingBody,  // armed: waiting for the rest of a body
  kIdle,         // armed: keep-alive, between requests
  kWriting,      // armed for writing: the rest of an answer, sent as the client reads
  kLingering,    // armed: answered and half-closed, draining until the client closes
  kWorking,      // a complete request is queued or being answered
};

// epoll tags of the two descriptors that are not connections; connections
// are tagged with their id (from 2 on), never with a pointer, so that an
// event taken for a connection another thread just closed finds nothing.
constexpr std::uint64_t kListenTag = 0;
constexpr std::uint64_t kWakeTag = 1;

// One client connection. Whoever handles it holds `mutex`: the worker woken
// for it, the worker answering its request, or the deadline keeper.
struct Connection {
  std::mutex mutex;
  std::uint64_t id = 0;
  int fd = -1;
  bool closed = false;  // fd closed: nothing more to do
  State state = State::kReadingHead;
  std::string in;                 // received bytes not yet consumed (the current request first)
  std::size_t scanned = 0;        // how much of `in` the head scan has seen
  RequestHead head;               // the current request's framing (once its head is complete)
  std::size_t request_bytes = 0;  // head + body of the current request
  std::shared_ptr<nlohmann::json> parsed_body;  // the current body, if classify parsed it
  Clock::time_point started;      // the current head's first byte (the accept for a new one)
  Clock::time_point last_read;    // the last byte received
  Clock::time_point body_deadline;
  Clock::time_point idle_since;
  Clock::time_point linger_until;
  std::string unsent;                // the rest of an answer (kWriting)
  std::size_t parked = 0;            // of `unsent`, the bytes counted against its client's budget
  // The rest of the answer's body still in its source (a stored job result), read a piece
  // at a time into `unsent` as the client takes it: bytes [source_at, source_end).
  std::shared_ptr<const api::BodySource> source;
  std::uint64_t source_at = 0, source_end = 0;
  Clock::time_point write_deadline;  // kWriting: the client must take more by then
  bool continue_sent = false;        // "100 Continue" sent for the current request
  bool close_after = false;          // close once the current request is answered
  bool keep_open = false;            // the verdict on the request just answered
  bool peer_closed = false;          // the client shut its side: nothing more will arrive
  int served = 0;                    // requests answered on this connection
  bool admitted = true;              // counts against max_connections (and its client's)
  // The cancel flag of the compute request being answered (null otherwise), and when it
  // must stop; `cancel_mutex` guards both (the deadline keeper reads them while a worker
  // holds `mutex`).
  std::mutex cancel_mutex;
  RequestCancel* cancel = nullptr;
  Clock::time_point cancel_deadline;
  std::string remote_ip, local_ip;
  int remote_port = 0, local_port = 0;
};
using ConnectionPtr = std::shared_ptr<Connection>;

// Counts the workers of a pool that are answering a request, and their peak.
class BusyCounter {
 public:
  void Enter() {
    const long long now = busy_.fetch_add(1, std::memory_order_relaxed) + 1;
    long long peak = peak_.load(std::memory_order_relaxed);
    while (now > peak && !peak_.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
    }
  }
  void Leave() {
    busy_.fetch_sub(1, std::memory_order_relaxed);
    served_.fetch_add(1, std::memory_order_relaxed);
  }
  long long busy() const { return busy_.load(std::memory_order_relaxed); }
  long long peak() const { return peak_.load(std::memory_order_relaxed); }
  unsigned long long served() const { return served_.load(std::memory_order_relaxed); }

 private:
  std::atomic<long long> busy_{0};
  std::atomic<long long> peak_{0};
  std::atomic<unsigned long long> served_{0};
};

// The compute pool: a FIFO of connections with a complete request that runs
// models, and the threads that answer them.
class ComputePool {
 public:
  ComputePool(int threads, std::function<void(ConnectionPtr)> serve) : serve_(std::move(serve)) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Work(); });
  }
  ~ComputePool() { Shutdown(); }

  void Push(ConnectionPtr connection) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(std::move(connection));
    }
    cv_.notify_one();
  }
  // Answers what is queued, then joins the threads.
  void Shutdown() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (shutdown_) return;
      shutdown_ = true;
    }
    cv_.notify_all();
    for (auto& thread : threads_) thread.join();
  }
  int size() const { return static_cast<int>(threads_.size()); }
  std::size_t queued() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }

 private:
  void Work() {
    for (;;) {
      ConnectionPtr connection;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return shutdown_ || !queue_.empty(); });
        if (queue_.empty()) return;
        connection = std::move(queue_.front());
        queue_.pop_front();
      }
      serve_(std::move(connection));
    }
  }

  std::function<void(ConnectionPtr)> serve_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<ConnectionPtr> queue_;
  std::vector<std::thread> threads_;
  bool shutdown_ = false;
};

}  // namespace

struct ConnectionLoop::Impl {
  Impl(int listen, ConnectionLoopOptions o, ConnectionLoopHooks h)
      : listen_fd(listen), options(o), hooks(std::move(h)) {}

  int listen_fd;
  int epoll_fd = -1;
  int wake_fd = -1;  // becomes readable (and stays so) when the workers must leave
  const ConnectionLoopOptions options;
  const ConnectionLoopHooks hooks;

  mutable std::mutex map_mutex;
  std::unordered_map<std::uint64_t, ConnectionPtr> connections;
  std::unordered_map<std::string, int> per_client;  // admitted connections by client address
  // Unsent answer bytes held for each client address (max_unsent_bytes_per_client).
  std::unordered_map<std::string, std::size_t> parked_by_client;
  std::uint64_t next_id = 2;

  std::atomic<bool> stopping{false};
  std::atomic<long long> stop_ns{0};      // when Stop() was first called (steady clock)
  std::atomic<bool> grace_ended{false};  // EndGrace(): no more time for requests in flight
  std::atomic<int> admitted{0};   // open connections that count against max_connections
  std::atomic<int> lingering{0};  // half-closed connections being drained
  std::atomic<bool> accept_paused{false};
  std::atomic<long long> accept_resume_ns{0};
  std::vector<std::thread> light_threads;
  std::unique_ptr<ComputePool> compute;
  BusyCounter light_busy, compute_busy;
  std::array<std::atomic<unsigned long long>, static_cast<int>(Reason::kCount)> closed_by{};
  std::atomic<unsigned long long> accepted{0};
  std::atomic<int> idle_gauge{0};
  std::atomic<int> reading_gauge{0};

  // ------------------------------------------------------------ registry
  ConnectionPtr Find(std::uint64_t id) {
    std::lock_guard<std::mutex> lock(map_mutex);
    const auto it = connections.find(id);
    return it == connections.end() ? nullptr : it->second;
  }

  std::vector<ConnectionPtr> Snapshot() {
    std::lock_guard<std::mutex> lock(map_mutex);
    std::vector<ConnectionPtr> all;
    all.reserve(connections.size());
    for (const auto& [id, c] : connections) all.push_back(c);
    return all;
  }

  // ------------------------------------------------------------ epoll
  // Waits for the next bytes of `c` (one event, then disarmed until re-armed).
  void Arm(Connection& c) {
    epoll_event event{};
    event.events = (c.state == State::kWriting ? EPOLLOUT : EPOLLIN | EPOLLRDHUP) | EPOLLONESHOT;
    event.data.u64 = c.id;
    epoll_ctl(epoll_fd, EPOLL_CTL_MOD, c.fd, &event);
  }

  // ------------------------------------------------------------ closing (c.mutex held)
  void Close(Connection& c) {
    if (c.closed) return;
    c.closed = true;
    if (c.state == State::kLingering) lingering.fetch_sub(1, std::memory_order_relaxed);
    c.source.reset();
    ::close(c.fd);  // also takes it out of the epoll set
    std::lock_guard<std::mutex> lock(map_mutex);
    ReleaseAdmission(c);
    Unpark(c, c.parked);
    connections.erase(c.id);
  }

  // `n` of the bytes `c` has parked were sent or dropped (map_mutex held).
  void Unpark(Connection& c, std::size_t n) {
    n = std::min(n, c.parked);
    if (n == 0) return;
    c.parked -= n;
    const auto it = parked_by_client.find(c.remote_ip);
    if (it == parked_by_client.end()) return;
    it->second -= std::min(n, it->second);
    if (it->second == 0) parked_by_client.erase(it);
  }

  // The unsent answer bytes held for every client.
  std::size_t UnsentBytes() const {
    std::lock_guard<std::mutex> lock(map_mutex);
    std::size_t total = 0;
    for (const auto& [address, bytes] : parked_by_client) total += bytes;
    return total;
  }

  // Counts the rest of c's answer against its client's budget of unsent bytes; false (and
  // nothing counted) when it would exceed max_unsent_bytes_per_client.
  bool Park(Connection& c) {
    std::lock_guard<std::mutex> lock(map_mutex);
    std::size_t& held = parked_by_client[c.remote_ip];
    if (held + c.unsent.size() > options.max_unsent_bytes_per_client) {
      if (held == 0) parked_by_client.erase(c.remote_ip);
      return false;
    }
    held += c.unsent.size();
    c.parked = c.unsent.size();
    return true;
  }

  // `c` no longer counts against max_connections and its client's limit (map_mutex held).
  void ReleaseAdmission(Connection& c) {
    if (!c.admitted) return;
    c.admitted = false;
    admitted.fetch_sub(1, std::memory_order_relaxed);
    const auto it = per_client.find(c.remote_ip);
    if (it != per_client.end() && --it->second <= 0) per_client.erase(it);
  }

  // Half-closes `c` and drains it until the client closes or linger_s passes,
  // so that the client reads what was sent instead of a reset.
  void Linger(Connection& c, Clock::time_point now) {
    ::shutdown(c.fd, SHUT_WR);
    if (c.state != State::kLingering) {
      {
        std::lock_guard<std::mutex> lock(map_mutex);
        ReleaseAdmission(c);
      }
      lingering.fetch_add(1, std::memory_order_relaxed);
      c.state = State::kLingering;
    }
    c.in.clear();
    c.in.shrink_to_fit();
    c.linger_until = now + Seconds(options.linger_s);
    if (lingering.load(std::memory_order_relaxed) > std::max(64, options.max_connections)) {
      Close(c);  // too many already: no draining for this one
      return;
    }
    Arm(c);
  }

  // Answers `c` with an error envelope of its own, then lingers.
  void Refuse(Connection& c, int status, api::ErrorCode code, Reason reason,
              const std::string& message, Clock::time_point now) {
    closed_by[static_cast<int>(reason)].fetch_add(1, std::memory_order_relaxed);
    const std::string body = hooks.error_body ? hooks.error_body(status, code, message) : "";
    std::string response =
        "HTTP/1.1 " + std::to_string(status) + " " + StatusText(status) +
        "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
        "\r\nConnection: close\r\n";
    if (status == 503) response += "Retry-After: 1\r\n";
    response += "\r\n" + body;
    // Best effort: a socket's buffer takes a few hundred bytes at once.
    [[maybe_unused]] const ssize_t n =
        ::send(c.fd, response.data(), response.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (hooks.refused) hooks.refused(status, code, c.head.method, c.head.path);
    Linger(c, now);
  }

  // ------------------------------------------------------------ accepting
  void Accept() {
    for (;;) {
      sockaddr_storage peer{};
      socklen_t peer_len = sizeof peer;
      const int fd = ::accept4(listen_fd, reinterpret_cast<sockaddr*>(&peer), &peer_len,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      const Clock::time_point now = Clock::now();
      if (fd < 0) {
        if (errno == EINTR || errno == ECONNABORTED) continue;
        if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
          // Out of descriptors: stop accepting for 100 ms instead of spinning
          // (an EPOLLEXCLUSIVE registration cannot be modified, only removed).
          epoll_ctl(epoll_fd, EPOLL_CTL_DEL, listen_fd, nullptr);
          accept_resume_ns.store((now + std::chrono::milliseconds(100)).time_since_epoch().count());
          accept_paused.store(true);
        }
        return;
      }
      const int yes = 1;
      setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);  // pitfalls.md: Nagle
      auto c = std::make_shared<Connection>();
      std::lock_guard<std::mutex> hold(c->mutex);  // an event may come as soon as it is added
      c->fd = fd;
      c->started = c->last_read = now;
      AddressOf(peer, &c->remote_ip, &c->remote_port);
      sockaddr_storage local{};
      socklen_t local_len = sizeof local;
      if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_len) == 0) {
        AddressOf(local, &c->local_ip, &c->local_port);
      }
      int from_client = 0;
      {
        std::lock_guard<std::mutex> lock(map_mutex);
        c->id = next_id++;
        connections.emplace(c->id, c);
        from_client = ++per_client[c->remote_ip];
      }
      accepted.fetch_add(1, std::memory_order_relaxed);
      const bool over = admitted.fetch_add(1, std::memory_order_relaxed) >= options.max_connections;
      const bool over_client = from_client > options.max_connections_per_client;
      epoll_event event{};
      event.events = EPOLLIN | EPOLLRDHUP | EPOLLONESHOT;
      event.data.u64 = c->id;
      if (epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &event) != 0) {
        Close(*c);
        continue;
      }
      if (over) {
        Refuse(*c, 503, api::ErrorCode::kTooBusy, Reason::kOverLimit,
               "the server has " + std::to_string(options.max_connections) +
                   " connections open (limit max_connections); retry later",
               now);
      } else if (over_client) {
        Refuse(*c, 503, api::ErrorCode::kTooBusy, Reason::kOverClientLimit,
               "the server has " + std::to_string(options.max_connections_per_client) +
                   " connections open from " + c->remote_ip +
                   " (limit max_connections_per_client); retry later",
               now);
      }
    }
  }

  // ------------------------------------------------------------ reading (c.mutex held)
  // Reads what the socket has (up to the largest request, plus one chunk).
  // Returns false when the peer closed its side or failed.
  bool Receive(Connection& c, Clock::time_point now) {
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

  enum class Step {
    kWait,     // armed again, or closed, or lingering: nothing more to do now
    kRequest,  // a complete request is framed (state kWorking): answer it
  };

  // Waits for more of the current request, unless the client can send no more.
  Step AwaitMore(Connection& c) {
    if (c.peer_closed) {
      Close(c);
    } else {
      Arm(c);
    }
    return Step::kWait;
  }

  // Moves `c` on with what it has received: frames the head, waits for the
  // body, and says when a complete request is there.
  Step Advance(Connection& c, Clock::time_point now) {
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

  Step Framed(Connection& c) {
    if (c.peer_closed) c.close_after = true;
    c.state = State::kWorking;
    return Step::kRequest;
  }

  // ------------------------------------------------------------ answering (c.mutex held)
  // Answers the framed request of `c` with httplib; sets c.keep_open.
  void Answer(Connection& c, BusyCounter& busy, RequestCancel* cancel = nullptr) {
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
                        stopping.load(std::memory_order_relaxed);
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

  // Answers the framed request of `c` on a compute worker, with a cancel flag the deadline
  // keeper sets (client gone, max_request_time_s, shutdown). A request whose client left
  // while it was queued is dropped; once the server stops, one still queued is refused.
  // True once the server stops and the requests in flight have had their grace.
  bool GraceOver(Clock::time_point now) const {
    if (!stopping.load()) return false;
    if (grace_ended.load()) return true;
    return now.time_since_epoch().count() - stop_ns.load() >=
           std::chrono::duration_cast<Clock::duration>(
               std::chrono::duration<double>(options.shutdown_grace_s))
               .count();
  }

  void AnswerCompute(Connection& c) {
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

  // The deadline keeper's look at a request being answered (`c` held by its worker): sets
  // its cancel flag when the client left, its time is up, or the server stops.
  void CheckWorking(Connection& c, Clock::time_point now, bool shutting_down) {
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

  // After an answer: closes (lingering) or goes back to waiting. Returns true
  // when `c` waits for its next request (Advance may find one already in).
  bool AfterAnswer(Connection& c, Clock::time_point now) {
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

  // The socket of a kWriting connection takes more: send what it takes; once
  // the answer is out, go on as after any answer. Returns true when `c` waits
  // for its next request.
  bool Writable(Connection& c, Clock::time_point now) {
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

  // Handles `c` until it waits for bytes, is closed, or went to the compute
  // pool: answers each complete request, one after another for a client that
  // pipelines.
  void Drive(const ConnectionPtr& c, std::unique_lock<std::mutex>& lock, Clock::time_point now,
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

  // ------------------------------------------------------------ the threads
  void LightWorker() {
    for (;;) {
      epoll_event event{};
      const int n = epoll_wait(epoll_fd, &event, 1, 1000);
      if (n <= 0) continue;
      if (event.data.u64 == kWakeTag) return;  // Run() is done: leave
      if (event.data.u64 == kListenTag) {
        if (!stopping.load()) Accept();
        continue;
      }
      const ConnectionPtr c = Find(event.data.u64);
      if (!c) continue;  // closed since the event was queued
      std::unique_lock<std::mutex> lock(c->mutex);
      if (c->closed) continue;
      const Clock::time_point now = Clock::now();
      if (c->state == State::kWriting) {
        if ((event.events & (EPOLLHUP | EPOLLERR)) != 0) {
          Close(*c);
        } else if (Writable(*c, now)) {
          Drive(c, lock, now, Pool::kLight);
        }
        continue;
      }
      const bool open = Receive(*c, now);
      if (c->state == State::kLingering) {
        if (!open || (event.events & (EPOLLHUP | EPOLLERR)) != 0) {
          Close(*c);
        } else {
          Arm(*c);
        }
        continue;
      }
      if (!open) {
        // The client closed its side: a request it completed first is still
        // answered (then the connection closes); otherwise nobody is listening.
        c->peer_closed = true;
        if (c->in.empty()) {
          Close(*c);
          continue;
        }
      }
      Drive(c, lock, now, Pool::kLight);
    }
  }

  void ComputeWorker(ConnectionPtr c) {
    // One of the pool's threads, unless a sweep has borrowed it (then this waits for it).
    api::ThreadBudget* budget = options.compute_budget;
    if (budget != nullptr) budget->TakeOne();
    struct GiveBack {
      api::ThreadBudget* budget;
      ~GiveBack() {
        if (budget != nullptr) budget->Give(1);
      }
    } give_back{budget};
    std::unique_lock<std::mutex> lock(c->mutex);
    if (c->closed) return;
    AnswerCompute(*c);
    if (c->closed || c->state == State::kLingering) return;
    const Clock::time_point now = Clock::now();
    if (AfterAnswer(*c, now)) Drive(c, lock, now, Pool::kCompute);
  }

  // ------------------------------------------------------------ deadlines (Run's thread)
  void Sweep(Clock::time_point now) {
    int idle = 0, reading = 0;
    for (const ConnectionPtr& c : Snapshot()) {
      std::unique_lock<std::mutex> lock(c->mutex, std::try_to_lock);
      if (!lock.owns_lock()) {
        CheckWorking(*c, now, /*shutting_down=*/false);  // a worker has it: answering
        continue;
      }
      if (c->closed) continue;
      switch (c->state) {
        case State::kIdle:
          ++idle;
          if (now - c->idle_since >= Seconds(options.keep_alive_timeout_s)) {
            closed_by[static_cast<int>(Reason::kIdle)].fetch_add(1, std::memory_order_relaxed);
            Close(*c);
          }
          break;
        case State::kReadingHead:
          ++reading;
          if (c->in.empty() && c->served == 0 &&
              now - c->started >= Seconds(options.first_byte_timeout_s)) {
            closed_by[static_cast<int>(Reason::kFirstByteTimeout)].fetch_add(
                1, std::memory_order_relaxed);
            Close(*c);
          } else if (now - c->started >= Seconds(options.header_timeout_s) ||
              now - c->last_read >= Seconds(options.read_timeout_s)) {
            ExpireHead(*c, now);
          }
          break;
        case State::kReadingBody:
          ++reading;
          if (now >= c->body_deadline || now - c->last_read >= Seconds(options.read_timeout_s)) {
            ExpireBody(*c, now);
          }
          break;
        case State::kWriting:
          if (now >= c->write_deadline) {
            closed_by[static_cast<int>(Reason::kWriteTimeout)].fetch_add(1,
                                                                         std::memory_order_relaxed);
            Close(*c);
          }
          break;
        case State::kLingering:
          if (now >= c->linger_until) Close(*c);
          break;
        case State::kWorking:
          break;
      }
    }
    idle_gauge.store(idle, std::memory_order_relaxed);
    reading_gauge.store(reading, std::memory_order_relaxed);
  }

  void ExpireHead(Connection& c, Clock::time_point now) {
    const bool silent = now - c.last_read >= Seconds(options.read_timeout_s);
    if (c.in.empty() && c.served == 0 && silent) {
      // A connection that never sent a byte: nothing to answer.
      closed_by[static_cast<int>(Reason::kReadTimeout)].fetch_add(1, std::memory_order_relaxed);
      Close(c);
      return;
    }
    if (silent && now - c.started < Seconds(options.header_timeout_s)) {
      RefuseSilent(c, "head", now);
      return;
    }
    Refuse(c, 408, api::ErrorCode::kTimeout, Reason::kHeaderTimeout,
           "the request head did not arrive within header_timeout_s = " +
               FormatSeconds(options.header_timeout_s) + " s",
           now);
  }

  void ExpireBody(Connection& c, Clock::time_point now) {
    if (now >= c.body_deadline) {
      Refuse(c, 408, api::ErrorCode::kTimeout, Reason::kBodyTooSlow,
             "the request body of " + std::to_string(c.head.content_length) +
                 " bytes did not arrive within header_timeout_s + bytes / "
                 "body_min_rate_bytes_per_s = " +
                 FormatSeconds(options.header_timeout_s) + " s + " +
                 std::to_string(c.head.content_length) + " / " +
                 FormatSeconds(options.body_min_rate_bytes_per_s) + " s",
             now);
      return;
    }
    RefuseSilent(c, "body", now);
  }

  // 408 for a request that sent nothing for read_timeout_s, in its head or body (`part`).
  void RefuseSilent(Connection& c, const char* part, Clock::time_point now) {
    Refuse(c, 408, api::ErrorCode::kTimeout, Reason::kReadTimeout,
           std::string("no byte of the request ") + part + " arrived for read_timeout_s = " +
               FormatSeconds(options.read_timeout_s) + " s (read timeout)",
           now);
  }

  // Stop: closes every connection that is not being answered (those close
  // themselves after their answer; answers still being sent get their write
  // timeout). Returns how many connections remain.
  std::size_t CloseWaiting(Clock::time_point now) {
    for (const ConnectionPtr& c : Snapshot()) {
      std::unique_lock<std::mutex> lock(c->mutex, std::try_to_lock);
      if (!lock.owns_lock()) {
        CheckWorking(*c, now, GraceOver(now));  // being answered: stopped once the grace ends
        continue;
      }
      if (c->closed || c->state == State::kWorking) continue;
      // An answer being sent gets its write timeout, and at most the grace.
      if (c->state == State::kWriting && now < c->write_deadline && !GraceOver(now)) continue;
      Close(*c);
    }
    std::lock_guard<std::mutex> lock(map_mutex);
    return connections.size();
  }
};

ConnectionLoop::ConnectionLoop(int listen_fd, ConnectionLoopOptions options,
                               ConnectionLoopHooks hooks)
    : impl_(std::make_unique<Impl>(listen_fd, options, std::move(hooks))) {
  impl_->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  impl_->epoll_fd = epoll_create1(EPOLL_CLOEXEC);
}

ConnectionLoop::~ConnectionLoop() {
  Stop();
  Impl& m = *impl_;
  for (auto& thread : m.light_threads) {
    if (thread.joinable()) thread.join();
  }
  if (m.compute) m.compute->Shutdown();
  for (const ConnectionPtr& c : m.Snapshot()) {
    if (!c->closed) ::close(c->fd);
  }
  if (m.listen_fd >= 0) ::close(m.listen_fd);
  if (m.epoll_fd >= 0) ::close(m.epoll_fd);
  if (m.wake_fd >= 0) ::close(m.wake_fd);
}

void ConnectionLoop::Stop() {
  long long unset = 0;
  impl_->stop_ns.compare_exchange_strong(unset, Clock::now().time_since_epoch().count());
  impl_->stopping.store(true);
}

void ConnectionLoop::EndGrace() { impl_->grace_ended.store(true); }

bool ConnectionLoop::Run() {
  Impl& m = *impl_;
  if (m.epoll_fd < 0 || m.wake_fd < 0 || m.listen_fd < 0 || !m.light_threads.empty()) return false;
  epoll_event event{};
  // Level-triggered and never read: once written, it wakes every worker (to leave).
  event.events = EPOLLIN;
  event.data.u64 = kWakeTag;
  if (epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.wake_fd, &event) != 0) return false;
  // One worker woken per new connection (EPOLLEXCLUSIVE), not all of them.
  event.events = EPOLLIN | EPOLLEXCLUSIVE;
  event.data.u64 = kListenTag;
  if (epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.listen_fd, &event) != 0) return false;

  m.compute =
      std::make_unique<ComputePool>(std::max(1, m.options.compute_workers),
                                    [&m](ConnectionPtr c) { m.ComputeWorker(std::move(c)); });
  for (int i = 0; i < std::max(1, m.options.light_workers); ++i) {
    m.light_threads.emplace_back([&m] { m.LightWorker(); });
  }

  // This thread keeps the deadlines until Stop().
  while (!m.stopping.load()) {
    std::this_thread::sleep_for(kConnectionSweepInterval);
    const Clock::time_point now = Clock::now();
    m.Sweep(now);
    if (m.accept_paused.load() && now.time_since_epoch().count() >= m.accept_resume_ns.load()) {
      m.accept_paused.store(false);
      event.events = EPOLLIN | EPOLLEXCLUSIVE;
      event.data.u64 = kListenTag;
      // EPOLLEXCLUSIVE cannot be modified: take the socket out and add it again.
      epoll_ctl(m.epoll_fd, EPOLL_CTL_DEL, m.listen_fd, nullptr);
      epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, m.listen_fd, &event);
    }
  }
  // Stop: no new connections; those waiting for a request are closed; the
  // requests being answered finish (with Connection: close) and close theirs.
  epoll_ctl(m.epoll_fd, EPOLL_CTL_DEL, m.listen_fd, nullptr);
  while (m.CloseWaiting(Clock::now()) > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(m.wake_fd, &one, sizeof one);
  for (auto& thread : m.light_threads) thread.join();
  m.light_threads.clear();
  m.compute->Shutdown();
  // Closed only now that no worker can be accepting on it: later connections are refused.
  ::close(m.listen_fd);
  m.listen_fd = -1;
  return true;
}

std::string ConnectionLoop::MetricsText() const {
  const Impl& m = *impl_;
  std::ostringstream out;
  out << "# HELP sweetspot_connections Open connections by state (admitted ones count against "
         "max_connections).\n"
      << "# TYPE sweetspot_connections gauge\n"
      << "sweetspot_connections{state=\"admitted\"} " << m.admitted.load() << "\n"
      << "sweetspot_connections{state=\"idle\"} " << m.idle_gauge.load() << "\n"
      << "sweetspot_connections{state=\"reading\"} " << m.reading_gauge.load() << "\n"
      << "sweetspot_connections{state=\"lingering\"} " << m.lingering.load() << "\n"
      << "# HELP sweetspot_unsent_bytes Answer bytes held for clients that read slower than "
         "they are answered (bounded per client address by max_unsent_bytes_per_client).\n"
      << "# TYPE sweetspot_unsent_bytes gauge\n"
      << "sweetspot_unsent_bytes " << m.UnsentBytes() << "\n"
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
  const int light_size = std::max(1, m.options.light_workers);
  const int compute_size = std::max(1, m.options.compute_workers);
  out << "# HELP sweetspot_workers Worker threads per pool.\n# TYPE sweetspot_workers gauge\n"
      << "sweetspot_workers{pool=\"light\"} " << light_size << "\n"
      << "sweetspot_workers{pool=\"compute\"} " << compute_size << "\n"
      << "# HELP sweetspot_workers_busy Workers answering a request now, per pool.\n"
      << "# TYPE sweetspot_workers_busy gauge\n"
      << "sweetspot_workers_busy{pool=\"light\"} " << m.light_busy.busy() << "\n"
      << "sweetspot_workers_busy{pool=\"compute\"} " << m.compute_busy.busy() << "\n"
      << "# HELP sweetspot_workers_busy_peak The most workers answering at once since the "
         "start, per pool.\n"
      << "# TYPE sweetspot_workers_busy_peak gauge\n"
      << "sweetspot_workers_busy_peak{pool=\"light\"} " << m.light_busy.peak() << "\n"
      << "sweetspot_workers_busy_peak{pool=\"compute\"} " << m.compute_busy.peak() << "\n"
      << "# HELP sweetspot_requests_queued Complete requests waiting for a compute worker.\n"
      << "# TYPE sweetspot_requests_queued gauge\n"
      << "sweetspot_requests_queued{pool=\"compute\"} " << (m.compute ? m.compute->queued() : 0)
      << "\n"
      << "# HELP sweetspot_pool_requests_total Requests answered, per pool.\n"
      << "# TYPE sweetspot_pool_requests_total counter\n"
      << "sweetspot_pool_requests_total{pool=\"light\"} " << m.light_busy.served() << "\n"
      << "sweetspot_pool_requests_total{pool=\"compute\"} " << m.compute_busy.served() << "\n";
  return out.str();
}

}  // namespace sweetspot::server
