#include "server/warm_up.hpp"

#include <cmath>
#include <cstddef>
#include <limits>

namespace galpha::server {
namespace {

/// `value` moved up by `ulps` representable doubles.
double NudgedUp(double value, int ulps) {
  for (int i = 0; i < ulps; ++i) value = std::nextafter(value, std::numeric_limits<double>::infinity());
  return value;
}

}  // namespace

WarmUpInput WarmUpLattice(int side) {
  WarmUpInput input;
  input.points.reserve(static_cast<size_t>(side) * static_cast<size_t>(side));
  input.weights.reserve(input.points.capacity());
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      // Away from the origin, so that an ulp is a relative perturbation of the lattice (1000 has
      // ulps of 2^-43), in a pattern that leaves no two rows or columns alike; the upper half of the
      // rows stays exact, so that exact ties (co-circular lattice squares) are proved too.
      const bool nudged = i < side / 2;
      input.points.push_back(Point2{NudgedUp(1000.0 + i, nudged ? (7 * i + 3 * j) % 4 : 0),
                                    NudgedUp(1000.0 + j, nudged ? (5 * i + 11 * j) % 4 : 0)});
      input.weights.push_back(i % 4 == 0 && j % 4 == 0 ? 3.0 : 0.0);
    }
  }
  return input;
}

}  // namespace galpha::server
