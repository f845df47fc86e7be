// A value or a named error: the subset of C++23 std::expected that wircam
// needs, spelled the same way so the switch to <expected> is a rename.
#pragma once

#include <type_traits>
#include <utility>
#include <variant>

namespace wircam {

template <typename E>
struct Unexpected {
  E error;
};

template <typename E>
Unexpected<E> unexpected(E error) {
  return Unexpected<E>{std::move(error)};
}

template <typename T, typename E>
class Expected {
 public:
  Expected(T value) : storage_(std::in_place_index<0>, std::move(value)) {}
  Expected(Unexpected<E> failure) : storage_(std::in_place_index<1>, std::move(failure.error)) {}
  // unexpected("text") where E is std::string, as std::expected allows.
  template <typename U>
  requires(!std::is_same_v<U, E> && std::is_constructible_v<E, U>) Expected(Unexpected<U> failure)
      : storage_(std::in_place_index<1>, E(std::move(failure.error))) {}

  bool has_value() const { return storage_.index() == 0; }
  explicit operator bool() const { return has_value(); }

  T& value() & { return std::get<0>(storage_); }
  const T& value() const& { return std::get<0>(storage_); }
  T&& value() && { return std::get<0>(std::move(storage_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const E& error() const { return std::get<1>(storage_); }

 private:
  std::variant<T, E> storage_;
};

}  // namespace wircam
