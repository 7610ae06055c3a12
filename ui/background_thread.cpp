#include "ui/background_thread.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace orthoflow::ui {

namespace {
constexpr int BACKGROUND_NICE = 19;

id_t this_thread_id() noexcept { return static_cast<id_t>(::syscall(SYS_gettid)); }
}  // namespace

bool make_this_thread_background() noexcept {
  return ::setpriority(PRIO_PROCESS, this_thread_id(), BACKGROUND_NICE) == 0;
}

int this_thread_nice() noexcept { return ::getpriority(PRIO_PROCESS, this_thread_id()); }

}  // namespace orthoflow::ui
