#include "core/family/classification_summary.hpp"

#include "core/exact/predicates.hpp"

namespace galpha {

ClassificationSummary SummarizeClassification(const AlphaFamily& family, const Classification& classes) {
  return SummarizeClassification(family.points(), family.representative(), family.triangles(), classes);
}

ClassificationSummary SummarizeClassification(const HostVector<Point2>& p, const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& mesh_triangles,
                                              const Classification& classes) {
  ClassificationSummary summary;
  uint64_t* vertices = summary.vertices.data();
  uint64_t* edges = summary.edges.data();
  uint64_t* triangles = summary.triangles.data();
  const int64_t nv = static_cast<int64_t>(classes.vertices.size()), ne = static_cast<int64_t>(classes.edges.size()),
                nt = static_cast<int64_t>(classes.triangles.size());
  // Counts are sums of integers: any order gives the same answer, so the cores share them.
#pragma omp parallel
  {
#pragma omp for schedule(static) reduction(+ : vertices[:4]) nowait
    for (int64_t v = 0; v < nv; ++v) {
      if (representative[v] == v) ++vertices[static_cast<size_t>(classes.vertices[v])];
    }
#pragma omp for schedule(static) reduction(+ : edges[:4]) nowait
    for (int64_t e = 0; e < ne; ++e) ++edges[static_cast<size_t>(classes.edges[e])];
#pragma omp for schedule(static) reduction(+ : triangles[:4]) nowait
    for (int64_t t = 0; t < nt; ++t) ++triangles[static_cast<size_t>(classes.triangles[t])];
  }
  // The area is a floating-point sum: in triangle order, one thread, as AssembleShape sums it.
  for (uint32_t t = 0; t < classes.triangles.size(); ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) {
      const auto& tri = mesh_triangles[t];
      summary.interior_area += 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
    }
  }
  return summary;
}

}  // namespace galpha
