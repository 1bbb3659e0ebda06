// What the alpha_family_test files share: the backend fixture with a Build helper, and the exact
// radii of the family's simplices.
#pragma once

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/family/alpha_family.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "tests/support/backend_fixture.hpp"

namespace galpha::testing {

using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

/// BackendTest that builds families on its backend.
class AlphaFamilyTest : public BackendTest {
 protected:
  absl::StatusOr<AlphaFamily> Build(const std::vector<Point2>& points) const {
    BuildOptions options;
    options.backend = GetParam();
    return BuildAlphaFamily(points, options);
  }
};

/// A named input.
struct Case {
  std::string name;
  std::vector<Point2> points;
};

/// Exact rho^2 of a triangle or an edge of the family.
mpq_class TriangleRhoSq(const AlphaFamily& f, uint32_t t);
mpq_class EdgeRhoSq(const AlphaFamily& f, uint32_t e);

/// The exact threshold of rank r (1..K), recomputed from the simplex the family names for it.
mpq_class ExactThreshold(const AlphaFamily& f, int64_t rank);

inline Tri SortedTri(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace galpha::testing
