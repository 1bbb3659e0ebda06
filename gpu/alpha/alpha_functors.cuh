// Host/device functors of the alpha pipeline (alpha_impl.cuh): edge topology, radii and attachment,
// the exact repair of the approximately sorted spectrum, intervals and the master list. Every
// decision is exact: keys only order values whose certified intervals are disjoint.
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/base/point.hpp"
#include "core/exact/attachment.hpp"
#include "core/exact/order.hpp"
#include "core/exact/radius_compare.hpp"
#include "core/exact/radius_key.hpp"
#include "core/exact/radius_nearest.hpp"
#include "core/exact/radius_refined.hpp"
#include "core/exact/simplex_radius.hpp"
#include "core/family/alpha_ranks.hpp"
#include "gpu/system/atomic_increment.cuh"

namespace galpha::detail {

struct TriIdx {
  uint32_t v[3];
};
struct TriNb {
  int32_t n[3];
};
struct EdgeIdx {
  uint32_t v[2];
};
struct EdgeTris {
  int32_t t[2];
};

/// Atomic minimum / maximum on both backends (CUDA atomics; GCC builtins on the host).
GALPHA_HD inline void AtomicMinU32(uint32_t* p, uint32_t v) {
#if defined(__CUDA_ARCH__)
  atomicMin(p, v);
#else
  uint32_t old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v < old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
#endif
}
GALPHA_HD inline void AtomicMaxU32(uint32_t* p, uint32_t v) {
#if defined(__CUDA_ARCH__)
  atomicMax(p, v);
#else
  uint32_t old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v > old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
#endif
}

/// The triangulation's ownership rule (delaunay_output.cuh): triangle t owns its local edge k (from
/// vertex k to k+1, opposite vertex k+2) when the indices increase along it or on the hull. Writes
/// each owned edge's incident triangles.
struct WriteEdgeTriangles {
  const TriIdx* tri;
  const TriNb* nbr;
  const uint32_t* edge_begin;
  EdgeTris* edge_tris;
  GALPHA_HD void operator()(uint32_t t) const {
    uint32_t slot = edge_begin[t];
    for (int k = 0; k < 3; ++k) {
      const int32_t across = nbr[t].n[(k + 2) % 3];
      if (!(tri[t].v[k] < tri[t].v[(k + 1) % 3] || across < 0)) continue;
      edge_tris[slot++] = EdgeTris{{static_cast<int32_t>(t), across}};
    }
  }
};

/// The points of simplex `id` (id < num_tri: a triangle; else the edge id - num_tri) into p;
/// returns the number of points. A weighted family's simplices have weights too (`weights`, per
/// input index; nullptr for an unweighted family): the radius operations of
/// core/exact/simplex_radius.hpp take `Weights(w)`, which is nullptr for an unweighted family.
struct SimplexPoints {
  const Point2* points;
  const TriIdx* tri;
  const EdgeIdx* edges;
  uint32_t num_tri;
  const double* weights = nullptr;
  GALPHA_HD int operator()(uint32_t id, Point2* p) const {
    if (id < num_tri) {
      for (int k = 0; k < 3; ++k) p[k] = points[tri[id].v[k]];
      return 3;
    }
    const EdgeIdx e = edges[id - num_tri];
    p[0] = points[e.v[0]];
    p[1] = points[e.v[1]];
    return 2;
  }
  /// The points and, weighted, the weights (w is left alone for an unweighted family).
  GALPHA_HD int operator()(uint32_t id, Point2* p, double* w) const {
    const int n = (*this)(id, p);
    if (weights != nullptr) {
      if (id < num_tri) {
        for (int k = 0; k < 3; ++k) w[k] = weights[tri[id].v[k]];
      } else {
        const EdgeIdx e = edges[id - num_tri];
        w[0] = weights[e.v[0]];
        w[1] = weights[e.v[1]];
      }
    }
    return n;
  }
  /// What the radius operations take for a simplex's weights read into w.
  GALPHA_HD const double* Weights(const double* w) const { return weights != nullptr ? w : nullptr; }
};

/// Radius key of every triangle (entries 0..T) and edge (entries T..T+E); an attached edge gets
/// kAttachedKey (it has no spectrum value of its own). Flags uncertified keys (1), and weighted
/// edges whose attachment the bounded arithmetic could not decide (kAttachmentUndecided, plus 1
/// when the key is not certified either): the host decides those (ResolveAttachmentOnHost).
constexpr uint64_t kAttachedKey = ~uint64_t{0} - 1;  // below kInfiniteRadiusKey, above every radius
constexpr uint8_t kAttachmentUndecided = 2;
struct ComputeRadiusKeys {
  SimplexPoints simplex;
  const EdgeTris* edge_tris;
  uint64_t* keys;
  uint8_t* uncertified;
  GALPHA_HD void operator()(uint32_t id) const {
    Point2 p[3];
    double w[3];
    const int n = simplex(id, p, w);
    uint8_t undecided = 0;
    if (n == 2) {
      const EdgeTris et = edge_tris[id - simplex.num_tri];
      for (int side = 0; side < 2; ++side) {
        const int32_t t = et.t[side];
        if (t < 0) continue;
        // The triangle's vertex off the edge.
        uint32_t r = simplex.tri[t].v[0];
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = simplex.tri[t].v[k];
          const Point2 q = simplex.points[v];
          if (!(q == p[0]) && !(q == p[1])) r = v;
        }
        if (simplex.weights != nullptr) w[2] = simplex.weights[r];
        const int sign = SimplexAttachedSign(p[0], p[1], simplex.points[r], simplex.Weights(w));
        if (sign == 2) undecided = kAttachmentUndecided;
        if (sign == 1) {
          keys[id] = kAttachedKey;
          uncertified[id] = 0;
          return;
        }
      }
    }
    const RadiusSqApprox a = ApproxSimplexRadiusSq(p, simplex.Weights(w), n);
    keys[id] = a.key;
    uncertified[id] = static_cast<uint8_t>((a.certified ? 0 : 1) | undecided);
  }
};

