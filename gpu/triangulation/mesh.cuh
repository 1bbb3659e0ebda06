// The triangle-neighbour mesh the triangulation works on, as seen from a functor, with the exact
// predicates adapted to it.
//
// Vertices 0..n-1 are the distinct input points in Hilbert order; vertex n is the symbolic vertex at
// infinity. Triangles are counter-clockwise vertex triples on the sphere formed with that vertex:
// a triangle holding it is "infinite" and stands for the outside of one hull edge. nbr[t].n[k] is the
// triangle across the edge opposite vertex k (the edge from v[k+1] to v[k+2]).
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/power.hpp"
#include "core/exact/predicates.hpp"

// The weighted predicates stay out of line: inlined, they would enlarge every kernel that calls
// the mesh's predicates (registers, occupancy) although unweighted builds never run them.
#if defined(__CUDACC__)
#define GALPHA_WEIGHTED_COLD __noinline__
#else
#define GALPHA_WEIGHTED_COLD __attribute__((noinline))
#endif

namespace galpha::detail {

/// PowerSoS of triangle (a, b, c) and vertex s > 0: s's lift below the triangle's lifted plane.
GALPHA_HD GALPHA_WEIGHTED_COLD inline bool PowerConflict(const Point2* pts, const double* weight, const uint32_t* rank,
                                                         int32_t a, int32_t b, int32_t c, int32_t s) {
  return PowerSoS(pts[a], weight[a], rank[a], pts[b], weight[b], rank[b], pts[c], weight[c], rank[c], pts[s], weight[s],
                  rank[s]) > 0;
}

struct Tri {
  int32_t v[3];
};
struct TriNbr {
  int32_t n[3];
};

GALPHA_HD inline int Next(int k) { return k == 2 ? 0 : k + 1; }
GALPHA_HD inline int Prev(int k) { return k == 0 ? 2 : k - 1; }

/// Position in triangle x of the edge running from a to b (the edge opposite that position), or -1.
GALPHA_HD inline int EdgePosIn(const Tri& x, int32_t a, int32_t b) {
  for (int k = 0; k < 3; ++k) {
    if (x.v[Next(k)] == a && x.v[Prev(k)] == b) return k;
  }
  return -1;
}

/// Position in triangle y of its vertex other than a and b, two of its vertices (in a valid mesh, the
/// apex across y's edge a-b; never out of range, where EdgePosIn's -1 would be).
GALPHA_HD inline int ApexPos(const Tri& y, int32_t a, int32_t b) {
  if (y.v[0] != a && y.v[0] != b) return 0;
  return y.v[1] != a && y.v[1] != b ? 1 : 2;
}

/// Mutable view of the mesh; copied by value into functors.
///
/// Weighted (a regular triangulation: `weight` set): the in-circle test becomes the power test
/// (core/exact/power.hpp), a flip also needs its quadrilateral convex, and points whose lift lies
/// above the mesh's lifted surface are hidden (Hidden).
struct MeshView {
  const Point2* pts;    // vertex coordinates, Hilbert order
  const uint32_t* sos;  // input index of each vertex
  Tri* tri;
  TriNbr* nbr;
  int32_t inf;  // id of the vertex at infinity (= number of finite vertices)
  // The vertices of the first triangle. Their symbolic interior point c = a + e1 (b - a) +
  // e2 (c - a) (0 < e2 << e1 << 1) lies inside every later hull; rays from it through the hull
  // vertices split the outside into disjoint sectors, one per infinite triangle, so points
  // inserted outside the hull in the same round never overlap.
  int32_t center_a, center_b, center_c;
  // The Simulation-of-Simplicity rank of each vertex: its input index (`sos`) when unweighted; when
  // weighted, its position in decreasing lexicographic order (CGAL's tie rule, power.hpp).
  const uint32_t* sos_rank;
  // Weight of each vertex, scaled with `pts` (by the square of their power of two); nullptr:
  // unweighted, a Delaunay triangulation.
  const double* weight;
  // A packed build of many point sets (delaunay_batch.cuh), one mesh each in the same arrays: the
  // set of each vertex, and the vertices of each set's first triangle (three a set), whose centre
  // replaces center_a, b and c. nullptr: one set.
  const uint32_t* vertex_set = nullptr;
  const int32_t* set_center = nullptr;

