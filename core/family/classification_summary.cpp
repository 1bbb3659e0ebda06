#include "core/family/classification_summary.hpp"

#include <array>
#include <cstdint>
#include <vector>

#include "core/exact/predicates.hpp"

namespace galpha {

ClassificationSummary SummarizeClassification(const AlphaFamily& family, const Classification& classes) {
  return SummarizeClassification(family.points(), family.representative(), family.triangles(), classes);
}

namespace {

// Counts of each class among classes[i] for the i in [0, n) that `counted(i)` keeps, as four
// register sums of comparisons: a histogram's increments through memory serialize whenever a class
// repeats (most of a 1M-point summary's 17 ms on 2 cores). Sums of integers: any order, every core.
template <typename Counted>
std::array<uint64_t, 4> CountClasses(const SimplexClass* classes, int64_t n, Counted counted) {
  uint64_t c0 = 0, c1 = 0, c2 = 0, c3 = 0;
#pragma omp parallel for schedule(static) reduction(+ : c0, c1, c2, c3)
  for (int64_t i = 0; i < n; ++i) {
    const unsigned c = static_cast<unsigned>(classes[i]);
    const uint64_t in = counted(i) ? 1 : 0;
    c0 += in & static_cast<uint64_t>(c == 0);
    c1 += in & static_cast<uint64_t>(c == 1);
    c2 += in & static_cast<uint64_t>(c == 2);
    c3 += in & static_cast<uint64_t>(c == 3);
  }
  return {c0, c1, c2, c3};
}

}  // namespace

ClassificationSummary SummarizeClassification(const HostVector<Point2>& p, const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& mesh_triangles,
                                              const Classification& classes) {
  ClassificationSummary summary;
  const int64_t nv = static_cast<int64_t>(classes.vertices.size()), ne = static_cast<int64_t>(classes.edges.size()),
                nt = static_cast<int64_t>(classes.triangles.size());
  summary.vertices = CountClasses(classes.vertices.data(), nv,
                                  [&](int64_t v) { return representative[v] == static_cast<uint32_t>(v); });
  summary.edges = CountClasses(classes.edges.data(), ne, [](int64_t) { return true; });
  summary.triangles = CountClasses(classes.triangles.data(), nt, [](int64_t) { return true; });
  // The area is a floating-point sum: in triangle order, one thread, as AssembleShape sums it. Its
  // terms are computed first on every core (each reads three points at random: most of the pass's
  // time), then added in order, so the sum is the same double.
  std::vector<double> terms(static_cast<size_t>(nt));
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < nt; ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) {
      const auto& tri = mesh_triangles[t];
      terms[static_cast<size_t>(t)] = 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
    }
  }
  // A local accumulator: the struct's member, written through memory on every term, tripled the
  // pass's time (a store-to-load chain of 2M links at 1M points).
  double area = 0.0;
  for (int64_t t = 0; t < nt; ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) area += terms[static_cast<size_t>(t)];
  }
  summary.interior_area = area;
  return summary;
}

}  // namespace galpha