/// Whether a flag byte has `flag` set.
struct HasFlag {
  uint8_t flag;
  GALPHA_HD bool operator()(uint8_t v) const { return (v & flag) != 0; }
};

/// Weighted: a duplicate takes its representative's hidden flag (the triangulation marks
/// representatives only); representatives are left alone, so that no flag is both read and written.
struct HiddenThroughRepresentative {
  const uint32_t* representative;
  uint8_t* hidden;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t r = representative[i];
    if (r != i) hidden[i] = hidden[r];
  }
};

/// Weighted: a distinct point (its own representative) that is hidden.
struct HiddenRepresentative {
  const uint32_t* representative;
  const uint8_t* hidden;
  GALPHA_HD bool operator()(uint32_t i) const { return representative[i] == i && hidden[i] != 0; }
};

/// Whether a spectrum entry (by key) takes part in the spectrum: born at a finite radius and not
/// an attached edge.
struct IsSpectrumEntry {
  const uint64_t* keys;
  const uint8_t* uncertified;
  bool want_uncertified;
  GALPHA_HD bool operator()(uint32_t id) const {
    if (keys[id] == kAttachedKey || keys[id] == kInfiniteRadiusKey) return false;
    return (uncertified[id] != 0) == want_uncertified;
  }
};

/// link[i]: entries i and i+1 of the sorted spectrum may be tied or out of order.
struct MayTieWithNext {
  const uint64_t* sorted_keys;
  GALPHA_HD uint8_t operator()(uint32_t i) const {
    return RadiusKeysMayTie(sorted_keys[i], sorted_keys[i + 1]) ? 1 : 0;
  }
};

/// A position where a run of entries linked to each other starts (a run of one is a settled value).
struct IsRunStart {
  const uint8_t* link;  // n - 1 links
  GALPHA_HD bool operator()(uint32_t i) const { return i == 0 || link[i - 1] == 0; }
};

/// Largest run sorted in place by one thread; longer runs go to the host's three-way quicksort.
constexpr uint32_t kMaxDeviceRun = 16;

