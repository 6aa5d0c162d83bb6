// The connection loop's threads: the light workers (accept, read, answer cheap requests), the
// compute workers, and the deadline keeper on Run's thread (timeouts, cancels, shutdown).
#include "server/connection_loop_internal.hpp"

namespace sweetspot::server {

// The loop's helpers and types (this file is compiled alone: server/CMakeLists.txt).
using namespace loop_internal;  // NOLINT(build/namespaces)

void ConnectionLoop::Impl::LightWorker() {
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

void ConnectionLoop::Impl::ComputeWorker(ConnectionPtr c) {
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

void ConnectionLoop::Impl::Sweep(Clock::time_point now) {
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

void ConnectionLoop::Impl::ExpireHead(Connection& c, Clock::time_point now) {
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

void ConnectionLoop::Impl::ExpireBody(Connection& c, Clock::time_point now) {
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

void ConnectionLoop::Impl::RefuseSilent(Connection& c, const char* part, Clock::time_point now) {
  Refuse(c, 408, api::ErrorCode::kTimeout, Reason::kReadTimeout,
         std::string("no byte of the request ") + part + " arrived for read_timeout_s = " +
             FormatSeconds(options.read_timeout_s) + " s (read timeout)",
         now);
}

std::size_t ConnectionLoop::Impl::CloseWaiting(Clock::time_point now) {
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

}  // namespace sweetspot::server
