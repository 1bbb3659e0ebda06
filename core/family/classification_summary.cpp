#include "core/family/classification_summary.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
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

// The terms of the triangles t with interior(t) added in triangle order, one addition at a time,
// as AssembleShape sums them: `for t: if interior(t): area += terms[t]`, the same double. Done that
// way, the branch mispredicts about every other triangle at a middle level (most of a 1M-point
// summary's time, ~10 ms). Here each core first packs the interior terms of its block of triangles
// without a branch (every term is written, the next position advances only past an interior
// one), then one thread adds the packed terms block after block: the same additions in the same
// order.
template <typename Interior>
double AddInteriorTermsInOrder(const double* terms, int64_t nt, Interior interior) {
  if (nt == 0) return 0.0;
  const int64_t blocks = std::min<int64_t>(nt, 4 * static_cast<int64_t>(omp_get_max_threads()));
  // Block b packs into [its first triangle, packed_end[b]): never past its own triangles.
  const std::unique_ptr<double[]> packed(new double[static_cast<size_t>(nt)]);
  std::vector<int64_t> packed_end(static_cast<size_t>(blocks));
  const auto block_begin = [&](int64_t b) { return nt * b / blocks; };
#pragma omp parallel for schedule(static, 1)
  for (int64_t b = 0; b < blocks; ++b) {
    int64_t k = block_begin(b);
    const int64_t end = block_begin(b + 1);
    for (int64_t t = block_begin(b); t < end; ++t) {
      packed[static_cast<size_t>(k)] = terms[t];
      k += static_cast<int64_t>(interior(t));
    }
    packed_end[static_cast<size_t>(b)] = k;
  }
  double area = 0.0;
  for (int64_t b = 0; b < blocks; ++b) {
    const double* term = packed.get() + block_begin(b);
    const double* const end = packed.get() + packed_end[static_cast<size_t>(b)];
    for (; term != end; ++term) area += *term;
  }
  return area;
}

double InteriorArea(const double* terms, const Classification& classes) {
  const SimplexClass* cls = classes.triangles.data();
  return AddInteriorTermsInOrder(terms, static_cast<int64_t>(classes.triangles.size()),
                                 [cls](int64_t t) { return cls[t] == SimplexClass::kInterior; });
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

namespace {

// The interior triangles' terms first, on every core (each reads three points at random: most of
// the pass's time), then added in order; the others' are 0 (written, since the packing reads every
// term, and first touched by the threads that fill them).
template <typename Interior>
double InteriorAreaFromPoints(const HostVector<Point2>& p, const HostVector<std::array<uint32_t, 3>>& triangles,
                              Interior interior) {
  const int64_t nt = static_cast<int64_t>(triangles.size());
  const std::unique_ptr<double[]> terms(new double[static_cast<size_t>(nt)]);
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < nt; ++t) {
    double term = 0.0;
    if (interior(t)) {
      const auto& tri = triangles[t];
      term = 0.5 * Orient2dApprox(p[tri[0]], p[tri[1]], p[tri[2]]);
    }
    terms[static_cast<size_t>(t)] = term;
  }
  return AddInteriorTermsInOrder(terms.get(), nt, interior);
}

}  // namespace

ClassificationSummary SummarizeClassification(const HostVector<Point2>& p, const HostVector<uint32_t>& representative,
                                              const HostVector<std::array<uint32_t, 3>>& mesh_triangles,
                                              const Classification& classes) {
  ClassificationSummary summary = CountAll(representative, classes);
  const SimplexClass* cls = classes.triangles.data();
  summary.interior_area =
      InteriorAreaFromPoints(p, mesh_triangles, [cls](int64_t t) { return cls[t] == SimplexClass::kInterior; });
  return summary;
}

double InteriorAreaOfFlagged(const HostVector<Point2>& p, const HostVector<std::array<uint32_t, 3>>& triangles,
                             const std::vector<uint8_t>& in_complex) {
  const uint8_t* in = in_complex.data();
  return InteriorAreaFromPoints(p, triangles, [in](int64_t t) { return in[t] != 0; });
}

}  // namespace galpha
