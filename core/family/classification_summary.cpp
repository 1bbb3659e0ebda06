#include "core/family/classification_summary.hpp"

#include <array>
#include <cstdint>
#include <memory>

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

// The counts of every kind and class (the area is the callers').
ClassificationSummary CountAll(const HostVector<uint32_t>& representative, const Classification& classes) {
  ClassificationSummary summary;
  const int64_t nv = static_cast<int64_t>(classes.vertices.size()), ne = static_cast<int64_t>(classes.edges.size()),
                nt = static_cast<int64_t>(classes.triangles.size());
  summary.vertices = CountClasses(classes.vertices.data(), nv,
                                  [&](int64_t v) { return representative[v] == static_cast<uint32_t>(v); });
  summary.edges = CountClasses(classes.edges.data(), ne, [](int64_t) { return true; });
  summary.triangles = CountClasses(classes.triangles.data(), nt, [](int64_t) { return true; });
  return summary;
}

// The interior triangles' terms added in triangle order, one thread, as AssembleShape sums them
// (terms[t] is read for interior triangles only). A local accumulator: the struct's member,
// written through memory on every term, tripled this pass's time.
double InteriorArea(const double* terms, const Classification& classes) {
  double area = 0.0;
  const size_t nt = classes.triangles.size();
  for (size_t t = 0; t < nt; ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) area += terms[t];
  }
  return area;
}

}  // namespace

std::vector<double> TriangleAreaTerms(const HostVector<Point2>& p,
                                      const HostVector<std::array<uint32_t, 3>>& triangles) {
  const int64_t nt = static_cast<int64_t>(triangles.size());
  std::vector<double> terms(static_cast<size_t>(nt));
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < nt; ++t) {
    const auto& tri = triangles[t];
    terms[static_cast<size_t>(t)] = 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
  }
  return terms;
}

ClassificationSummary SummarizeClassification(const HostVector<uint32_t>& representative,
                                              const std::vector<double>& area_terms, const Classification& classes) {
  ClassificationSummary summary = CountAll(representative, classes);
  summary.interior_area = InteriorArea(area_terms.data(), classes);
  return summary;
}

ClassificationSummary SummarizeClassification(const HostVector<Point2>& p, const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& mesh_triangles,
                                              const Classification& classes) {
  ClassificationSummary summary = CountAll(representative, classes);
  const int64_t nt = static_cast<int64_t>(classes.triangles.size());
  // The interior triangles' terms first, on every core (each reads three points at random: most of
  // the pass's time), then added in order. Not zero-filled: only interior terms are written and
  // read, and the pages are first touched by the threads that fill them.
  const std::unique_ptr<double[]> terms(new double[static_cast<size_t>(nt)]);
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < nt; ++t) {
    if (classes.triangles[t] == SimplexClass::kInterior) {
      const auto& tri = mesh_triangles[t];
      terms[static_cast<size_t>(t)] = 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
    }
  }
  summary.interior_area = InteriorArea(terms.get(), classes);
  return summary;
}

}  // namespace galpha