/// Exact order of two simplices' squared radii (sign of a - b) for the short runs, cheapest proof
/// first: congruent simplices (RadiusCongruent: the same edge coordinates up to sign and order, as
/// the copies of quantized data such as centimetre LiDAR are, by the million) are equal without
/// arithmetic; disjoint double-double enclosures (EncloseRadiusSq, about 2^-95 relative) order the
/// near ties that the 64-bit keys cannot (a circle's are 2^-40 to 2^-100 apart); the rest, exact
/// ties of simplices that are not copies (a lattice's co-circular triangles) and values closer
/// than the enclosures, take the bounded exact comparison, counted. Everything but that last step
/// stays in registers: on the device a thread per comparison is bound by its local memory. Not
/// inlined: OrderRunNeighbours and RepairRun's two loops call it.
GALPHA_HD GALPHA_NOINLINE inline Order CompareRunEntries(const Point2* pa, const double* wa, int na, const Point2* pb,
                                                         const double* wb, int nb, uint32_t* count) {
  if (wa != nullptr) {  // weighted: no enclosures (their bound is the unweighted formula's)
    if (WeightedRadiusCongruent(pa, wa, na, pb, wb, nb)) return Order::kEqual;
    ++*count;
    return CompareSimplexRadiusSqBounded(pa, wa, na, pb, wb, nb);
  }
  if (RadiusCongruent(pa, na, pb, nb)) return Order::kEqual;
  RadiusSqEnclosure ea, eb;
  if (EncloseRadiusSq(pa, na, &ea) && EncloseRadiusSq(pb, nb, &eb)) {
    if (EnclosuresSeparated(ea, eb)) return Order::kLess;
    if (EnclosuresSeparated(eb, ea)) return Order::kGreater;
  }
  ++*count;
  return CompareRadiusSqBounded(pa, na, pb, nb);
}

/// A verdict of OrderRunNeighbours on entries i and i + 1 of a short run: the Order plus one in
/// the low two bits, kVerdictBounded when it took the bounded exact comparison.
constexpr uint8_t kVerdictBounded = 0x80;
GALPHA_HD inline uint8_t EncodeVerdict(Order order, bool bounded) {
  return static_cast<uint8_t>(static_cast<int>(order) + 1) | (bounded ? kVerdictBounded : 0);
}
GALPHA_HD inline Order DecodeVerdict(uint8_t verdict) { return static_cast<Order>((verdict & 0x3) - 1); }

/// Compares every pair of neighbours in the short runs at once, a thread each, for RepairRun: the
/// keys put a run's entries almost always in exact order already (ties in key order, near ties
/// the keys did order), so checking the run costs one comparison per neighbour pair, done in
/// parallel, where sorting it in one thread made a chain of comparisons as long as the run twice
/// over (centimetre LiDAR at 1M: 66K bounded comparisons in chains, 8 ms of one kernel on the
/// H100). Thread t takes neighbour pair t / num_tied of run tied[t % num_tied]: with the runs
/// longest first, the threads with work at each pair index are a prefix, so warps stay full.
struct OrderRunNeighbours {
  SimplexPoints simplex;
  const uint32_t* tied;  // runs of two entries or more, longest first
  uint32_t num_tied;
  const uint32_t* run_begin;  // each run's first entry, then the number of entries
  const uint32_t* ids;        // sorted spectrum entries
  uint8_t* verdict;           // per entry i of a short run but its last: entries i and i + 1
  GALPHA_HD void operator()(uint32_t t) const {
    const uint32_t k = t / num_tied, r = tied[t % num_tied];
    const uint32_t b = run_begin[r], n = run_begin[r + 1] - b;
    if (n > kMaxDeviceRun || k + 1 >= n) return;
    Point2 pa[3], pb[3];
    double wa[3], wb[3];
    const int na = simplex(ids[b + k], pa, wa);
    const int nb = simplex(ids[b + k + 1], pb, wb);
    uint32_t count = 0;
    const Order order = CompareRunEntries(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb, &count);
    verdict[b + k] = EncodeVerdict(order, count != 0);
  }
};

