#include "api/thread_budget.hpp"

#include <algorithm>
#include <condition_variable>
#include <mutex>

namespace sweetspot::api {

struct ThreadBudget::Impl {
  std::mutex mutex;
  std::condition_variable freed;
  int capacity = 0;
  int taken = 0;
};

ThreadBudget::ThreadBudget(int threads) : impl_(std::make_unique<Impl>()) {
  impl_->capacity = std::max(0, threads);
}

ThreadBudget::~ThreadBudget() = default;

int ThreadBudget::TryTake(int wanted) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const int granted = std::max(0, std::min(wanted, impl_->capacity - impl_->taken));
  impl_->taken += granted;
  return granted;
}

void ThreadBudget::TakeOne() {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  impl_->freed.wait(lock, [this] { return impl_->taken < impl_->capacity; });
  ++impl_->taken;
}

void ThreadBudget::Give(int threads) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->taken = std::max(0, impl_->taken - threads);
  }
  impl_->freed.notify_all();
}

int ThreadBudget::taken() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->taken;
}

}  // namespace sweetspot::api
