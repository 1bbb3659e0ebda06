// The exact radii of alpha_family_fixture.hpp.
#include "tests/gpu/alpha/alpha_family_fixture.hpp"

#include "core/exact/radius_rational.hpp"

namespace galpha::testing {

mpq_class TriangleRhoSq(const AlphaFamily& f, uint32_t t) {
  const Point2 p[3] = {f.points()[f.triangles()[t][0]], f.points()[f.triangles()[t][1]],
                       f.points()[f.triangles()[t][2]]};
  return *RadiusSqRational(p, 3);
}

mpq_class EdgeRhoSq(const AlphaFamily& f, uint32_t e) {
  const Point2 p[2] = {f.points()[f.edges()[e][0]], f.points()[f.edges()[e][1]]};
  return *RadiusSqRational(p, 2);
}

mpq_class ExactThreshold(const AlphaFamily& f, int64_t rank) {
  const uint32_t id = f.ranks().spectrum_simplex[static_cast<size_t>(rank - 1)];
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  return id < num_tri ? TriangleRhoSq(f, id) : EdgeRhoSq(f, id - num_tri);
}

}  // namespace galpha::testing