/// Sorts one short run of linked entries exactly and marks where a new exact value starts. A run
/// whose neighbours' verdicts (OrderRunNeighbours) are all Less or Equal is in exact order (order
/// is transitive) and only marked; the insertion sort with CompareRunEntries below is what it did
/// before, and does to the rest, with the same result on a run already in order (it compares the
/// same neighbours and moves nothing). There, entries proven equal while sorting share a class,
/// and the pass that marks new values does not compare them again (a tie the bounded arithmetic
/// proved costs one comparison, not two). A run that the bounded arithmetic cannot decide, or
/// that is too long, is left for the host (`needs_host`).
struct RepairRun {
  SimplexPoints simplex;
  const uint32_t* run_begin;
  const uint32_t* run_end;
  const uint8_t* verdict;  // OrderRunNeighbours's
  uint32_t* ids;           // sorted spectrum entries
  uint8_t* new_value;      // 1 where an exact value starts
  uint8_t* needs_host;     // per run
  uint32_t* comparisons;   // per run: bounded comparisons done
  GALPHA_HD void operator()(uint32_t r) const {
    const uint32_t b = run_begin[r], e = run_end[r];
    needs_host[r] = 0;
    comparisons[r] = 0;
    if (e - b == 1) return;  // a settled value: new_value stays 1
    if (e - b > kMaxDeviceRun) {
      needs_host[r] = 1;
      return;
    }
    const uint32_t n = e - b;
    uint32_t count = 0;
    bool in_order = true;
    for (uint32_t i = 0; i + 1 < n; ++i) {
      const Order order = DecodeVerdict(verdict[b + i]);
      if ((verdict[b + i] & kVerdictBounded) != 0) ++count;
      in_order = in_order && (order == Order::kLess || order == Order::kEqual);
    }
    if (in_order) {
      new_value[b] = 1;
      for (uint32_t i = 1; i < n; ++i) new_value[b + i] = DecodeVerdict(verdict[b + i - 1]) == Order::kLess ? 1 : 0;
      comparisons[r] = count;
      return;
    }
    uint32_t local[kMaxDeviceRun];       // the entries in sorted order
    uint8_t equal_class[kMaxDeviceRun];  // per sorted position: where its class's first member was taken
    for (uint32_t i = 0; i < n; ++i) local[i] = ids[b + i];
    equal_class[0] = 0;
    Point2 pa[3], pb[3];
    double wa[3], wb[3];
    for (uint32_t i = 1; i < n; ++i) {
      const uint32_t x = local[i];
      const int nx = simplex(x, pa, wa);
      uint8_t x_class = static_cast<uint8_t>(i);
      uint32_t j = i;
      while (j > 0) {
        const int ny = simplex(local[j - 1], pb, wb);
        const Order c = CompareRunEntries(pb, simplex.Weights(wb), ny, pa, simplex.Weights(wa), nx, &count);
        if (c == Order::kUndecided) {
          needs_host[r] = 1;
          comparisons[r] = count;
          return;
        }
        if (c == Order::kEqual) x_class = equal_class[j - 1];
        if (c != Order::kGreater) break;
        local[j] = local[j - 1];
        equal_class[j] = equal_class[j - 1];
        --j;
      }
      local[j] = x;
      equal_class[j] = x_class;
    }
    new_value[b] = 1;
    for (uint32_t i = 1; i < n; ++i) {
      if (equal_class[i] == equal_class[i - 1]) {
        new_value[b + i] = 0;
        continue;
      }
      const int na = simplex(local[i - 1], pa, wa);
      const int nb = simplex(local[i], pb, wb);
      const Order c = CompareRunEntries(pa, simplex.Weights(wa), na, pb, simplex.Weights(wb), nb, &count);
      if (c == Order::kUndecided) {
        needs_host[r] = 1;
        comparisons[r] = count;
        return;
      }
      new_value[b + i] = c != Order::kEqual ? 1 : 0;
    }
    for (uint32_t i = 0; i < n; ++i) ids[b + i] = local[i];
    comparisons[r] = count;
  }
};

/// Runs of two or more entries (the others are settled values).
struct IsTiedRun {
  const uint32_t* run_begin;
  GALPHA_HD bool operator()(uint32_t r) const { return run_begin[r + 1] - run_begin[r] > 1; }
};

/// A run's length, negated as an unsigned key so that an ascending sort puts the longest first.
struct NegatedRunLength {
  const uint32_t* run_begin;
  GALPHA_HD uint32_t operator()(uint32_t r) const { return ~(run_begin[r + 1] - run_begin[r]); }
};

/// 1 where a run starts (for numbering runs by a scan).
struct RunStartAsU32 {
  const uint8_t* link;
  GALPHA_HD uint32_t operator()(uint32_t i) const { return i == 0 || link[i - 1] == 0 ? 1u : 0u; }
};

