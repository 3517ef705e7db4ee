// Settings compared as a whole: a settings structure lists its fields once, in a member
// fields() (a std::tie of them all), and namesEveryField checks at compile time that the
// list holds every field, so that a field added later cannot be left out of a comparison.
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

namespace jle {
namespace detail {

// Converts to any field's type: T{AnyField{}, ...} with n of them compiles while T, an
// aggregate, has at least n fields.
struct AnyField {
  template <class T>
  constexpr operator T() const noexcept {  // NOLINT(google-explicit-constructor)
    return T{};
  }
};

template <class T, class Indices, class = void>
struct BracedWith : std::false_type {};
template <class T, std::size_t... I>
struct BracedWith<T, std::index_sequence<I...>,
                  std::void_t<decltype(T{(static_cast<void>(I), AnyField{})...})>>
    : std::true_type {};

template <class T, std::size_t N = 0>
constexpr std::size_t fieldCount() {
  if constexpr (BracedWith<T, std::make_index_sequence<N + 1>>::value) {
    return fieldCount<T, N + 1>();
  } else {
    return N;
  }
}

}  // namespace detail

/// Whether T::fields() names as many fields as the aggregate T has (fields of scalar,
/// enum or string type: a nested aggregate would be counted by its own fields).
template <class T>
constexpr bool namesEveryField() {
  static_assert(std::is_aggregate_v<T>, "namesEveryField: T must be an aggregate");
  return detail::fieldCount<T>() == std::tuple_size_v<decltype(std::declval<const T&>().fields())>;
}

}  // namespace jle
