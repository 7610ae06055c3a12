#pragma once
/// @file
/// @brief The bug channel (STYLE rule 9): OF_ENFORCE in all builds, OF_ASSERT in debug builds.
/// A failed check prints where and why to stderr and aborts: it marks a programming error, never
/// bad input.

namespace orthoflow::core {
/// @brief Prints "file:line: check failed: expr (message)" to stderr and aborts. Never returns.
[[noreturn]] void enforce_failed(const char* file, int line, const char* expr,
                                 const char* message) noexcept;
}  // namespace orthoflow::core

#define OF_ENFORCE(cond, message)                                              \
  do {                                                                         \
    if (!(cond)) [[unlikely]] {                                                \
      ::orthoflow::core::enforce_failed(__FILE__, __LINE__, #cond, (message)); \
    }                                                                          \
  } while (false)

#ifdef NDEBUG
#define OF_ASSERT(cond, message) \
  do {                           \
  } while (false)
#else
#define OF_ASSERT(cond, message) OF_ENFORCE(cond, message)
#endif