/// Clears settled[r] unless entry i and its run's first both have rho^2 exactly equal to one
/// double (ExactDoubleRadiusSq): then the whole run is one exact value. Only runs still needing
/// repair (settled starts as needs_host) are checked; concurrent writes only ever write 0.
struct CheckRunOfOneDouble {
  SimplexPoints simplex;
  const uint32_t* ids;
  const uint32_t* run_of;  // inclusive scan of run starts: run index + 1
  const uint32_t* run_begin;
  uint8_t* settled;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t r = run_of[i] - 1;
    if (!settled[r]) return;
    Point2 p[3], q[3];
    double wp[3], wq[3];
    const int n = simplex(ids[i], p, wp), m = simplex(ids[run_begin[r]], q, wq);
    double a, b;
    if (!ExactDoubleSimplexRadiusSq(p, simplex.Weights(wp), n, &a) ||
        !ExactDoubleSimplexRadiusSq(q, simplex.Weights(wq), m, &b) || a != b) {
      settled[r] = 0;
    }
  }
};

/// In a settled run, only the first entry starts a value.
struct SettleRunOfOneDouble {
  const uint32_t* run_of;
  const uint32_t* run_begin;
  const uint8_t* settled;
  uint8_t* new_value;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t r = run_of[i] - 1;
    if (settled[r]) new_value[i] = i == run_begin[r] ? 1 : 0;
  }
};

/// Equalities a settled run proved: one per entry after its first.
struct SettledComparisons {
  const uint32_t* run_begin;
  const uint8_t* settled;
  GALPHA_HD uint64_t operator()(uint32_t r) const { return settled[r] ? run_begin[r + 1] - run_begin[r] - 1 : 0; }
};

struct StillNeedsHost {
  const uint8_t* needs_host;
  const uint8_t* settled;
  GALPHA_HD uint8_t operator()(uint32_t r) const { return needs_host[r] && !settled[r] ? 1 : 0; }
};

struct ToU32 {
  GALPHA_HD uint32_t operator()(uint8_t v) const { return v; }
};

/// Scatters each sorted entry's rank to its simplex and records the smallest simplex id of every
/// rank (`spectrum_simplex` filled with ~0u first). The smallest, not the first in the exact order:
/// the order of exactly tied entries depends on the path that repaired their run, and a packed
/// build of many sets (several sets' entries in one run) must name the simplex its set's build
/// alone names.
struct ScatterRanks {
  const uint32_t* ids;
  const uint32_t* rank;  // inclusive scan of new_value: 1..K
  uint32_t num_tri;
  uint32_t* tri_rank;
  uint32_t* edge_rho_rank;
  uint32_t* spectrum_simplex;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t id = ids[i];
    if (id < num_tri) {
      tri_rank[id] = rank[i];
    } else {
      edge_rho_rank[id - num_tri] = rank[i];
    }
    AtomicMinU32WarpCombined(&spectrum_simplex[rank[i] - 1], id);
  }
};

/// The nearest double of each spectrum value (bounded arithmetic; failures flagged for the host).
struct NearestSpectrumValue {
  SimplexPoints simplex;
  const uint32_t* spectrum_simplex;
  double* spectrum;
  uint8_t* needs_host;
  GALPHA_HD void operator()(uint32_t r) const {
    Point2 p[3];
    double w[3];
    const int n = simplex(spectrum_simplex[r], p, w);
    needs_host[r] = NearestSimplexRadiusSq(p, simplex.Weights(w), n, &spectrum[r]) ? 0 : 1;
  }
};