  /// Sign of orient(center, w, p): orient is affine in its first point, so it is the first
  /// nonzero of the exact signs with a, b, c in its place (never zero: a, b, c are not collinear).
  GALPHA_HD int CenterOrient(int32_t w, int32_t p) const {
    int32_t a = center_a, b = center_b, c = center_c;
    if (set_center != nullptr) {
      const int32_t* center = set_center + 3 * static_cast<size_t>(vertex_set[p]);
      a = center[0];
      b = center[1];
      c = center[2];
    }
    int s = Orient2dSign(pts[a], pts[w], pts[p]);
    if (s == 0) s = Orient2dSign(pts[b], pts[w], pts[p]);
    if (s == 0) s = Orient2dSign(pts[c], pts[w], pts[p]);
    return s;
  }

  GALPHA_HD bool IsInfinite(int32_t t) const {
    const Tri& x = tri[t];
    return x.v[0] == inf || x.v[1] == inf || x.v[2] == inf;
  }

  /// For an infinite triangle t and its hull vertex `shared` opposite its position k: the next hull
  /// vertex past `shared`, the finite vertex other than `shared` of the infinite triangle across
  /// that edge (from `shared` to the vertex at infinity); `shared` itself if there is none.
  GALPHA_HD int32_t NextHullVertex(int32_t t, int k, int32_t shared) const {
    const Tri& y = tri[nbr[t].n[k]];
    for (int j = 0; j < 3; ++j) {
      if (y.v[j] != inf && y.v[j] != shared) return y.v[j];
    }
    return shared;
  }

  /// Exact, never-zero orientation of three finite vertices.
  GALPHA_HD int Orient(int32_t a, int32_t b, int32_t c) const {
    return Orient2dSoS(pts[a], sos_rank[a], pts[b], sos_rank[b], pts[c], sos_rank[c]);
  }

  /// Whether finite vertex s is in conflict with the hull edge u->w (outside on its left): strictly
  /// beyond its line, or on the line strictly between u and w. Exact, without the symbolic
  /// perturbation: a point on a hull segment becomes a hull vertex, as in reality. Under the
  /// perturbation, points on a hull line would instead sink in or stick out by rank, and those that
  /// sink would hang from the few that stick out in long fans of flat triangles: every later point on
  /// that line would then start a flip cascade along the fan (two parallel lines of points took
  /// hundreds of sequential flip iterations a round).
  ///
  /// Weighted (kWeighted: the predicates of the regular triangulation, compiled apart so that the
  /// Delaunay kernels carry none of their code), a point on the segment is in conflict unless its
  /// lift lies strictly above the lifted segment (then it is hidden; a tie joins the hull, as in
  /// CGAL).
  template <bool kWeighted = false>
  GALPHA_HD bool HullEdgeConflict(int32_t u, int32_t w, int32_t s) const {
    const int o = Orient2dSign(pts[u], pts[w], pts[s]);
    if (o != 0) return o > 0;
    if (!OnOpenSegment(u, w, s)) return false;
    if constexpr (kWeighted) {
      return CollinearPowerSign(pts[u], weight[u], pts[w], weight[w], pts[s], weight[s]) >= 0;
    } else {
      return true;
    }
  }

  /// Whether s, on the line through u and w, lies strictly between them.
  GALPHA_HD bool OnOpenSegment(int32_t u, int32_t w, int32_t s) const {
    const Point2 a = pts[u], b = pts[w], m = pts[s];
    return (LexLess(a, m) && LexLess(m, b)) || (LexLess(b, m) && LexLess(m, a));
  }

  /// Whether vertex s lies inside the (symbolically perturbed) circumcircle of the triangle with
  /// vertices `x`. For an infinite triangle the "circle" is the half-plane beyond its hull edge,
  /// closed on the edge's open segment (HullEdgeConflict). Weighted: the power test's (s's lift
  /// below the plane).
  template <bool kWeighted = false>
  GALPHA_HD bool InConflictWith(const Tri& x, int32_t s) const {
    if (s == inf) return false;
    for (int k = 0; k < 3; ++k) {
      if (x.v[k] == inf) return HullEdgeConflict<kWeighted>(x.v[Next(k)], x.v[Prev(k)], s);
    }
    const int32_t a = x.v[0], b = x.v[1], c = x.v[2];
    if constexpr (kWeighted) {
      return PowerConflict(pts, weight, sos_rank, a, b, c, s);
    } else {
      return InCircleSoS(pts[a], sos_rank[a], pts[b], sos_rank[b], pts[c], sos_rank[c], pts[s], sos_rank[s]) > 0;
    }
  }

