#include "tests/support/gudhi_persistence_oracle.hpp"

#include <CGAL/Epeck_d.h>
#include <gudhi/Alpha_complex.h>
#include <gudhi/Persistent_cohomology.h>
#include <gudhi/Simplex_tree.h>

#include <limits>
#include <vector>

namespace galpha::testing {

GudhiDiagram GudhiAlphaPersistence(absl::Span<const Point2> points) {
  using Kernel = CGAL::Epeck_d<CGAL::Dimension_tag<2>>;
  using PointD = Kernel::Point_d;
  using SimplexTree = Gudhi::Simplex_tree<>;
  using Field = Gudhi::persistent_cohomology::Field_Zp;
  using Cohomology = Gudhi::persistent_cohomology::Persistent_cohomology<SimplexTree, Field>;

  std::vector<PointD> input;
  input.reserve(points.size());
  for (const Point2& p : points) input.emplace_back(p.x, p.y);
  Gudhi::alpha_complex::Alpha_complex<Kernel> alpha(input);
  SimplexTree tree;
  GudhiDiagram out;
  if (!alpha.create_complex(tree, std::numeric_limits<double>::infinity(), /*exact=*/true)) return out;
  out.num_simplices = tree.num_simplices();
  Cohomology cohomology(tree);
  cohomology.init_coefficients(2);
  cohomology.compute_persistent_cohomology(/*min_interval_length=*/0.0);
  for (int dimension = 0; dimension < 2; ++dimension) {
    out.intervals[dimension] = cohomology.intervals_in_dimension(dimension);
  }
  return out;
}

}  // namespace galpha::testing
