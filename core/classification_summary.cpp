#include "core/classification_summary.hpp"

#include "core/predicates.hpp"

namespace galpha {

ClassificationSummary SummarizeClassification(const AlphaFamily& family, const Classification& classes) {
  ClassificationSummary summary;
  for (uint32_t v = 0; v < classes.vertices.size(); ++v) {
    if (family.representative()[v] == v) ++summary.vertices[static_cast<size_t>(classes.vertices[v])];
  }
  for (const SimplexClass c : classes.edges) ++summary.edges[static_cast<size_t>(c)];
  const auto& p = family.points();
  for (uint32_t t = 0; t < classes.triangles.size(); ++t) {
    ++summary.triangles[static_cast<size_t>(classes.triangles[t])];
    if (classes.triangles[t] == SimplexClass::kInterior) {
      const auto& tri = family.triangles()[t];
      summary.interior_area += 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
    }
  }
  return summary;
}

}  // namespace galpha