/// Edge intervals (Table 2.1 of the report "Computing 2D Alpha Shapes Using GPU") and their
/// contribution to their vertices' intervals.
struct EdgeIntervals {
  const EdgeIdx* edges;
  const EdgeTris* edge_tris;
  const uint32_t* tri_rank;
  uint32_t* edge_rho_rank;  // 0 written for attached edges
  uint32_t* edge_mu_low;
  uint32_t* edge_mu_high;
  const uint64_t* keys;  // kAttachedKey marks attached edges
  uint32_t num_tri;
  uint32_t* vertex_mu_low;
  uint32_t* vertex_mu_high;
  uint32_t* vertex_tri_low;
  GALPHA_HD void operator()(uint32_t e) const {
    const EdgeTris et = edge_tris[e];
    const uint32_t r0 = et.t[0] >= 0 ? tri_rank[et.t[0]] : kNeverRank;
    const uint32_t r1 = et.t[1] >= 0 ? tri_rank[et.t[1]] : kNeverRank;
    const uint32_t lo = r0 < r1 ? r0 : r1;
    const bool interior = et.t[0] >= 0 && et.t[1] >= 0;
    const uint32_t hi = interior ? (r0 > r1 ? r0 : r1) : kNeverRank;
    if (keys[num_tri + e] == kAttachedKey) edge_rho_rank[e] = 0;
    edge_mu_low[e] = lo;
    edge_mu_high[e] = hi;
    const uint32_t birth = edge_rho_rank[e] != 0 ? edge_rho_rank[e] : lo;
    for (int k = 0; k < 2; ++k) {
      const uint32_t v = edges[e].v[k];
      AtomicMinU32(&vertex_mu_low[v], birth);
      AtomicMaxU32(&vertex_mu_high[v], hi);
      AtomicMinU32(&vertex_tri_low[v], lo);
    }
  }
};

/// Vertices without edges (a single point) are never regular or interior; duplicates repeat their
/// representative's intervals.
struct FinishVertexIntervals {
  const uint32_t* representative;
  uint32_t* vertex_mu_low;
  uint32_t* vertex_mu_high;
  uint32_t* vertex_tri_low;
  GALPHA_HD void operator()(uint32_t v) const {
    const uint32_t rep = representative[v];
    if (rep != v) {
      // Representatives are finished by the same pass; read theirs raw and apply the same rule.
      const uint32_t low = vertex_mu_low[rep];
      vertex_mu_low[v] = low;
      vertex_mu_high[v] = low == kNeverRank ? kNeverRank : vertex_mu_high[rep];
      vertex_tri_low[v] = vertex_tri_low[rep];
      return;
    }
    if (vertex_mu_low[v] == kNeverRank) vertex_mu_high[v] = kNeverRank;
  }
};

/// A master-list entry packed so that its natural order is the order within a rank: vertex < edge
/// < triangle, then id, then end point.
GALPHA_HD inline uint64_t PackMasterEntry(SimplexKind kind, uint32_t id, Endpoint endpoint) {
  return MasterEntry(id, kind, endpoint).packed();
}

/// Visits every master-list end point of every simplex (ranks 1..K; 0 and kNeverRank are not end
/// points in the list): Visitor(rank, packed entry). Items 0..n-1 are vertices, then edges, then
/// triangles.
struct MasterEndpoints {
  const uint32_t* representative;
  const uint32_t* vertex_mu_low;
  const uint32_t* vertex_mu_high;
  const uint32_t* edge_rho;
  const uint32_t* edge_mu_low;
  const uint32_t* edge_mu_high;
  const uint32_t* tri_rank;
  uint32_t num_points;
  uint32_t num_edges;

  template <class Visitor>
  GALPHA_HD void Visit(uint32_t item, Visitor& visit) const {
    auto real = [](uint32_t r) { return r != 0 && r != kNeverRank; };
    if (item < num_points) {
      const uint32_t v = item;
      if (representative[v] != v) return;
      if (real(vertex_mu_low[v])) visit(vertex_mu_low[v], PackMasterEntry(SimplexKind::kVertex, v, Endpoint::kMuLow));
      if (real(vertex_mu_high[v]))
        visit(vertex_mu_high[v], PackMasterEntry(SimplexKind::kVertex, v, Endpoint::kMuHigh));
      return;
    }
    item -= num_points;
    if (item < num_edges) {
      const uint32_t e = item;
      if (real(edge_rho[e])) visit(edge_rho[e], PackMasterEntry(SimplexKind::kEdge, e, Endpoint::kRho));
      if (real(edge_mu_low[e])) visit(edge_mu_low[e], PackMasterEntry(SimplexKind::kEdge, e, Endpoint::kMuLow));
      if (real(edge_mu_high[e])) visit(edge_mu_high[e], PackMasterEntry(SimplexKind::kEdge, e, Endpoint::kMuHigh));
      return;
    }
    const uint32_t t = item - num_edges;
    if (real(tri_rank[t])) visit(tri_rank[t], PackMasterEntry(SimplexKind::kTriangle, t, Endpoint::kRho));
  }
};

