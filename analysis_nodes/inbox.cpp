#include "inbox.hpp"

#include <algorithm>

namespace dynhet {

Inbox::Inbox(int64_t hard_cap) {
  s_.hard_cap = hard_cap;
  s_.bound = hard_cap;
}

bool Inbox::push(Message m, bool bulk, bool wait) {
  const int64_t c = cost(m);
  std::unique_lock<std::mutex> lock(mu_);
  if (wait) not_full_.wait(lock, [&] { return stopped_ || fits(c, bulk); });
  if (stopped_ || !fits(c, bulk)) {
    ++s_.dropped;
    s_.dropped_bytes += c;
    return false;
  }
  q_.push_back(std::move(m));
  s_.queued_bytes += c;
  s_.peak_bytes = std::max(s_.peak_bytes, s_.queued_bytes);
  lock.unlock();
  not_empty_.notify_one();
  return true;
}

void Inbox::close() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
  }
  not_empty_.notify_all();
}

void Inbox::receive_turn(double seconds) {
  std::lock_guard<std::mutex> lock(mu_);
  s_.longest_receive_gap = std::max(s_.longest_receive_gap, seconds);
}

std::optional<Inbox::Message> Inbox::pop(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mu_);
  if (!not_empty_.wait_for(lock, timeout, [&] { return !q_.empty() || closed_; }) || q_.empty())
    return std::nullopt;
  Message m = std::move(q_.front());
  q_.pop_front();
  s_.queued_bytes -= cost(m);
  lock.unlock();
  not_full_.notify_all();
  return m;
}

bool Inbox::ended() const {
  std::lock_guard<std::mutex> lock(mu_);
  return closed_ && q_.empty();
}

void Inbox::set_bound(int64_t bytes) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    s_.bound = std::min(bytes, s_.hard_cap);
  }
  not_full_.notify_all();
}

void Inbox::stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopped_ = true;
  }
  not_full_.notify_all();
}

Inbox::Stats Inbox::stats() const {
  std::lock_guard<std::mutex> lock(mu_);
  return s_;
}

} // namespace dynhet
