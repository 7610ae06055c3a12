#pragma once
/// @file
/// @brief EventStream: pushes the state document (ui/ui_json.hpp) to every WebSocket client at the
/// rate that client chose, capped at the graph's frame rate (at most 30 Hz). One thread; a document
/// is made once per tick for all the clients due then. The transport is a write function, so the
/// stream is tested without sockets.
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @brief Thread-safe. Every client is removed before the write function's target goes away.
class EventStream {
 public:
  /// @brief Writes @p text to client @p client; false when it failed (the client is then skipped
  /// until removed).
  using Write = std::function<bool(void* client, std::string_view text)>;
  EventStream(UiBackend& backend, double max_hz, std::size_t max_clients, Write write);
  ~EventStream();
  EventStream(const EventStream&) = delete;
  EventStream& operator=(const EventStream&) = delete;

  /// @brief The rate a client asking for @p hz gets: min(hz, max_hz).
  [[nodiscard]] double clamp(double hz) const noexcept { return hz < max_hz_ ? hz : max_hz_; }
  /// @brief Adds @p client at clamp(@p hz); its first document goes out at once. With @p camera,
  /// each document it is due sends the backend want_camera() first.
  /// @return false when max_clients are streaming.
  bool add(void* client, double hz, bool camera = false);
  /// @brief Removes @p client; when it returns no write to it is in progress or will start.
  void remove(void* client);
  [[nodiscard]] std::size_t clients() const;
  [[nodiscard]] std::uint64_t sent() const;

 private:
  struct Client {
    void* id = nullptr;
    std::int64_t period_ns = 0;
    std::int64_t next_ns = 0;
    bool camera = false;
    bool failed = false;
  };
  void run();

  UiBackend& backend_;
  double max_hz_;
  std::size_t max_clients_;
  Write write_;
  mutable std::mutex lock_;  // held while writing, so remove() waits for a write in progress
  std::condition_variable wake_;
  std::vector<Client> clients_;
  std::uint64_t sent_ = 0;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace orthoflow::ui
