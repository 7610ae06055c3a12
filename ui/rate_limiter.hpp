#pragma once
/// @file
/// @brief A token bucket per client address: a flood of requests from one client gets 429 and
/// costs the server a map look-up, never the frame path anything (the server does not touch the
/// graph for a refused request).
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>

namespace orthoflow::ui {

/// @brief Rate settings: @p rate_per_s tokens refill per second up to @p burst.
struct RateLimit {
  double rate_per_s = 20.0;
  double burst = 40.0;
  std::size_t max_clients = 1024;  ///< buckets kept; beyond, idle (full) buckets are dropped
};

/// @brief Thread-safe (one mutex, held for a look-up).
class RateLimiter {
 public:
  explicit RateLimiter(RateLimit limit) : limit_(limit) {}
  /// @brief Takes one token from @p client's bucket at time @p now_ns (steady clock).
  /// @return false when the bucket is empty (answer 429).
  [[nodiscard]] bool allow(std::string_view client, std::int64_t now_ns);
  [[nodiscard]] std::size_t clients() const;

 private:
  struct Bucket {
    double tokens = 0.0;
    std::int64_t stamp_ns = 0;
  };
  void forget_idle(std::int64_t now_ns);
  RateLimit limit_;
  mutable std::mutex lock_;
  std::unordered_map<std::string, Bucket> buckets_;
};

}  // namespace orthoflow::ui
