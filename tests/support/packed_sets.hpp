// Point sets packed one after the other with their offsets, as TriangulateSets and
// BuildAlphaFamilies take them, and the names a failure prints (header only).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha::testing {

struct SetsToPack {
  std::vector<std::string> names;
  std::vector<Point2> points;
  std::vector<uint32_t> set_begin{0};

  void Add(std::string name, const std::vector<Point2>& set) {
    names.push_back(std::move(name));
    points.insert(points.end(), set.begin(), set.end());
    set_begin.push_back(static_cast<uint32_t>(points.size()));
  }
  /// Set s's points.
  absl::Span<const Point2> Set(size_t s) const {
    return absl::Span<const Point2>(points.data() + set_begin[s], set_begin[s + 1] - set_begin[s]);
  }
};

}  // namespace galpha::testing
