#include "core/family/persistence.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <numeric>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "core/base/host_vector.hpp"
#include "core/family/radix_sort.hpp"

namespace galpha {
namespace {

/// Union-find whose root is always its component's eldest member: nodes are numbered so that
/// age is their order (H0: a vertex's index, the smaller the elder; H1: a dual node's position in
/// the filtration, the larger the elder), and a join links the younger root under the elder. The
/// forest is then one array of parents, with no eldest or size beside it: each step of the passes
/// below touches one word a node, where the representative, size and parent of the general form
/// were three random reads. Path halving keeps the finds short (amortized logarithmic without a
/// union by size; in practice one or two hops).
class AgeOrderedForest {
 public:
  explicit AgeOrderedForest(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), uint32_t{0}); }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /// Starts loading a node the loop will find a few steps later: the passes read the forest at
  /// random (the filtration order has no locality), and waiting for each read one at a time is
  /// what they spent their time on.
  void Prefetch(uint32_t x) const { __builtin_prefetch(&parent_[x]); }
  bool IsRoot(uint32_t x) const { return parent_[x] == x; }
  void Link(uint32_t younger_root, uint32_t elder_root) { parent_[younger_root] = elder_root; }

 private:
  std::vector<uint32_t> parent_;
};

/// How many steps ahead the passes prefetch the forest's nodes.
constexpr size_t kPrefetchAhead = 16;

uint32_t RankOfKey(uint64_t key) { return static_cast<uint32_t>(key >> 32); }
uint32_t PositionOfKey(uint64_t key) { return static_cast<uint32_t>(key); }

/// Filtration keys of the simplices of one dimension: birth rank in the high word, canonical
/// position in the low word, sorted. The keys are made in canonical order, so a stable sort by
/// rank alone sorts them (a radix sort over the ranks' width, kNeverRank as the bucket after rank
/// K: two passes up to 4M ranks). A comparison sort of the 64-bit keys took most of the diagram's
/// time.
template <class RankOf>
HostVector<uint64_t> SortedFiltrationKeys(absl::Span<const uint32_t> order, size_t num_ranks, RankOf rank_of) {
  const size_t n = order.size();
  HostVector<uint64_t> keys(n), scratch;
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(n); ++i) {
    keys[i] = (uint64_t{rank_of(order[i])} << 32) | static_cast<uint64_t>(i);
  }
  const uint64_t never_bucket = uint64_t{num_ranks} + 1;
  detail::StableRadixSort(keys, scratch, detail::BitWidth(never_bucket), [never_bucket](uint64_t key) {
    const uint32_t rank = RankOfKey(key);
    return rank == kNeverRank ? never_bucket : uint64_t{rank};
  });
  return keys;
}

/// Sorts each run of consecutive items that `same_run` puts together by `less`: the lists below
/// come out of the union-finds already ordered but for ties, so sorting the runs is linear.
template <class SameRun, class Less>
void SortRuns(HostVector<PersistencePair>::iterator begin, HostVector<PersistencePair>::iterator end, SameRun same_run,
              Less less) {
  while (begin != end) {
    auto run_end = begin + 1;
    while (run_end != end && same_run(*begin, *run_end)) ++run_end;
    if (run_end - begin > 1) std::sort(begin, run_end, less);
    begin = run_end;
  }
}

}  // namespace

double RankValue(absl::Span<const double> spectrum, uint32_t rank) {
  if (rank == kNeverRank) return std::numeric_limits<double>::infinity();
  if (rank == 0) return 0.0;
  return spectrum[rank - 1];
}

double RankValue(const AlphaFamily& family, uint32_t rank) {
  return RankValue(absl::MakeConstSpan(family.spectrum()), rank);
}

PairVertices VerticesOf(absl::Span<const std::array<uint32_t, 2>> edges,
                        absl::Span<const std::array<uint32_t, 3>> triangles, const PersistencePair& pair) {
  PairVertices out;
  if (pair.dimension == 0) {
    out.creator[0] = pair.creator;
    if (!pair.essential()) {
      const auto edge = SortedEdge(edges[pair.killer]);
      std::copy(edge.begin(), edge.end(), out.killer.begin());
    }
  } else {
    out.creator = SortedEdge(edges[pair.creator]);
    if (!pair.essential()) out.killer = SortedTriangle(triangles[pair.killer]);
  }
  return out;
}

PairVertices VerticesOf(const AlphaFamily& family, const PersistencePair& pair) {
  return VerticesOf(absl::MakeConstSpan(family.edges()), absl::MakeConstSpan(family.triangles()), pair);
}