  /// Weighted: whether vertex s, located in triangle t (Locate), is hidden: its lift lies above
  /// the lifted triangle (finite t, not flat), or it lies on t's hull segment strictly between its
  /// ends with its lift above theirs. The mesh only gains vertices and its lifted surface only
  /// sinks as points are inserted, so a point hidden now is hidden in the final triangulation.
  GALPHA_HD GALPHA_WEIGHTED_COLD bool Hidden(int32_t t, int32_t s) const {
    const Tri& x = tri[t];
    for (int k = 0; k < 3; ++k) {
      if (x.v[k] == inf) {
        const int32_t u = x.v[Next(k)], w = x.v[Prev(k)];
        return Orient2dSign(pts[u], pts[w], pts[s]) == 0 && OnOpenSegment(u, w, s) &&
               CollinearPowerSign(pts[u], weight[u], pts[w], weight[w], pts[s], weight[s]) < 0;
      }
    }
    const int32_t a = x.v[0], b = x.v[1], c = x.v[2];
    if (Orient2dSign(pts[a], pts[b], pts[c]) == 0) return false;
    return !PowerConflict(pts, weight, sos_rank, a, b, c, s);
  }

  /// Weighted: the vertex a locally non-regular edge cannot be flipped around (the edge of t
  /// opposite position k, whose quadrilateral r, p, s, q is not convex at p or at q), or -1 when
  /// the edge is regular or can be flipped. Such a vertex is hidden: with p inside the triangle
  /// r, s, q, the lower hull of the four lifts either has p below the plane of r, s, q (and then
  /// the triangles r, p, q and s, q, p are on it, so the edge would be regular) or p above it.
  GALPHA_HD int32_t BlockedVertex(int32_t t, int k) const {
    const Tri& x = tri[t];
    const int32_t r = x.v[k], p = x.v[Next(k)], q = x.v[Prev(k)];
    if (r == inf || p == inf || q == inf) return -1;
    const Tri& y = tri[nbr[t].n[k]];
    const int32_t s = y.v[ApexPos(y, p, q)];
    if (s == inf || !InConflictWith<true>(x, s)) return -1;
    if (Orient(r, p, s) < 0) return p;
    if (Orient(s, q, r) < 0) return q;
    return -1;
  }

  /// Position in triangle t of the edge running from a to b (the edge opposite that position), or -1.
  GALPHA_HD int EdgePos(int32_t t, int32_t a, int32_t b) const { return EdgePosIn(tri[t], a, b); }

  /// Visibility walk from triangle t to a triangle containing vertex p: a finite triangle with p
  /// inside (SoS orientation: never on an edge), or an infinite triangle whose hull edge p sees.
  /// Terminates on a Delaunay (or regular) triangulation (Edelsbrunner's acyclicity theorem); a
  /// weighted mesh between rounds may hold non-regular edges that could not flip, where that
  /// argument does not hold: returns -1 if it exceeds `max_steps` (never measured), which the
  /// caller reports as an internal error.
  ///
  /// A step loads its triangle's neighbours with its vertices (one dependent load a step instead of
  /// two: the walks wait on memory), and does not test the edge it entered by: p was strictly
  /// beyond that edge as seen from the triangle it left, and the SoS orientation is antisymmetric,
  /// so p is strictly inside it as seen from this one. At 1M points two crossing lines of points
  /// walk 4.1 steps a walk, a fifth of their orientation tests on collinear (degenerate) edges,
  /// against uniform input's 2.7 steps: the test saved is one of three on most of their steps.
  GALPHA_HD int32_t Locate(int32_t t, int32_t p, uint32_t max_steps) const {
    // The edge the walk came in by, as its two vertices (-1: none, or the walk is in an infinite
    // triangle, whose tests below do not use it).
    int32_t entry_a = -1, entry_b = -1;
    for (uint32_t step = 0; step < max_steps; ++step) {
      const Tri x = tri[t];
      const TriNbr n = nbr[t];
      int inf_pos = -1;
      for (int k = 0; k < 3; ++k) {
        if (x.v[k] == inf) inf_pos = k;
      }
      if (inf_pos >= 0) {
        // Hull edge u->w with the outside on its left; its sector is the wedge from ray
        // center->w counter-clockwise to ray center->u.
        const int32_t u = x.v[Next(inf_pos)], w = x.v[Prev(inf_pos)];
        if (CenterOrient(w, p) < 0) {
          t = n.n[Next(inf_pos)];  // across the edge (w, inf): the sector clockwise of w
          entry_a = -1;
        } else if (CenterOrient(u, p) > 0) {
          t = n.n[Prev(inf_pos)];  // across the edge (inf, u): the sector beyond u
          entry_a = -1;
        } else if (Orient(u, w, p) > 0) {
          return t;
        } else {
          t = n.n[inf_pos];  // inside the hull, beyond its edge u->w (Orient(u, w, p) < 0)
          entry_a = u;
          entry_b = w;
        }
        continue;
      }
      // The position opposite the entry edge, whose edge is not tested (-1: test all three).
      const int skip = entry_a < 0 ? -1 : ApexPos(x, entry_a, entry_b);
      // Start at a rotating edge so that walks through long chains spread over the three choices.
      const int first = static_cast<int>((static_cast<uint32_t>(p) + step) % 3u);
      int exit_edge = -1;
      for (int i = 0; i < 3; ++i) {
        const int k = (first + i) % 3;
        if (k != skip && Orient(x.v[Next(k)], x.v[Prev(k)], p) < 0) {
          exit_edge = k;
          break;
        }
      }
      if (exit_edge < 0) return t;
      entry_a = x.v[Next(exit_edge)];
      entry_b = x.v[Prev(exit_edge)];
      t = n.n[exit_edge];
    }
    return -1;
  }

