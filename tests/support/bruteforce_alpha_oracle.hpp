// The alpha family by brute force from its definitions (docs/design.md, "Semantics"), with GMP rationals,
// independently of CGAL and of the engine: on small point sets whose Delaunay triangulation is
// unique, a triple is a Delaunay triangle iff no other point lies inside or on its circumcircle;
// births, attachment and the spectrum come straight from their definitions; every simplex is
// classified at any alpha_sq from those births alone. O(n^4): for a few dozen points at most.
#pragma once

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/base/point.hpp"
#include "core/family/alpha_family.hpp"
#include "core/family/alpha_ranks.hpp"

namespace galpha::testing {

// ---- Exact primitives (GMP rationals; every double is a dyadic rational) ------------------------

struct QPoint {
  mpq_class x, y;
};

QPoint ToQ(const Point2& p);

/// Sign of the orientation of (a, b, c): > 0 counter-clockwise.
int Orient(const QPoint& a, const QPoint& b, const QPoint& c);

/// > 0 when d lies strictly inside the circle through a, b, c (in either orientation), 0 on it.
int InCircle(const QPoint& a, const QPoint& b, const QPoint& c, const QPoint& d);

/// Squared circumradius through the exact circumcentre (a different formula from the library's).
mpq_class CircumradiusSq(const QPoint& a, const QPoint& b, const QPoint& c);

mpq_class HalfLengthSq(const QPoint& a, const QPoint& b);

/// Strictly inside the diametral circle of (a, b): the angle a-c-b is obtuse.
bool InsideDiametral(const QPoint& a, const QPoint& b, const QPoint& c);

/// Whether `d` is a double nearest to `value` (checked against both neighbours, exactly).
bool IsNearestDouble(double d, const mpq_class& value);

/// No three distinct points collinear, no four co-circular and no two equal, exactly: a unique
/// Delaunay triangulation.
bool InGeneralPosition(const std::vector<Point2>& points);

// ---- The family by brute force -------------------------------------------------------------------

using BruteTri = std::array<uint32_t, 3>;
using BruteEdge = std::array<uint32_t, 2>;

struct BruteClasses {
  std::vector<SimplexClass> vertices;  // by input index
  std::vector<SimplexClass> edges;     // by brute edge index
  std::vector<SimplexClass> triangles;
};

struct BruteFamily {
  std::vector<Point2> points;
  std::vector<QPoint> q;
  std::vector<uint32_t> rep;     // first occurrence of each input point
  std::vector<uint32_t> uniq;    // the distinct points, by input index
  std::vector<BruteTri> tris;    // ascending input indices
  std::vector<BruteEdge> edges;  // (smaller, larger)
  std::vector<std::vector<uint32_t>> edge_tris, vertex_edges, vertex_tris;
  std::vector<bool> on_hull;  // by input index (representatives)
  std::vector<mpq_class> tri_birth, edge_rho, edge_birth;
  std::vector<bool> attached;
  std::vector<mpq_class> spectrum;  // sorted distinct births of triangles and unattached edges
  bool valid_triangulation = true;  // the brute-force triangles tile the convex hull

  int64_t K() const { return static_cast<int64_t>(spectrum.size()); }
  mpq_class Threshold(int64_t level) const {
    if (level < 0) return mpq_class(-1);
    if (level == 0) return mpq_class(0);
    return spectrum[static_cast<size_t>(level - 1)];
  }
  uint32_t RankOf(const mpq_class& v) const {
    const auto it = std::lower_bound(spectrum.begin(), spectrum.end(), v);
    if (it == spectrum.end() || *it != v) return kNeverRank - 1;  // not a spectrum value: a failure
    return static_cast<uint32_t>(it - spectrum.begin()) + 1;
  }
  // Number of spectrum values <= v (the level of v; -1 for v < 0).
  int64_t LevelOf(const mpq_class& v) const {
    if (sgn(v) < 0) return -1;
    return std::upper_bound(spectrum.begin(), spectrum.end(), v) - spectrum.begin();
  }
};

/// The Delaunay triangulation (all empty circumcircles; a chain when the points are collinear),
/// births, attachment and spectrum of `points`. valid_triangulation is false when the Delaunay
/// triangulation is not unique (then the rest means nothing).
BruteFamily BruteForce(const std::vector<Point2>& points);

/// Classes at alpha_sq = A by the definitions (closed at the threshold).
BruteClasses ClassifyBrute(const BruteFamily& b, const mpq_class& A, ClassifyMode mode, VertexRule rule);

/// Connected components of the complex at alpha_sq = A (0 for A < 0).
uint32_t BruteComponents(const BruteFamily& b, const mpq_class& A);

/// Edge-connected components of the interior triangles at alpha_sq = A.
uint32_t BruteSolidComponents(const BruteFamily& b, const mpq_class& A);

/// Connected components of the regularized complex at alpha_sq = A: the closed triangles born at
/// A or before, joined where they share a vertex.
uint32_t BruteRegularizedComponents(const BruteFamily& b, const mpq_class& A);

/// Holes (b1) of the complex at alpha_sq = A by the definition of homology over GF(2):
/// dim ker d1 - rank d2, with both ranks by Gaussian elimination (no planarity or Euler argument).
/// GENERAL: the whole complex; REGULARIZED: the closed triangles born at A or before.
uint32_t BruteHoles(const BruteFamily& b, const mpq_class& A, ClassifyMode mode);

/// Whether every distinct point is a vertex of a triangle born at A or before.
bool EveryPointOnATriangle(const BruteFamily& b, const mpq_class& A);

}  // namespace galpha::testing
