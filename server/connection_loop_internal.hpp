// The connection loop's private parts (server/connection_loop.hpp is its interface): the
// helpers, a connection's state, the pools, and ConnectionLoop::Impl with every member it has.
// Its member functions are defined in three files, along the life of a connection:
//   connection_loop.cpp          the interface; the registry, epoll, closing and accepting
//   connection_loop_serve.cpp    reading and framing a request, answering it, writing the answer
//   connection_loop_threads.cpp  the light and compute workers, and the deadlines (Run's thread)
// Included only by those three, which are compiled alone (not in unity batches, whose
// neighbours would see the using-directive each of them starts with).
#pragma once

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

namespace sweetspot::server::loop_internal {

using Clock = std::chrono::steady_clock;

// How often deadlines are checked, and so how late past its deadline a slow
// connection may be closed.
inline constexpr auto kConnectionSweepInterval = std::chrono::milliseconds(25);
// Bytes read from a socket per recv.
inline constexpr std::size_t kReadChunk = 64 * 1024;

inline Clock::duration Seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

inline const char* StatusText(int status) {
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
inline void AddressOf(const sockaddr_storage& addr, std::string* ip, int* port) {
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

inline std::string FormatSeconds(double s) {
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

inline constexpr std::array<const char*, static_cast<int>(Reason::kCount)> kReasonNames = {
    "over_limit",        "header_timeout",     "body_too_slow",   "read_timeout",
    "head_too_large",    "bad_request",        "keep_alive_idle", "write_timeout",
    "over_client_limit", "first_byte_timeout", "client_gone",     "unsent_over_limit"};

// True when the client of `fd` closed its side (or the socket failed) and sent nothing
// more that is still unread: nobody will read an answer. Never blocks.
inline bool PeerGone(int fd) {
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
inline constexpr std::uint64_t kListenTag = 0;
inline constexpr std::uint64_t kWakeTag = 1;

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
}  // namespace sweetspot::server::loop_internal

namespace sweetspot::server {

struct ConnectionLoop::Impl {
  using Clock = loop_internal::Clock;
  using Connection = loop_internal::Connection;
  using ConnectionPtr = loop_internal::ConnectionPtr;
  using State = loop_internal::State;
  using Reason = loop_internal::Reason;
  using BusyCounter = loop_internal::BusyCounter;
  using ComputePool = loop_internal::ComputePool;

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
  std::atomic<bool> draining{false};      // BeginDrain(): answers carry Connection: close
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
  ConnectionPtr Find(std::uint64_t id);

  std::vector<ConnectionPtr> Snapshot();

  // ------------------------------------------------------------ epoll
  // Waits for the next bytes of `c` (one event, then disarmed until re-armed).
  void Arm(Connection& c);

  // ------------------------------------------------------------ closing (c.mutex held)
  void Close(Connection& c);

  // `n` of the bytes `c` has parked were sent or dropped (map_mutex held).
  void Unpark(Connection& c, std::size_t n);

  // The unsent answer bytes held for every client.
  std::size_t UnsentBytes() const;

  // Counts the rest of c's answer against its client's budget of unsent bytes; false (and
  // nothing counted) when it would exceed max_unsent_bytes_per_client.
  bool Park(Connection& c);

  // `c` no longer counts against max_connections and its client's limit (map_mutex held).
  void ReleaseAdmission(Connection& c);

  // Half-closes `c` and drains it until the client closes or linger_s passes,
  // so that the client reads what was sent instead of a reset.
  void Linger(Connection& c, Clock::time_point now);

  // Answers `c` with an error envelope of its own, then lingers.
  void Refuse(Connection& c, int status, api::ErrorCode code, Reason reason,
              const std::string& message, Clock::time_point now);

  // ------------------------------------------------------------ accepting
  void Accept();

  // ------------------------------------------------------------ reading (c.mutex held)
  // Reads what the socket has (up to the largest request, plus one chunk).
  // Returns false when the peer closed its side or failed.
  bool Receive(Connection& c, Clock::time_point now);

  enum class Step {
    kWait,     // armed again, or closed, or lingering: nothing more to do now
    kRequest,  // a complete request is framed (state kWorking): answer it
  };

  // Waits for more of the current request, unless the client can send no more.
  Step AwaitMore(Connection& c);

  // Moves `c` on with what it has received: frames the head, waits for the
  // body, and says when a complete request is there.
  Step Advance(Connection& c, Clock::time_point now);

  Step Framed(Connection& c);

  // ------------------------------------------------------------ answering (c.mutex held)
  // Answers the framed request of `c` with httplib; sets c.keep_open.
  void Answer(Connection& c, BusyCounter& busy, RequestCancel* cancel = nullptr);

  // Answers the framed request of `c` on a compute worker, with a cancel flag the deadline
  // keeper sets (client gone, max_request_time_s, shutdown). A request whose client left
  // while it was queued is dropped; once the server stops, one still queued is refused.
  // True once the server stops and the requests in flight have had their grace.
  bool GraceOver(Clock::time_point now) const;

  void AnswerCompute(Connection& c);

  // The deadline keeper's look at a request being answered (`c` held by its worker): sets
  // its cancel flag when the client left, its time is up, or the server stops.
  void CheckWorking(Connection& c, Clock::time_point now, bool shutting_down);

  // After an answer: closes (lingering) or goes back to waiting. Returns true
  // when `c` waits for its next request (Advance may find one already in).
  bool AfterAnswer(Connection& c, Clock::time_point now);

  // The socket of a kWriting connection takes more: send what it takes; once
  // the answer is out, go on as after any answer. Returns true when `c` waits
  // for its next request.
  bool Writable(Connection& c, Clock::time_point now);

  // Handles `c` until it waits for bytes, is closed, or went to the compute
  // pool: answers each complete request, one after another for a client that
  // pipelines.
  void Drive(const ConnectionPtr& c, std::unique_lock<std::mutex>& lock, Clock::time_point now,
             Pool pool);

  // ------------------------------------------------------------ the threads
  void LightWorker();

  void ComputeWorker(ConnectionPtr c);

  // ------------------------------------------------------------ deadlines (Run's thread)
  void Sweep(Clock::time_point now);

  void ExpireHead(Connection& c, Clock::time_point now);

  void ExpireBody(Connection& c, Clock::time_point now);

  // 408 for a request that sent nothing for read_timeout_s, in its head or body (`part`).
  void RefuseSilent(Connection& c, const char* part, Clock::time_point now);

  // Stop: closes every connection that is not being answered (those close
  // themselves after their answer; answers still being sent get their write
  // timeout). Returns how many connections remain.
  std::size_t CloseWaiting(Clock::time_point now);
};

}  // namespace sweetspot::server
