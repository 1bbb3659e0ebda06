// galpha._engine.Family: a built family's answers as NumPy arrays and plain Python values (dicts,
// tuples), the same as the galpha service's (family_answers.hpp). Each call copies the family's
// shared pointer under the GIL and then computes with the GIL released, so that release() in one
// thread never pulls the family from under a query in another.
#pragma once

#include <memory>

#include <pybind11/pybind11.h>

#include "python/engine/family_state.hpp"

namespace galpha::python {

/// The Python object: the family, until release() drops this reference to it.
class FamilyObject {
 public:
  explicit FamilyObject(std::shared_ptr<const FamilyState> state) : state_(std::move(state)) {}
  /// The family; NotFound once released.
  std::shared_ptr<const FamilyState> state() const;
  /// Drops the family (arrays already returned keep what they view); true when it was held.
  bool Release();

 private:
  std::shared_ptr<const FamilyState> state_;
};

/// Defines galpha._engine.Family on `module`.
void RegisterFamily(pybind11::module_& module);

}  // namespace galpha::python
