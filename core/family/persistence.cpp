#include "core/family/persistence.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <numeric>
#include <tuple>

#include "absl/strings/str_cat.h"

namespace galpha {
namespace {

/// Union-find with path halving and union by size; each root keeps a representative chosen by
/// the caller (the eldest member under the elder rule).
class ElderForest {
 public:
  explicit ElderForest(size_t n) : parent_(n), eldest_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), uint32_t{0});
    std::iota(eldest_.begin(), eldest_.end(), uint32_t{0});
  }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  uint32_t eldest(uint32_t root) const { return eldest_[root]; }
  /// Joins two roots; the joined component's eldest is `eldest`.
  void Join(uint32_t a, uint32_t b, uint32_t eldest) {
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    eldest_[a] = eldest;
  }

 private:
  std::vector<uint32_t> parent_, eldest_, size_;
};

/// Sorts each run of consecutive items that `same_run` puts together by `less`: the lists below
/// come out of the union-finds already ordered but for ties, so sorting the runs is linear.
template <class SameRun, class Less>
void SortRuns(std::vector<PersistencePair>::iterator begin, std::vector<PersistencePair>::iterator end,
              SameRun same_run, Less less) {
  while (begin != end) {
    auto run_end = begin + 1;
    while (run_end != end && same_run(*begin, *run_end)) ++run_end;
    if (run_end - begin > 1) std::sort(begin, run_end, less);
    begin = run_end;
  }
}

/// Ids in filtration order within ranks: `order` lists ids in canonical order; the result lists
/// them by rank (kNeverRank last), canonical order within a rank (a stable counting sort).
template <class RankOf>
std::vector<uint32_t> SortByRank(absl::Span<const uint32_t> order, size_t num_ranks, RankOf rank_of) {
  // Bucket K + 1 holds kNeverRank.
  std::vector<uint32_t> start(num_ranks + 3, 0);
  auto bucket = [&](uint32_t id) -> size_t {
    const uint32_t r = rank_of(id);
    return r == kNeverRank ? num_ranks + 1 : r;
  };
  for (uint32_t id : order) ++start[bucket(id) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<uint32_t> sorted(order.size());
  for (uint32_t id : order) sorted[start[bucket(id)]++] = id;
  return sorted;
}

}  // namespace

double RankValue(const AlphaFamily& family, uint32_t rank) {
  if (rank == kNeverRank) return std::numeric_limits<double>::infinity();
  if (rank == 0) return 0.0;
  return family.spectrum()[rank - 1];
}

PairVertices VerticesOf(const AlphaFamily& family, const PersistencePair& pair) {
  PairVertices out;
  if (pair.dimension == 0) {
    out.creator[0] = pair.creator;
    if (!pair.essential()) {
      const auto edge = SortedEdge(family.edges()[pair.killer]);
      std::copy(edge.begin(), edge.end(), out.killer.begin());
    }
  } else {
    out.creator = SortedEdge(family.edges()[pair.creator]);
    if (!pair.essential()) out.killer = SortedTriangle(family.triangles()[pair.killer]);
  }
  return out;
}

bool PersistsAtLeast(const AlphaFamily& family, const PersistencePair& pair, double min_persistence) {
  if (pair.essential()) return true;
  const double birth = RankValue(family, pair.birth_rank), death = RankValue(family, pair.death_rank);
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

absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family) {
  const CanonicalOrders orders = ComputeCanonicalOrders(family);
  return ComputePersistence(family, orders.edge_order, orders.triangle_order);
}

namespace {

/// H0: every distinct point is born at rank 0; an edge joining two components kills the one whose
/// oldest vertex (lowest index: vertices of one rank are ordered by index) comes later. An edge
/// inside one component closes a loop (it creates an H1 class): marked in `closes_loop`. Pairs in
/// Kruskal's order (death ascending), then the essential classes (ordered by the caller).
std::vector<PersistencePair> PairComponents(const AlphaFamily& family, const std::vector<uint32_t>& edges_in_order,
                                            std::vector<uint8_t>* closes_loop) {
  const AlphaRanks& r = family.ranks();
  const auto num_points = static_cast<uint32_t>(family.points().size());
  std::vector<PersistencePair> pairs;
  pairs.reserve(family.num_unique());
  ElderForest forest(num_points);
  for (uint32_t e : edges_in_order) {
    const uint32_t a = forest.Find(family.edges()[e][0]), b = forest.Find(family.edges()[e][1]);
    if (a == b) {
      (*closes_loop)[e] = 1;
      continue;
    }
    const uint32_t oldest_a = forest.eldest(a), oldest_b = forest.eldest(b);
    const uint32_t young = oldest_a < oldest_b ? b : a, old = young == a ? b : a;
    const uint32_t death = EdgeBirthRank(r, e);
    if (death > 0) pairs.push_back({0, 0, death, forest.eldest(young), death == kNeverRank ? kNoSimplex : e});
    forest.Join(a, b, forest.eldest(old));
  }
  for (uint32_t v = 0; v < num_points; ++v) {
    // One essential class a component, created by its oldest vertex (not its root: the forest
    // joins by size).
    if (family.representative()[v] == v && forest.Find(v) == v) {
      pairs.push_back({0, 0, kNeverRank, forest.eldest(v), kNoSimplex});
    }
  }
  return pairs;
}

/// H1 through the dual: nodes are the triangles and the outer face (node num_tri), joined in
/// reverse filtration order by the edges; an edge whose two sides are already one component of
/// the complement is a spanning-forest edge of the primal (planar duality: the complement of a
/// minimum spanning forest is a maximum spanning tree of the dual, both in the one filtration
/// order), marked in `joins_dual` false. Of two joining components the one whose eldest member (in
/// reverse order: the latest triangle; the outer face before all) comes first in the filtration
/// dies: the loop the edge made is filled last by that triangle. Pairs in reverse filtration order
/// of their creators.
std::vector<PersistencePair> PairHoles(const AlphaFamily& family, const std::vector<uint32_t>& edges_in_order,
                                       const std::vector<uint32_t>& triangle_position,
                                       std::vector<uint8_t>* joins_dual) {
  const AlphaRanks& r = family.ranks();
  const auto num_tri = static_cast<uint32_t>(family.triangles().size());
  const uint32_t outer = num_tri;
  std::vector<PersistencePair> pairs;
  pairs.reserve(num_tri);
  ElderForest forest(size_t{num_tri} + 1);
  // Filtration key of a dual node; the outer face is never filled.
  auto key = [&](uint32_t node) {
    if (node == outer) return std::make_tuple(uint64_t{1} << 33, uint32_t{0});
    return std::make_tuple(uint64_t{r.tri_rank[node]}, triangle_position[node]);
  };
  for (auto it = edges_in_order.rbegin(); it != edges_in_order.rend(); ++it) {
    const uint32_t e = *it;
    const auto sides = r.edge_triangles[e];
    const uint32_t a = forest.Find(sides[0] < 0 ? outer : static_cast<uint32_t>(sides[0]));
    const uint32_t b = forest.Find(sides[1] < 0 ? outer : static_cast<uint32_t>(sides[1]));
    if (a == b) continue;
    (*joins_dual)[e] = 1;
    const bool a_elder = key(forest.eldest(a)) > key(forest.eldest(b));
    const uint32_t old = a_elder ? a : b, young = a_elder ? b : a;
    const uint32_t killer = forest.eldest(young);
    const uint32_t birth = EdgeBirthRank(r, e), death = r.tri_rank[killer];
    if (death > birth) pairs.push_back({1, birth, death, e, death == kNeverRank ? kNoSimplex : killer});
    forest.Join(a, b, forest.eldest(old));
  }
  return pairs;
}

}  // namespace