bool PersistsAtLeast(absl::Span<const double> spectrum, const PersistencePair& pair, double min_persistence) {
  if (pair.essential()) return true;
  const double birth = RankValue(spectrum, pair.birth_rank), death = RankValue(spectrum, pair.death_rank);
  // The rounded difference is within half an ulp of the exact one, so a bound two doubles away or
  // more is on the same side of both; only a bound at the difference or next to it needs the
  // exact rationals.
  const double difference = death - birth;
  if (min_persistence != difference && min_persistence != std::nextafter(difference, -INFINITY) &&
      min_persistence != std::nextafter(difference, INFINITY)) {
    return difference > min_persistence;
  }
  return mpq_class(death) - mpq_class(birth) >= mpq_class(min_persistence);
}

bool PersistsAtLeast(const AlphaFamily& family, const PersistencePair& pair, double min_persistence) {
  return PersistsAtLeast(absl::MakeConstSpan(family.spectrum()), pair, min_persistence);
}

absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family) {
  const CanonicalOrders orders = ComputeCanonicalOrders(family);
  return ComputePersistence(family, orders.edge_order, orders.triangle_order);
}

namespace {

/// The edges in filtration order, each step with what the passes read of it, gathered once (in
/// parallel) so that the passes scan them in sequence.
struct EdgeStep {
  uint32_t a, b;      // vertices (H0 nodes)
  uint32_t sides[2];  // the triangles on its two sides as dual nodes (filtration positions; the outer face last)
  uint32_t birth;     // rank
  uint32_t id;        // the family's edge id
  uint32_t position;  // canonical position (ties in the diagram's order)
};

/// H0: every distinct point is born at rank 0; an edge joining two components kills the one whose
/// oldest vertex (lowest index: vertices of one rank are ordered by index) comes later. An edge
/// inside one component closes a loop (it creates an H1 class): marked in `closes_loop` (by step).
/// Pairs in Kruskal's order (death ascending), then the essential classes (ordered by the caller).
HostVector<PersistencePair> PairComponents(const AlphaFamily& family, const HostVector<EdgeStep>& steps,
                                           std::vector<uint8_t>* closes_loop) {
  const auto num_points = static_cast<uint32_t>(family.points().size());
  HostVector<PersistencePair> pairs;
  pairs.reserve(family.num_unique());
  AgeOrderedForest forest(num_points);  // roots: their component's lowest index
  for (size_t i = 0; i < steps.size(); ++i) {
    if (i + kPrefetchAhead < steps.size()) {
      forest.Prefetch(steps[i + kPrefetchAhead].a);
      forest.Prefetch(steps[i + kPrefetchAhead].b);
    }
    const EdgeStep& step = steps[i];
    const uint32_t a = forest.Find(step.a), b = forest.Find(step.b);
    if (a == b) {
      (*closes_loop)[i] = 1;
      continue;
    }
    const uint32_t young = std::max(a, b), old = std::min(a, b);
    if (step.birth > 0) pairs.push_back({0, 0, step.birth, young, step.birth == kNeverRank ? kNoSimplex : step.id});
    forest.Link(young, old);
  }
  // One essential class a component, created by its oldest vertex (its root).
  for (uint32_t v = 0; v < num_points; ++v) {
    if (family.representative()[v] == v && !family.hidden(v) && forest.IsRoot(v)) {
      pairs.push_back({0, 0, kNeverRank, v, kNoSimplex});
    }
  }
  return pairs;
}

/// H1 through the dual: nodes are the triangles (by filtration position) and the outer face (last
/// of all), joined in reverse filtration order by the edges; an edge whose two sides are already
/// one component of the complement is a spanning-forest edge of the primal (planar duality: the
/// complement of a minimum spanning forest is a maximum spanning tree of the dual, both in the one
/// filtration order), marked in `joins_dual` false (by step). Of two joining components the one
/// whose eldest member (in reverse order: the latest triangle; the outer face before all) comes
/// first in the filtration dies: the loop the edge made is filled last by that triangle. Pairs in
/// reverse filtration order of their creators. Here an H1 pair's `creator` is the edge's canonical
/// position and its `killer` the triangle's filtration position: the caller orders the pairs by
/// the first, then maps both to ids.
HostVector<PersistencePair> PairHoles(const HostVector<EdgeStep>& steps, const HostVector<uint64_t>& triangle_keys,
                                      std::vector<uint8_t>* joins_dual) {
  const auto num_tri = static_cast<uint32_t>(triangle_keys.size());
  HostVector<PersistencePair> pairs;
  pairs.reserve(num_tri);
  AgeOrderedForest forest(size_t{num_tri} + 1);  // roots: their component's latest position
  for (size_t i = steps.size(); i-- > 0;) {
    if (i >= kPrefetchAhead) {
      forest.Prefetch(steps[i - kPrefetchAhead].sides[0]);
      forest.Prefetch(steps[i - kPrefetchAhead].sides[1]);
    }
    const EdgeStep& step = steps[i];
    const uint32_t a = forest.Find(step.sides[0]), b = forest.Find(step.sides[1]);
    if (a == b) continue;
    (*joins_dual)[i] = 1;
    // The outer face (num_tri) is never the younger: only two of its own sides would make it so.
    const uint32_t young = std::min(a, b), old = std::max(a, b);
    const uint32_t death = RankOfKey(triangle_keys[young]);
    if (death > step.birth)
      pairs.push_back({1, step.birth, death, step.position, death == kNeverRank ? kNoSimplex : young});
    forest.Link(young, old);
  }
  return pairs;
}

}  // namespace

absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family, absl::Span<const uint32_t> edge_order,
                                                      absl::Span<const uint32_t> triangle_order) {
  const AlphaRanks& r = family.ranks();
  const auto num_tri = static_cast<uint32_t>(family.triangles().size());

  // The filtration: each dimension sorted by (birth rank, canonical position).
  const HostVector<uint64_t> triangle_keys =
      SortedFiltrationKeys(triangle_order, r.spectrum.size(), [&](uint32_t t) { return r.tri_rank[t]; });
  const HostVector<uint64_t> edge_keys =
      SortedFiltrationKeys(edge_order, r.spectrum.size(), [&](uint32_t e) { return EdgeBirthRank(r, e); });
  // Dual nodes: a triangle's filtration position; the outer face after every triangle.
  HostVector<uint32_t> dual_node(num_tri);
#pragma omp parallel for schedule(static)
  for (int64_t j = 0; j < static_cast<int64_t>(num_tri); ++j) {
    dual_node[triangle_order[PositionOfKey(triangle_keys[j])]] = static_cast<uint32_t>(j);
  }
  HostVector<EdgeStep> steps(edge_keys.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < static_cast<int64_t>(steps.size()); ++i) {
    const uint32_t position = PositionOfKey(edge_keys[i]);
    const uint32_t e = edge_order[position];
    const auto sides = r.edge_triangles[e];
    steps[i] = {family.edges()[e][0],
                family.edges()[e][1],
                {sides[0] < 0 ? num_tri : dual_node[sides[0]], sides[1] < 0 ? num_tri : dual_node[sides[1]]},
                RankOfKey(edge_keys[i]),
                e,
                position};
  }

  // The two passes are independent (the dual decides for itself which edges close loops): the
  // holes on a second thread, the components here.
  std::vector<uint8_t> closes_loop(steps.size(), 0), joins_dual(steps.size(), 0);
  std::future<HostVector<PersistencePair>> holes =
      std::async(std::launch::async, [&] { return PairHoles(steps, triangle_keys, &joins_dual); });
  HostVector<PersistencePair> components = PairComponents(family, steps, &closes_loop);
  HostVector<PersistencePair> h1 = holes.get();
  // Alexander duality, checked: an edge closes a loop exactly when it joins two components of the
  // complement.
  if (closes_loop != joins_dual) {
    size_t i = 0;
    while (closes_loop[i] == joins_dual[i]) ++i;
    return absl::InternalError(
        absl::StrCat("persistence: edge ", steps[i].id, (closes_loop[i] ? " closes" : " does not close"),
                     " a loop but ", (joins_dual[i] ? "joins" : "does not join"), " two components of the complement"));
  }
  // The order: dimension, birth, death (kNeverRank sorts last), creator's canonical position. H0
  // pairs came in Kruskal's order (birth 0, death ascending; the essential classes last); H1 pairs
  // in reverse filtration order of their creators (birth descending): reversed, only runs of equal
  // ranks remain to be ordered.
  PersistenceDiagram diagram;
  HostVector<PersistencePair>& pairs = diagram.pairs;
  pairs = std::move(components);
  const size_t num_h0 = pairs.size();
  pairs.insert(pairs.end(), h1.rbegin(), h1.rend());
  // Every creator is its canonical position here (a vertex's is its index; H1's were recorded so).
  auto by_key = [](const PersistencePair& x, const PersistencePair& y) {
    return std::make_tuple(x.birth_rank, x.death_rank, x.creator) <
           std::make_tuple(y.birth_rank, y.death_rank, y.creator);
  };
  const auto h1_begin = pairs.begin() + static_cast<std::ptrdiff_t>(num_h0);
  SortRuns(
      pairs.begin(), h1_begin,
      [](const PersistencePair& x, const PersistencePair& y) { return x.death_rank == y.death_rank; }, by_key);
  SortRuns(
      h1_begin, pairs.end(),
      [](const PersistencePair& x, const PersistencePair& y) { return x.birth_rank == y.birth_rank; }, by_key);
  // H1's creators and killers by id.
  for (auto it = h1_begin; it != pairs.end(); ++it) {
    it->creator = edge_order[it->creator];
    if (it->killer != kNoSimplex) it->killer = triangle_order[PositionOfKey(triangle_keys[it->killer])];
  }
  diagram.dimension_begin[0] = 0;
  diagram.dimension_begin[1] = num_h0;
  diagram.dimension_begin[2] = pairs.size();
  return diagram;
}

}  // namespace galpha
