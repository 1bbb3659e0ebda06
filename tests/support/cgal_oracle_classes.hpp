// What both CGAL alpha-shape oracles (cgal_alpha_oracle.cpp, cgal_weighted_alpha_oracle.cpp) read
// the same way from their Alpha_shape_2: a classification as an OracleClass, and an edge as the
// ascending pair of its vertices' input indices (vertex info). For their .cpp files only, after
// CGAL's headers.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>

#include "tests/support/cgal_alpha_oracle.hpp"

namespace galpha::testing {

template <class Shape>
OracleClass OracleClassOf(typename Shape::Classification_type type) {
  switch (type) {
    case Shape::EXTERIOR:
      return OracleClass::kExterior;
    case Shape::SINGULAR:
      return OracleClass::kSingular;
    case Shape::REGULAR:
      return OracleClass::kRegular;
    case Shape::INTERIOR:
      return OracleClass::kInterior;
  }
  return OracleClass::kExterior;
}

template <class Shape>
std::pair<uint32_t, uint32_t> EdgeKeyOf(const typename Shape::Edge& edge) {
  const uint32_t a = edge.first->vertex(Shape::cw(edge.second))->info();
  const uint32_t b = edge.first->vertex(Shape::ccw(edge.second))->info();
  return {std::min(a, b), std::max(a, b)};
}

}  // namespace galpha::testing