absl::StatusOr<PersistenceDiagram> ComputePersistence(const AlphaFamily& family, absl::Span<const uint32_t> edge_order,
                                                      absl::Span<const uint32_t> triangle_order) {
  const AlphaRanks& r = family.ranks();
  const auto num_edges = static_cast<uint32_t>(family.edges().size());
  const auto num_tri = static_cast<uint32_t>(family.triangles().size());
  const size_t num_ranks = r.spectrum.size();

  // Canonical positions break ties between simplices of one rank and dimension.
  std::vector<uint32_t> edge_position(num_edges), triangle_position(num_tri);
  for (uint32_t i = 0; i < num_edges; ++i) edge_position[edge_order[i]] = i;
  for (uint32_t i = 0; i < num_tri; ++i) triangle_position[triangle_order[i]] = i;
  const std::vector<uint32_t> edges_in_order =
      SortByRank(edge_order, num_ranks, [&](uint32_t e) { return EdgeBirthRank(r, e); });

  // The two passes are independent (the dual decides for itself which edges close loops): the
  // holes on a second thread, the components here.
  std::vector<uint8_t> closes_loop(num_edges, 0), joins_dual(num_edges, 0);
  std::future<std::vector<PersistencePair>> holes =
      std::async(std::launch::async, [&] { return PairHoles(family, edges_in_order, triangle_position, &joins_dual); });
  std::vector<PersistencePair> components = PairComponents(family, edges_in_order, &closes_loop);
  std::vector<PersistencePair> h1 = holes.get();
  // Alexander duality, checked: an edge closes a loop exactly when it joins two components of the
  // complement.
  if (closes_loop != joins_dual) {
    size_t e = 0;
    while (closes_loop[e] == joins_dual[e]) ++e;
    return absl::InternalError(absl::StrCat("persistence: edge ", e, (closes_loop[e] ? " closes" : " does not close"),
                                            " a loop but ", (joins_dual[e] ? "joins" : "does not join"),
                                            " two components of the complement"));
  }

  // The order: dimension, birth, death (kNeverRank sorts last), creator's canonical position. H0
  // pairs came in Kruskal's order (birth 0, death ascending; the essential classes last); H1 pairs
  // in reverse filtration order of their creators (birth descending): reversed, only runs of equal
  // ranks remain to be ordered.
  PersistenceDiagram diagram;
  std::vector<PersistencePair>& pairs = diagram.pairs;
  pairs = std::move(components);
  const size_t num_h0 = pairs.size();
  pairs.insert(pairs.end(), h1.rbegin(), h1.rend());
  auto position = [&](const PersistencePair& p) { return p.dimension == 0 ? p.creator : edge_position[p.creator]; };
  auto by_key = [&](const PersistencePair& x, const PersistencePair& y) {
    return std::make_tuple(x.birth_rank, x.death_rank, position(x)) <
           std::make_tuple(y.birth_rank, y.death_rank, position(y));
  };
  const auto h1_begin = pairs.begin() + static_cast<std::ptrdiff_t>(num_h0);
  SortRuns(
      pairs.begin(), h1_begin,
      [](const PersistencePair& x, const PersistencePair& y) { return x.death_rank == y.death_rank; }, by_key);
  SortRuns(
      h1_begin, pairs.end(),
      [](const PersistencePair& x, const PersistencePair& y) { return x.birth_rank == y.birth_rank; }, by_key);
  diagram.dimension_begin[0] = 0;
  diagram.dimension_begin[1] = num_h0;
  diagram.dimension_begin[2] = pairs.size();
  return diagram;
}

}  // namespace galpha
