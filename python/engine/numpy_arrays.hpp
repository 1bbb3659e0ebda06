// NumPy arrays over C++ memory, without copies: a vector handed over to the array (a capsule owns
// it and is the array's base), or a read-only view into a family's own arrays (the capsule keeps
// the family alive as long as any view of it lives, released or not).
#pragma once

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "python/engine/family_state.hpp"

namespace galpha::python {

/// A C-contiguous array of `shape` taking over `values` (whose size is the shape's product).
template <class T>
pybind11::array_t<T> ArrayFromVector(std::vector<T>&& values, std::vector<pybind11::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  pybind11::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return pybind11::array_t<T>(std::move(shape), owned->data(), owner);
}

/// A one-dimensional array taking over `values`.
template <class T>
pybind11::array_t<T> ArrayFromVector(std::vector<T>&& values) {
  const auto n = static_cast<pybind11::ssize_t>(values.size());
  return ArrayFromVector(std::move(values), {n});
}

/// A read-only, C-contiguous view of `shape` at `data`, memory that `state` owns. Read-only because
/// every answer of the family shares it.
template <class T>
pybind11::array_t<T> ReadOnlyView(const T* data, std::vector<pybind11::ssize_t> shape,
                                  std::shared_ptr<const FamilyState> state) {
  auto* owned = new std::shared_ptr<const FamilyState>(std::move(state));
  pybind11::capsule owner(owned, [](void* p) { delete static_cast<std::shared_ptr<const FamilyState>*>(p); });
  pybind11::array_t<T> view(std::move(shape), data, owner);
  view.attr("setflags")(pybind11::arg("write") = false);
  return view;
}

}  // namespace galpha::python
