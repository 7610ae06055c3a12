#pragma once
/// @file
/// @brief orthoflow::Result<T, E>: the recoverable-failure channel (STYLE rule 9).
/// Lives in core/, the shared vocabulary every other target links.
#include <type_traits>
#include <utility>
#include <variant>

#include "core/assert.hpp"

namespace orthoflow {

/// @brief Wraps an error value so that Result can be built from it unambiguously.
template <class E>
struct Unexpected {
  E error;
};

/// @brief Makes an Unexpected from an error value: `return orthoflow::err(Error::X);`
template <class E>
[[nodiscard]] Unexpected<std::decay_t<E>> err(E&& error) {
  return Unexpected<std::decay_t<E>>{std::forward<E>(error)};
}

/// @brief Holds either a value of type T or an error of type E.
/// @note Accessing the wrong alternative is a bug and aborts through OF_ENFORCE.
template <class T, class E>
class [[nodiscard]] Result {
 public:
  Result(T value)
      : storage_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  template <class U>
  requires std::is_constructible_v<E, U> Result(Unexpected<U> error)
      : storage_(std::in_place_index<1>, std::move(error.error)) {}  // NOLINT

  [[nodiscard]] bool has_value() const noexcept { return storage_.index() == 0; }
  explicit operator bool() const noexcept { return has_value(); }

  [[nodiscard]] T& value() & {
    OF_ENFORCE(has_value(), "Result::value() called on an error");
    return std::get<0>(storage_);
  }
  [[nodiscard]] const T& value() const& {
    OF_ENFORCE(has_value(), "Result::value() called on an error");
    return std::get<0>(storage_);
  }
  [[nodiscard]] T&& value() && {
    OF_ENFORCE(has_value(), "Result::value() called on an error");
    return std::get<0>(std::move(storage_));
  }
  [[nodiscard]] const E& error() const& {
    OF_ENFORCE(!has_value(), "Result::error() called on a value");
    return std::get<1>(storage_);
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

 private:
  std::variant<T, E> storage_;
};

/// @brief Result of an operation that yields no value.
template <class E>
class [[nodiscard]] Result<void, E> {
 public:
  Result() = default;
  template <class U>
  requires std::is_constructible_v<E, U> Result(Unexpected<U> error)
      : error_(std::move(error.error)), failed_(true) {}  // NOLINT

  [[nodiscard]] bool has_value() const noexcept { return !failed_; }
  explicit operator bool() const noexcept { return has_value(); }
  [[nodiscard]] const E& error() const& {
    OF_ENFORCE(failed_, "Result::error() called on a value");
    return error_;
  }

 private:
  E error_{};
  bool failed_ = false;
};

}  // namespace orthoflow
