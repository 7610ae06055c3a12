#include "ui/rate_limiter.hpp"

#include <algorithm>

namespace orthoflow::ui {

namespace {
double refilled(double tokens, std::int64_t elapsed_ns, double rate, double burst) {
  return std::min(
      burst, tokens + static_cast<double>(std::max<std::int64_t>(elapsed_ns, 0)) * 1e-9 * rate);
}
}  // namespace

bool RateLimiter::allow(std::string_view client, std::int64_t now_ns) {
  std::lock_guard<std::mutex> guard(lock_);
  auto it = buckets_.find(std::string(client));
  if (it == buckets_.end()) {
    if (buckets_.size() >= limit_.max_clients) forget_idle(now_ns);
    if (buckets_.size() >= limit_.max_clients) return false;  // every known client is busy
    it = buckets_.emplace(std::string(client), Bucket{limit_.burst, now_ns}).first;
  }
  Bucket& b = it->second;
  b.tokens = refilled(b.tokens, now_ns - b.stamp_ns, limit_.rate_per_s, limit_.burst);
  b.stamp_ns = now_ns;
  if (b.tokens < 1.0) return false;
  b.tokens -= 1.0;
  return true;
}

std::size_t RateLimiter::clients() const {
  std::lock_guard<std::mutex> guard(lock_);
  return buckets_.size();
}

// A bucket that has refilled to the burst is the same as a new one: dropping it loses nothing.
void RateLimiter::forget_idle(std::int64_t now_ns) {
  std::erase_if(buckets_, [&](const auto& entry) {
    return refilled(entry.second.tokens, now_ns - entry.second.stamp_ns, limit_.rate_per_s,
                    limit_.burst) >= limit_.burst;
  });
}

}  // namespace orthoflow::ui