  /// The first edge of triangle t, among the positions `mask` names, that must be flipped to
  /// restore the (SoS) Delaunay property, or -1; `*across` is then the triangle across it. While the
  /// hull is still being built (`hull_may_change`): an edge between two infinite triangles flips
  /// when its finite vertex is not convex, and a hull edge flips when the finite triangle on it is
  /// flat with its apex on the edge (the apex joins the hull). Otherwise hull edges never flip.
  ///
  /// t and the triangles across its masked edges are loaded before the first predicate: the flip
  /// loop's short tail waits on memory latency, and checked one edge after the other (a load of t's
  /// neighbour, then of its apex), the three edges of a triangle made three chains of dependent loads.
  template <bool kWeighted = false>
  GALPHA_HD int FirstEdgeToFlip(int32_t t, uint8_t mask, bool hull_may_change, int32_t* across) const {
    const Tri x = tri[t];
    const TriNbr n = nbr[t];
    Tri y[3]{};
    for (int k = 0; k < 3; ++k) {
      if ((mask >> k) & 1u) y[k] = tri[n.n[k]];
    }
    for (int k = 0; k < 3; ++k) {
      if (!((mask >> k) & 1u)) continue;
      const int32_t s = y[k].v[ApexPos(y[k], x.v[Next(k)], x.v[Prev(k)])];
      if (EdgeMustFlip<kWeighted>(x, k, s, hull_may_change)) {
        *across = n.n[k];
        return k;
      }
    }
    return -1;
  }

  /// Whether the edge of triangle x opposite position k, whose other triangle has apex s, must be
  /// flipped (FirstEdgeToFlip).
  template <bool kWeighted = false>
  GALPHA_HD bool EdgeMustFlip(const Tri& x, int k, int32_t s, bool hull_may_change) const {
    const int32_t r = x.v[k], p = x.v[Next(k)], q = x.v[Prev(k)];
    if (r == inf || s == inf) {
      if (!hull_may_change || (r == inf && s == inf)) return false;
      return r == inf ? HullEdgeConflict<kWeighted>(p, q, s) : HullEdgeConflict<kWeighted>(q, p, r);
    }
    if ((p == inf || q == inf) && !hull_may_change) return false;
    if (!InConflictWith<kWeighted>(x, s)) return false;
    if constexpr (kWeighted) {
      // A regular triangulation may meet a non-regular edge whose quadrilateral is not convex: it
      // cannot flip (the flip would fold the mesh); its reflex vertex is hidden (BlockedVertex).
      return p == inf || q == inf || (Orient(r, p, s) > 0 && Orient(s, q, r) > 0);
    } else {
      return true;
    }
  }
};

}  // namespace galpha::detail

#undef GALPHA_WEIGHTED_COLD
