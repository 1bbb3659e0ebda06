// The plain 2D point every module shares.
#pragma once

#include "core/base/hd.hpp"

namespace galpha {

/// A point in the plane, in the caller's units.
struct Point2 {
  double x;
  double y;
};

GALPHA_HD inline bool operator==(const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }

/// Lexicographic order (x, then y): the order duplicates are found in.
GALPHA_HD inline bool LexLess(const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

}  // namespace galpha
