#pragma once
/// @file
/// @brief What every UiBackend shares: the recent-events log (with when each category was last
/// taught through it) and the page's view of an object list payload.
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "engine/object_list_payload.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @brief Recent events kept for the page.
inline constexpr std::size_t MAX_UI_EVENTS = 32;

/// @brief A sender id for a command channel (answers go to every sender: each keeps its own):
/// random, never 0.
[[nodiscard]] std::uint64_t random_client_id();

/// @brief The objects of @p list (at most OBJECT_LIST_CAPACITY, whatever its count says).
[[nodiscard]] std::vector<ObjectView> object_views(const engine::ObjectListPayload& list);

/// @brief The last MAX_UI_EVENTS actions and their answers. Thread-safe.
class EventLog {
 public:
  /// @brief Adds @p action's event (teach / correct also mark the label taught now; forget clears
  /// it).
  void record(const UiAction& action, const UiAnswer& answer);
  /// @brief The events, oldest first.
  [[nodiscard]] std::vector<EventView> events() const;
  /// @brief Unix ms of the last teach or correct of @p label through this log; 0 = none.
  [[nodiscard]] std::int64_t last_taught_ms(const std::string& label) const;

 private:
  mutable std::mutex lock_;
  std::deque<EventView> events_;                        // guarded by lock_
  std::map<std::string, std::int64_t> last_taught_ms_;  // guarded by lock_
  std::uint64_t next_event_ = 1;                        // guarded by lock_
};

}  // namespace orthoflow::ui