/// Pass 1: entries per rank.
struct CountMasterEntries {
  MasterEndpoints endpoints;
  uint32_t* count;
  GALPHA_HD void operator()(uint32_t item) const {
    auto visit = [this](uint32_t rank, uint64_t) { AtomicIncrement(&count[rank]); };
    endpoints.Visit(item, visit);
  }
};

/// Pass 2: each entry into a free slot of its rank's segment (order fixed by pass 3).
struct FillMasterEntries {
  MasterEndpoints endpoints;
  uint32_t* cursor;
  uint64_t* entries;
  GALPHA_HD void operator()(uint32_t item) const {
    auto visit = [this](uint32_t rank, uint64_t packed) { entries[AtomicIncrement(&cursor[rank])] = packed; };
    endpoints.Visit(item, visit);
  }
};

/// Bits of a packed master entry (MasterEntry: kind 2, id 32, end point 2): with ranks below
/// 2^(64 - kMasterEntryBits), (rank, entry) packs into one 64-bit sort key.
constexpr int kMasterEntryBits = 36;

/// The 64-bit key (rank, entry) of the master-list entry at `position`.
struct RankedMasterKey {
  const uint32_t* rank_of;
  const uint64_t* entries;
  GALPHA_HD uint64_t operator()(uint32_t position) const {
    return (uint64_t{rank_of[position]} << kMasterEntryBits) | entries[position];
  }
};

/// The entry of a RankedMasterKey.
struct EntryOfRankedKey {
  GALPHA_HD uint64_t operator()(uint64_t key) const { return key & ((uint64_t{1} << kMasterEntryBits) - 1); }
};

/// The number of master-list entries of an item (its end points with a real rank); 0 past the
/// last item, so that an exclusive scan over num_items + 1 values ends with the total.
struct MasterEntriesOfItem {
  MasterEndpoints endpoints;
  uint32_t num_items;
  GALPHA_HD uint32_t operator()(uint32_t item) const {
    if (item >= num_items) return 0;
    uint32_t count = 0;
    auto visit = [&count](uint32_t, uint64_t) { ++count; };
    endpoints.Visit(item, visit);
    return count;
  }
};

/// Writes an item's (rank, entry) keys (RankedMasterKey's layout) from its offset: no atomics,
/// so no contention where millions of entries share a few ranks.
struct WriteRankedMasterKeys {
  MasterEndpoints endpoints;
  const uint32_t* offset;
  uint64_t* keys;
  GALPHA_HD void operator()(uint32_t item) const {
    uint32_t at = offset[item];
    auto visit = [this, &at](uint32_t rank, uint64_t packed) {
      keys[at++] = (uint64_t{rank} << kMasterEntryBits) | packed;
    };
    endpoints.Visit(item, visit);
  }
};

/// The smallest (rank, entry) key of rank r: where r's segment begins among sorted keys.
struct FirstRankedMasterKey {
  GALPHA_HD uint64_t operator()(uint32_t r) const { return uint64_t{r} << kMasterEntryBits; }
};

/// Largest rank segment sorted by one thread; longer ones (exact ties: a grid's congruent
/// triangles) are sorted by a Thrust call each.
constexpr uint32_t kMaxThreadSegment = 64;

/// Master-list positions in a long segment (rank_of: each position's rank).
struct InLongSegment {
  const uint32_t* rank_of;
  const uint8_t* long_segment;
  GALPHA_HD bool operator()(uint32_t position) const { return long_segment[rank_of[position]] != 0; }
};

/// Pass 3: sorts every short rank segment (insertion sort); flags the long ones.
struct SortMasterSegment {
  const uint32_t* begin;
  uint64_t* entries;
  uint8_t* long_segment;
  GALPHA_HD void operator()(uint32_t rank) const {
    const uint32_t b = begin[rank], e = begin[rank + 1];
    long_segment[rank] = e - b > kMaxThreadSegment ? 1 : 0;
    if (e - b > kMaxThreadSegment) return;
    for (uint32_t i = b + 1; i < e; ++i) {
      const uint64_t x = entries[i];
      uint32_t j = i;
      while (j > b && entries[j - 1] > x) {
        entries[j] = entries[j - 1];
        --j;
      }
      entries[j] = x;
    }
  }
};

}  // namespace galpha::detail
