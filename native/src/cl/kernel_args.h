// Binds a kernel's arguments in their order in one call, so no argument
// index is written by hand anywhere: bind_args(k, a, b, c) sets arguments
// 0, 1 and 2. Arguments that several kernels take in a row (the scene's
// material inputs, the shadow maps) travel as one ArgPack, which bind_args
// expands in place, so each such group is declared once, where its buffers
// live, and in the same order as the kernels' macro that lists it.
#pragma once

#include <tuple>
#include <type_traits>
#include <utility>

#include "cl/cl.h"

namespace mp {

template <typename... Args>
struct ArgPack {
  std::tuple<Args...> args;
};

template <typename... Args>
ArgPack<std::decay_t<Args>...> arg_pack(Args&&... args) {
  return {std::tuple<std::decay_t<Args>...>(std::forward<Args>(args)...)};
}

namespace detail {

template <typename T>
struct IsArgPack : std::false_type {};
template <typename... Args>
struct IsArgPack<ArgPack<Args...>> : std::true_type {};

template <typename T>
void bind_arg(cl::Kernel& kernel, cl_uint& index, const T& value) {
  if constexpr (IsArgPack<T>::value)
    std::apply([&](const auto&... packed) { (bind_arg(kernel, index, packed), ...); }, value.args);
  else
    kernel.setArg(index++, value);
}

}  // namespace detail

// The same from argument `first` on: a kernel whose first arguments stay
// bound (the scene's data, scene_kernel.h).
template <typename... Args>
void bind_args_from(cl::Kernel& kernel, cl_uint first, const Args&... args) {
  (detail::bind_arg(kernel, first, args), ...);
}

template <typename... Args>
void bind_args(cl::Kernel& kernel, const Args&... args) {
  bind_args_from(kernel, 0, args...);
}

}  // namespace mp
