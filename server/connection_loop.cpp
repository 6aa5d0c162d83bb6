// The connection loop's interface (server/connection_loop.hpp), and what it keeps of its
// connections: the registry, epoll, closing (with lingering and refusals) and accepting.
#include "server/connection_loop_internal.hpp"

namespace sweetspot::server {

// The loop's helpers and types (this file is compiled alone: server/CMakeLists.txt).
using namespace loop_internal;  // NOLINT(build/namespaces)

ConnectionPtr ConnectionLoop::Impl::Find(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(map_mutex);
  const auto it = connections.find(id);
  return it == connections.end() ? nullptr : it->second;
}

std::vector<ConnectionPtr> ConnectionLoop::Impl::Snapshot() {
  std::lock_guard<std::mutex> lock(map_mutex);
  std::vector<ConnectionPtr> all;
  all.reserve(connections.size());
  for (const auto& [id, c] : connections) all.push_back(c);
  return all;
}

void ConnectionLoop::Impl::Arm(Connection& c) {
  epoll_event event{};
  event.events = (c.state == State::kWriting ? EPOLLOUT : EPOLLIN | EPOLLRDHUP) | EPOLLONESHOT;
  event.data.u64 = c.id;
  epoll_ctl(epoll_fd, EPOLL_CTL_MOD, c.fd, &event);
}

void ConnectionLoop::Impl::Close(Connection& c) {
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

void ConnectionLoop::Impl::Unpark(Connection& c, std::size_t n) {
  n = std::min(n, c.parked);
  if (n == 0) return;
  c.parked -= n;
  const auto it = parked_by_client.find(c.remote_ip);
  if (it == parked_by_client.end()) return;
  it->second -= std::min(n, it->second);
  if (it->second == 0) parked_by_client.erase(it);
}

std::size_t ConnectionLoop::Impl::UnsentBytes() const {
  std::lock_guard<std::mutex> lock(map_mutex);
  std::size_t total = 0;
  for (const auto& [address, bytes] : parked_by_client) total += bytes;
  return total;
}

bool ConnectionLoop::Impl::Park(Connection& c) {
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

void ConnectionLoop::Impl::ReleaseAdmission(Connection& c) {
  if (!c.admitted) return;
  c.admitted = false;
  admitted.fetch_sub(1, std::memory_order_relaxed);
  const auto it = per_client.find(c.remote_ip);
  if (it != per_client.end() && --it->second <= 0) per_client.erase(it);
}

void ConnectionLoop::Impl::Linger(Connection& c, Clock::time_point now) {
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

void ConnectionLoop::Impl::Refuse(Connection& c, int status, api::ErrorCode code, Reason reason,
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

void ConnectionLoop::Impl::Accept() {
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

void ConnectionLoop::BeginDrain() { impl_->draining.store(true); }

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
