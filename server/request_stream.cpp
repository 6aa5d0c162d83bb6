#include "server/request_stream.hpp"

#include <poll.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <sys/uio.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace sweetspot::server {
namespace {

thread_local RequestStream* current_stream = nullptr;

int MillisecondsLeft(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
      deadline - std::chrono::steady_clock::now());
  return static_cast<int>(std::max<long long>(0, left.count()));
}

}  // namespace

RequestStream::RequestStream(int fd, std::string_view request, double write_timeout_s,
                             const std::string& remote_ip, int remote_port,
                             const std::string& local_ip, int local_port)
    : fd_(fd),
      request_(request),
      write_timeout_(write_timeout_s),
      remote_ip_(remote_ip),
      remote_port_(remote_port),
      local_ip_(local_ip),
      local_port_(local_port),
      previous_current_(current_stream) {
  current_stream = this;
}

RequestStream::~RequestStream() { current_stream = previous_current_; }

RequestStream* RequestStream::Current() { return current_stream; }

bool RequestStream::is_readable() const { return read_at_ < request_.size(); }

bool RequestStream::is_writable() const {
  if (!healthy_) return false;
  pollfd p{fd_, POLLOUT, 0};
  const int ms = static_cast<int>(
      std::chrono::duration_cast<std::chrono::milliseconds>(write_timeout_).count());
  return ::poll(&p, 1, ms) == 1 && (p.revents & (POLLERR | POLLHUP | POLLNVAL)) == 0;
}

ssize_t RequestStream::read(char* ptr, size_t size) {
  const std::size_t n = std::min(size, request_.size() - read_at_);
  std::memcpy(ptr, request_.data() + read_at_, n);
  read_at_ += n;
  return static_cast<ssize_t>(n);  // 0 at the end of the request: httplib reads no further
}

ssize_t RequestStream::write(const char* ptr, size_t size) {
  if (!healthy_) return -1;
  if (defer_next_write_) {
    // The rest of the body comes from deferred_ (DeferBody): its bytes are not at ptr.
    defer_next_write_ = false;
    deferred_end_ = deferred_begin_ + size;
    return static_cast<ssize_t>(size);
  }
  if (write_through_) {
    if (!Flush() || !Send(ptr, size)) return -1;
    return static_cast<ssize_t>(size);
  }
  out_.append(ptr, size);  // the whole answer: httplib holds its body in memory already
  return static_cast<ssize_t>(size);
}

bool RequestStream::Flush() {
  if (out_.empty()) return healthy_;
  const bool sent = Send(out_.data(), out_.size());
  out_.clear();
  return sent;
}

void RequestStream::SetAnswer(std::string head, std::string body) {
  if (out_.empty()) {
    out_ = std::move(head);
  } else {
    out_ += head;
  }
  body_ = std::move(body);
}

bool RequestStream::SendWithoutWaiting(std::string* unsent) {
  // out_, then body_ (SetAnswer): one writev for both, no copy of the body.
  const std::size_t total = out_.size() + body_.size();
  std::size_t at = 0;
  while (healthy_ && at < total) {
    iovec parts[2];
    int count = 0;
    if (at < out_.size()) parts[count++] = {out_.data() + at, out_.size() - at};
    const std::size_t body_at = at > out_.size() ? at - out_.size() : 0;
    if (body_at < body_.size()) parts[count++] = {body_.data() + body_at, body_.size() - body_at};
    msghdr message{};
    message.msg_iov = parts;
    message.msg_iovlen = static_cast<std::size_t>(count);
    const ssize_t n = ::sendmsg(fd_, &message, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      at += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      break;
    } else {
      healthy_ = false;
    }
  }
  unsent->clear();
  if (healthy_ && at < total) {
    if (at < out_.size()) unsent->assign(out_, at, std::string::npos);
    unsent->append(body_, at > out_.size() ? at - out_.size() : 0, std::string::npos);
  }
  out_.clear();
  body_.clear();
  return healthy_;
}

void RequestStream::WriteThrough() { write_through_ = true; }

bool RequestStream::DeferBody(std::shared_ptr<const api::BodySource> source,
                              std::uint64_t offset) {
  if (write_through_ || !healthy_) return false;
  deferred_ = std::move(source);
  deferred_begin_ = deferred_end_ = offset;
  defer_next_write_ = true;
  return true;
}

std::shared_ptr<const api::BodySource> RequestStream::TakeDeferred(std::uint64_t* begin,
                                                                   std::uint64_t* end) {
  *begin = deferred_begin_;
  *end = deferred_end_;
  defer_next_write_ = false;
  if (deferred_end_ <= deferred_begin_) deferred_.reset();
  return std::move(deferred_);
}

bool RequestStream::Send(const char* data, std::size_t size) {
  if (!healthy_) return false;
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(write_timeout_);
  while (size > 0) {
    const ssize_t n = ::send(fd_, data, size, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      data += n;
      size -= static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      pollfd p{fd_, POLLOUT, 0};
      const int ms = MillisecondsLeft(deadline);
      if (ms > 0 && ::poll(&p, 1, ms) == 1 && (p.revents & POLLOUT) != 0) continue;
    }
    healthy_ = false;  // peer gone, or slower than the write timeout
    return false;
  }
  return true;
}

void RequestStream::get_remote_ip_and_port(std::string& ip, int& port) const {
  ip = remote_ip_;
  port = remote_port_;
}

void RequestStream::get_local_ip_and_port(std::string& ip, int& port) const {
  ip = local_ip_;
  port = local_port_;
}

socket_t RequestStream::socket() const { return fd_ < FD_SETSIZE ? fd_ : 0; }

}  // namespace sweetspot::server
