// What the radius tests share: a simplex as a value, its printout for failure messages, and a
// double moved by whole units in the last place.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/base/point.hpp"

namespace galpha::testing_support {

/// An edge (n = 2) or a triangle (n = 3).
struct Simplex {
  Point2 p[3];
  int n;
};

/// "(x, y) " per vertex, every digit a double needs.
inline std::string Show(const Simplex& s) {
  std::string out;
  char text[96];
  for (int i = 0; i < s.n; ++i) {
    std::snprintf(text, sizeof text, "(%.17g, %.17g) ", s.p[i].x, s.p[i].y);
    out += text;
  }
  return out;
}

/// v moved by n units in the last place (up for n > 0).
inline double Ulps(double v, int n) {
  for (int i = 0; i < std::abs(n); ++i) v = std::nextafter(v, n > 0 ? INFINITY : -INFINITY);
  return v;
}

}  // namespace galpha::testing_support
