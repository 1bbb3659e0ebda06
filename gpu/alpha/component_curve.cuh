// Component and hole curves by Borůvka's minimum spanning forest, one source for both backends.
//
// The number of components of a graph whose edges appear at ranks is, at every rank L, the number
// of nodes present minus the number of edges of rank <= L in a minimum spanning forest (Kruskal's
// algorithm adds exactly the edges that join two components, in rank order). Borůvka's algorithm
// finds that forest in parallel rounds: every component picks its lightest outgoing edge (weights
// made unique by the edge id), hooks to the other side, and pointer jumping flattens the hooks.
// A union-find in rank order computes the same curve, but sequentially and with a cache miss per
// step, which made it the slowest stage of a GPU build.
//
// Holes (the first Betti number b1) follow from the Euler characteristic: a complex in the plane
// has no 2-cycles, so V - E + T = b0 - b1, and with b0 = V - F (F: spanning-forest edges present)
// b1 = E - T - F at every level. The general complex's holes take its edge births and the forest
// above; the regularized complex (the closed triangles that are in) takes each edge from its first
// incident triangle (mu-low) and a forest of those edges. Vertices cancel out of both.
#pragma once

#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/transform.h>

#include <cstdint>
#include <optional>

#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_backend.hpp"

namespace galpha::detail {

/// An edge of the graph: its two nodes and its unique weight (rank << 32 | edge id).
struct WeightedEdge {
  uint32_t a, b;
  uint64_t weight;
};

GALPHA_HD inline void AtomicMinU64(unsigned long long* p, unsigned long long v) {
#if defined(__CUDA_ARCH__)
  atomicMin(p, v);
#else
  unsigned long long old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v < old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
#endif
}

GALPHA_HD inline void AtomicMaxU64(unsigned long long* p, unsigned long long v) {
#if defined(__CUDA_ARCH__)
  atomicMax(p, v);
#else
  unsigned long long old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v > old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
#endif
}

// The working edges carry the current component labels of their ends (relabelled every round),
// and the rounds visit only the live labels and edges: both shrink at least by half a round, so
// the total work is linear, not (nodes x rounds).

/// Each edge offers its weight to both of its components.
struct OfferLightestEdge {
  const WeightedEdge* edges;
  unsigned long long* best;
  GALPHA_HD void operator()(uint32_t i) const {
    const WeightedEdge e = edges[i];
    AtomicMinU64(&best[e.a], e.weight);
    AtomicMinU64(&best[e.b], e.weight);
  }
};

/// What a spanning forest reports of its edges (either may be null).
struct ForestOutputs {
  /// Forest edges counted at their rank (a weight's high word).
  uint32_t* merges_at_rank = nullptr;
  /// Forest edges marked with 1 at their index: (low word of the weight) - 1, for
  /// weights that carry one (the persistence pairing's keys, persistence_pairs.cuh). In a run of
  /// several graphs, the first graph's edges only.
  uint8_t* forest_mark = nullptr;
  /// Whether edges of rank kNeverRank are graph edges (the curves leave them out).
  bool keep_never = false;
  /// Several graphs in one run (disjoint node ranges, so that their rounds share launches and
  /// waits): the nodes from part_begin[0] on are the second graph's, from part_begin[1] on the
  /// third's, and graph k's merges count in part_merges[k] (merges_at_rank is part_merges[0]).
  uint32_t part_begin[2] = {~0u, ~0u};
  uint32_t* part_merges[2] = {nullptr, nullptr};

  GALPHA_HD uint32_t* MergesOf(uint32_t node) const {
    if (node >= part_begin[1]) return part_merges[1];
    return node >= part_begin[0] ? part_merges[0] : merges_at_rank;
  }
};

/// The edge a component chose tells it where to hook (the persistence pairing's hook paths).
struct RecordHookTarget {
  const WeightedEdge* edges;
  const unsigned long long* best;
  uint32_t* target;
  GALPHA_HD void operator()(uint32_t i) const {
    const WeightedEdge e = edges[i];
    if (best[e.a] == e.weight) target[e.a] = e.b;
    if (best[e.b] == e.weight) target[e.b] = e.a;
  }
};

/// A component hooks to the other end of its lightest edge, except the smaller of two components
/// that chose the same edge (the only cycles Borůvka can form with unique weights): the edge's
/// own thread hooks each side that chose it (a component's lightest edge is one edge of the live
/// list, its weight being unique). Each hooked edge is a forest edge, reported as `out` asks.
struct HookAcrossEdge {
  const WeightedEdge* edges;
  const unsigned long long* best;
  uint32_t* parent;
  ForestOutputs out;
  GALPHA_HD void operator()(uint32_t i) const {
    const WeightedEdge e = edges[i];
    const bool a_chose = best[e.a] == e.weight, b_chose = best[e.b] == e.weight;
    if (a_chose && !(b_chose && e.a < e.b)) Hook(e.a, e.b, e.weight);
    if (b_chose && !(a_chose && e.b < e.a)) Hook(e.b, e.a, e.weight);
  }
  GALPHA_HD void Hook(uint32_t c, uint32_t other, unsigned long long weight) const {
    parent[c] = other;
    const auto rank = static_cast<uint32_t>(weight >> 32);
    // A kept kNeverRank edge (the persistence diagram's) joins at no level.
    if (out.merges_at_rank != nullptr && rank != kNeverRank) AtomicIncrement(&out.MergesOf(c)[rank]);
    if (out.forest_mark != nullptr && c < out.part_begin[0]) {
      out.forest_mark[static_cast<uint32_t>(weight) - 1u] = 1;
    }
  }
};

/// One step of pointer jumping over the live labels (the hooks form trees once the two-cycles are
/// broken): log(depth) steps reach the roots even on long chains (a path whose weights increase
/// along it hooks every node to the next). Racing writes only move a pointer closer to its root.
struct JumpOnce {
  const uint32_t* labels;
  uint32_t* parent;
  uint32_t* changed;  // set when a pointer moved; null: not reported
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t c = labels[i];
    const uint32_t p = parent[c], pp = parent[p];
    if (p != pp) {
      parent[c] = pp;
      if (changed != nullptr) *changed = 1;
    }
  }
};

struct ResetBest {
  const uint32_t* labels;
  unsigned long long* best;
  GALPHA_HD void operator()(uint32_t i) const { best[labels[i]] = ~0ull; }
};

struct RelabelEdge {
  WeightedEdge* edges;
  const uint32_t* parent;
  GALPHA_HD void operator()(uint32_t i) const {
    WeightedEdge& e = edges[i];
    e.a = parent[e.a];
    e.b = parent[e.b];
  }
};

struct JoinsTwoComponents {
  GALPHA_HD bool operator()(const WeightedEdge& e) const { return e.a != e.b; }
};

struct IsRoot {
  const uint32_t* parent;
  GALPHA_HD bool operator()(uint32_t c) const { return parent[c] == c; }
};

template <class T>
struct CopyItem {
  const T* from;
  T* to;
  GALPHA_HD void operator()(uint32_t i) const { to[i] = from[i]; }
};

/// The round's bookkeeping after the compactions (one thread): the kept items' counts become the
/// live counts, and the next compaction's counts start at zero.
struct TakeKeptCounts {
  uint32_t* live_edges;
  uint32_t* live_labels;
  uint32_t* kept_edges;
  uint32_t* kept_labels;
  GALPHA_HD void operator()(uint32_t) const {
    *live_edges = *kept_edges;
    *live_labels = *kept_labels;
    *kept_edges = 0;
    *kept_labels = 0;
  }
};

struct ClearFlag {
  uint32_t* flag;
  GALPHA_HD void operator()(uint32_t) const { *flag = 0; }
};

/// Whether an edge is one of the graph's: not a loop (the dual graph's edges with the outer face
/// on both sides), and with a rank unless kNeverRank edges are kept.
struct IsGraphEdge {
  bool keep_never;
  GALPHA_HD bool operator()(const WeightedEdge& e) const {
    return e.a != e.b && (keep_never || static_cast<uint32_t>(e.weight >> 32) != kNeverRank);
  }
};

/// Finds the minimum spanning forest of a graph over nodes 0..num_nodes whose edges are the
/// `num_active` entries of `active` (graph edges only: no loops, and kNeverRank edges only when
/// `out` keeps them; weights unique), and reports its edges as `out` asks. `active` is working
/// space (clobbered), and so is `scratch` (as long as `active`) where the caller has one to spare;
/// without it (null) the compactions' target is allocated after the first round, as long as the
/// edges that round leaves.
///
/// A round's kernels are recorded once and replayed (the host's launch cost bounded the rounds,
/// as in the triangulation's flip loop): the live edge and label counts stay on the device, and
/// the host waits once a round, for whether edges were left and whether the pointer jumps
/// converged.
template <class System>
void ForestOfGraphEdges(System& sys, WeightedEdge* active, uint32_t num_active, WeightedEdge* scratch,
                        uint32_t num_nodes, const ForestOutputs& out) {
  auto policy = sys.policy();
  Buffer<uint32_t, System> labels(sys, num_nodes), parent(sys, num_nodes);
  Buffer<unsigned long long, System> best(sys, num_nodes);
  // The labels' compaction target: the lightest-edge words, which a round reads only before the
  // compaction and resets for the live labels after it (no other word is read).
  uint32_t* kept_labels = reinterpret_cast<uint32_t*>(best.data());
  enum Count { kLiveEdges, kLiveLabels, kKeptEdges, kKeptLabels, kJumped, kNumCounts };
  Buffer<uint32_t, System> counts(sys, kNumCounts);
  uint32_t* count = counts.data();
  thrust::sequence(policy, labels.data(), labels.data() + num_nodes);
  thrust::sequence(policy, parent.data(), parent.data() + num_nodes);
  thrust::fill_n(policy, best.data(), num_nodes, ~0ull);
  const uint32_t initial[kNumCounts] = {num_active, num_nodes, 0, 0, 0};
  sys.FromHost(count, initial, kNumCounts);
  std::optional<Buffer<WeightedEdge, System>> own_scratch;
  WeightedEdge* kept = scratch;  // the compactions' target

  // Hook trees are shallow on realistic input: a few jumps flatten them. The jumps run in groups,
  // and only the last of a group reports whether it still moved a pointer.
  constexpr int kJumpsPerCheck = 3;
  auto jump_group = [&] {
    for (int j = 0; j + 1 < kJumpsPerCheck; ++j) {
      sys.ForEachBelow(count + kLiveLabels, JumpOnce{labels.data(), parent.data(), nullptr});
    }
    sys.RunSingle(ClearFlag{count + kJumped});
    sys.ForEachBelow(count + kLiveLabels, JumpOnce{labels.data(), parent.data(), count + kJumped});
  };
  // Declared after the buffers: destroyed (after the stream's last replay) before them.
  typename System::Recording hook_round, more_jumps, shrink_round;
  for (int round = 0;; ++round) {
    // Every component with an edge left merges in a round: at most log2(nodes) + 1 rounds.
    if (round > 64) throw EngineError(EngineError::Kind::kInternal, "component rounds did not converge");
    sys.Replay(hook_round, [&] {
      sys.ForEachBelow(count + kLiveEdges, OfferLightestEdge{active, best.data()});
      sys.ForEachBelow(count + kLiveEdges, HookAcrossEdge{active, best.data(), parent.data(), out});
      jump_group();
    });
    // The round's wait: whether edges were left for it (none: it changed nothing, and the forest
    // is complete) and whether the jumps converged.
    uint32_t live_edges = 0, jumped = 0;
    sys.Download({{&live_edges, count + kLiveEdges, sizeof(uint32_t)}, {&jumped, count + kJumped, sizeof(uint32_t)}});
    if (live_edges == 0) return;
    for (int group = 0; jumped != 0; ++group) {
      if (group > 32) throw EngineError(EngineError::Kind::kInternal, "pointer jumping did not converge");
      sys.Replay(more_jumps, jump_group);
      jumped = sys.Read(count + kJumped);
    }
    if (kept == nullptr && !own_scratch) {
      // The first round's edges relabelled (the shrink does it again, to the same labels) and
      // counted: the target needs room for those that still join two components.
      thrust::for_each_n(policy, thrust::counting_iterator<uint32_t>(0), live_edges,
                         RelabelEdge{active, parent.data()});
      const auto left =
          static_cast<size_t>(thrust::count_if(policy, active, active + live_edges, JoinsTwoComponents{}));
      own_scratch.emplace(sys, left);
      kept = own_scratch->data();
    }
    sys.Replay(shrink_round, [&] {
      sys.ForEachBelow(count + kLiveEdges, RelabelEdge{active, parent.data()});
      sys.AppendIf(count + kLiveEdges, 1, active, active, JoinsTwoComponents{}, kept, count + kKeptEdges);
      sys.AppendIf(count + kLiveLabels, 1, labels.data(), labels.data(), IsRoot{parent.data()}, kept_labels,
                   count + kKeptLabels);
      sys.ForEachBelow(count + kKeptEdges, CopyItem<WeightedEdge>{kept, active});
      sys.ForEachBelow(count + kKeptLabels, CopyItem<uint32_t>{kept_labels, labels.data()});
      sys.ForEachBelow(count + kKeptLabels, ResetBest{labels.data(), best.data()});
      sys.RunSingle(TakeKeptCounts{count + kLiveEdges, count + kLiveLabels, count + kKeptEdges, count + kKeptLabels});
    });
  }
}

/// The general graph: nodes are input indices, an edge appears at its birth. Ties of rank are
/// broken by edge id, or, given `edge_position`, by canonical position (the persistence diagram's
/// filtration key, persistence_pairs.cuh: birth << 32 | (position + 1)).
struct GeneralGraphEdge {
  const EdgeIdx* edges;
  const uint32_t* rho;
  const uint32_t* mu_low;
  uint32_t first_node = 0;  // where the graph's nodes start in a run of several graphs
  const uint32_t* edge_position = nullptr;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const {
    const uint32_t birth = EdgeBirthRank(rho[e], mu_low[e]);
    const uint32_t tie = edge_position != nullptr ? edge_position[e] + 1u : e;
    return WeightedEdge{first_node + edges[e].v[0], first_node + edges[e].v[1],
                        (static_cast<uint64_t>(birth) << 32) | tie};
  }
};

/// The solid graph: nodes are triangles, an interior edge joins its two when it becomes interior.
struct SolidGraphEdge {
  const EdgeTris* edge_tris;
  const uint32_t* mu_high;
  uint32_t first_node = 0;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const {
    if (mu_high[e] == kNeverRank) {
      return WeightedEdge{first_node, first_node, (static_cast<uint64_t>(kNeverRank) << 32) | e};
    }
    return WeightedEdge{first_node + static_cast<uint32_t>(edge_tris[e].t[0]),
                        first_node + static_cast<uint32_t>(edge_tris[e].t[1]),
                        (static_cast<uint64_t>(mu_high[e]) << 32) | e};
  }
};

/// Per-level counters, replicated where the levels are few: item i counts into replica
/// (i / 32) mod `replicas` (a warp's items into one, so that its lanes still combine their
/// increments). A lattice puts millions of simplices on a few thousand levels (a grid on two), and
/// one counter per level made their atomics wait on each other: at 1M ulp-nudged lattice points
/// the edge births took 0.38 ms on the H200. SumReplicas adds the replicas up.
struct ReplicatedCounts {
  uint32_t* counts;  // replicas x levels
  uint32_t levels;
  uint32_t replicas;  // a power of two
  GALPHA_HD uint32_t* At(uint32_t item, uint32_t level) const {
    return counts + size_t{(item >> 5) & (replicas - 1)} * levels + level;
  }
};

/// Replicas a level's counter gets (ReplicatedCounts): as many as keep the replicated array within
/// 2^19 counters, at most 64; 1 where the levels are many (uniform points: a level a simplex).
inline uint32_t CounterReplicas(size_t levels) {
  uint32_t replicas = 64;
  while (replicas > 1 && levels * replicas > (size_t{1} << 19)) replicas /= 2;
  return replicas;
}

struct CountTriangleBirth {
  const uint32_t* tri_rank;
  ReplicatedCounts births_at_rank;
  GALPHA_HD void operator()(uint32_t t) const {
    if (tri_rank[t] != kNeverRank) AtomicIncrement(births_at_rank.At(t, tri_rank[t]));
  }
};

/// The regularized graph: nodes are input indices, an edge appears with its first incident
/// triangle (never without one).
struct RegularizedGraphEdge {
  const EdgeIdx* edges;
  const uint32_t* mu_low;
  uint32_t first_node = 0;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const {
    return WeightedEdge{first_node + edges[e].v[0], first_node + edges[e].v[1],
                        (static_cast<uint64_t>(mu_low[e]) << 32) | e};
  }
};

/// Counts each edge at its general birth (rho when unattached, else mu-low) and at its regularized
/// birth (mu-low; never without a triangle).
struct CountEdgeBirths {
  const uint32_t* rho;
  const uint32_t* mu_low;
  ReplicatedCounts general_at_rank;
  ReplicatedCounts regularized_at_rank;
  GALPHA_HD void operator()(uint32_t e) const {
    const uint32_t birth = EdgeBirthRank(rho[e], mu_low[e]);
    if (birth != kNeverRank) AtomicIncrement(general_at_rank.At(e, birth));
    if (mu_low[e] != kNeverRank) AtomicIncrement(regularized_at_rank.At(e, mu_low[e]));
  }
};

/// holes[L] = edges[0..L] - triangles[0..L] - forest[0..L] (prefix counts; b1 = E - T - F).
struct HolesAt {
  const uint32_t* edges_prefix;
  const uint32_t* triangles_prefix;
  const uint32_t* forest_prefix;
  GALPHA_HD uint32_t operator()(uint32_t level) const {
    return edges_prefix[level] - triangles_prefix[level] - forest_prefix[level];
  }
};

/// curve[L] = base + plus[0..L] - minus[0..L] for L in 0..K (plus may be null: a constant base).
struct CurveAt {
  const uint32_t* plus_prefix;
  const uint32_t* minus_prefix;
  uint32_t base;
  GALPHA_HD uint32_t operator()(uint32_t level) const {
    return base + (plus_prefix != nullptr ? plus_prefix[level] : 0u) - minus_prefix[level];
  }
};

/// Counts each distinct point at the rank of its first incident triangle (when it has one): the
/// vertices of the regularized complex.
struct CountRegularizedVertex {
  const uint32_t* representative;
  const uint32_t* vertex_tri_low;
  ReplicatedCounts at_rank;
  GALPHA_HD void operator()(uint32_t v) const {
    if (representative[v] == v && vertex_tri_low[v] != kNeverRank) AtomicIncrement(at_rank.At(v, vertex_tri_low[v]));
  }
};

/// Sums the replicas of level L's counter into counts[L].
struct SumReplicas {
  ReplicatedCounts replicated;
  uint32_t* counts;
  GALPHA_HD void operator()(uint32_t level) const {
    uint32_t sum = 0;
    for (uint32_t r = 0; r < replicated.replicas; ++r) sum += replicated.counts[size_t{r} * replicated.levels + level];
    counts[level] = sum;
  }
};

// ---- Pruning by the cycle property ----------------------------------------------------------------
//
// With unique weights the minimum spanning forest is unique, and the heaviest edge of any cycle is
// not in it (swapping it for a lighter edge of the cycle that crosses the same cut would give a
// lighter forest). So every edge that is the heaviest of some cycle can be dropped before the
// rounds, all at once: the forest of what is left is the same forest, since none of the dropped
// edges was in it. A triangulation offers cycles for free: in a graph whose nodes are points, each
// triangle's three edges; in a graph whose nodes are triangles (joined across edges), the edges
// around an interior vertex. Dropping the heaviest of each takes a third to a half of the edges
// out of every round (each triangle, each interior vertex drops one).
//
// A cycle counts only when all its edges are graph edges: an edge that is none (a loop, or a
// kNeverRank edge the graph leaves out) offers the largest weight there is, so a cycle through it
// drops nothing. A vertex on the hull has hull edges (mu-high kNeverRank) around it in the solid
// graph, so its fan, which is no cycle there, drops nothing either.

/// The cycles an edge lies on: its triangles (`edge_tris`, for graphs over points) or the fans
/// around its two ends (`edges`, for graphs over triangles); one of the two is null.
struct EdgeCycles {
  const EdgeTris* edge_tris;
  const EdgeIdx* edges;
  /// Writes the edge's cycle ids into ids; returns how many (0 to 2).
  GALPHA_HD int Of(uint32_t e, uint32_t ids[2]) const {
    int count = 0;
    for (int k = 0; k < 2; ++k) {
      if (edge_tris != nullptr) {
        if (edge_tris[e].t[k] >= 0) ids[count++] = static_cast<uint32_t>(edge_tris[e].t[k]);
      } else {
        ids[count++] = edges[e].v[k];
      }
    }
    return count;
  }
};

/// Each edge offers its weight to its cycles; a cycle keeps the heaviest (cycle_max starts at 0).
/// An edge that is no graph edge offers the most a weight can be: a cycle through it is none.
template <class Graph>
struct OfferWeightToCycles {
  Graph graph;
  EdgeCycles cycles;
  unsigned long long* cycle_max;
  bool keep_never;
  GALPHA_HD void operator()(uint32_t e) const {
    const WeightedEdge edge = graph(e);
    const unsigned long long weight = IsGraphEdge{keep_never}(edge) ? edge.weight : ~0ull;
    uint32_t ids[2];
    const int count = cycles.Of(e, ids);
    for (int k = 0; k < count; ++k) AtomicMaxU64(&cycle_max[ids[k]], weight);
  }
};

/// Whether an edge goes into the rounds: a graph edge that is the heaviest of none of its cycles.
template <class Graph>
struct IsForestCandidate {
  Graph graph;
  EdgeCycles cycles;
  const unsigned long long* cycle_max;
  bool keep_never;
  GALPHA_HD bool operator()(uint32_t e) const {
    const WeightedEdge edge = graph(e);
    if (!IsGraphEdge{keep_never}(edge)) return false;
    uint32_t ids[2];
    const int count = cycles.Of(e, ids);
    for (int k = 0; k < count; ++k) {
      if (cycle_max[ids[k]] == edge.weight) return false;
    }
    return true;
  }
};

/// The edges of a graph held in an array, as a generator.
struct EdgeAt {
  const WeightedEdge* edges;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const { return edges[e]; }
};

struct IsFlagged {
  GALPHA_HD bool operator()(uint8_t flag) const { return flag != 0; }
};

/// Several graphs over the same edge ids, pruned and packed into one forest run.
template <class System>
class ForestRun {
 public:
  ForestRun(System& sys, uint32_t num_edges, uint32_t max_cycles, uint32_t num_graphs)
      : sys_(sys), num_edges_(num_edges), flags_(sys, size_t{num_edges} * num_graphs), cycle_max_(sys, max_cycles) {}

  /// Flags graph `index`'s candidate edges (the generator `graph` places its nodes; kNeverRank
  /// edges are no graph edges unless `keep_never`: the curves count edges that appear).
  template <class Graph>
  void Flag(uint32_t index, Graph graph, EdgeCycles cycles, uint32_t num_cycles, bool keep_never = false) {
    auto policy = sys_.policy();
    thrust::counting_iterator<uint32_t> zero(0);
    thrust::fill_n(policy, cycle_max_.data(), num_cycles, 0ull);
    thrust::for_each_n(policy, zero, num_edges_,
                       OfferWeightToCycles<Graph>{graph, cycles, cycle_max_.data(), keep_never});
    thrust::transform(policy, zero, zero + num_edges_, flags_.data() + size_t{index} * num_edges_,
                      IsForestCandidate<Graph>{graph, cycles, cycle_max_.data(), keep_never});
  }

  /// Packs the flagged edges of every graph (the same generators, in the same order) and runs the
  /// forest over all their nodes.
  template <class... Graphs>
  void Run(uint32_t num_nodes, const ForestOutputs& out, Graphs... graphs) {
    auto policy = sys_.policy();
    cycle_max_.Reset();
    const size_t num_flags = size_t{num_edges_} * sizeof...(Graphs);
    const auto total =
        static_cast<uint32_t>(thrust::count_if(policy, flags_.data(), flags_.data() + num_flags, IsFlagged{}));
    Buffer<WeightedEdge, System> active(sys_, total);
    WeightedEdge* end = active.data();
    uint32_t index = 0;
    thrust::counting_iterator<uint32_t> zero(0);
    auto pack = [&](auto graph) {
      end = thrust::copy_if(policy, thrust::make_transform_iterator(zero, graph),
                            thrust::make_transform_iterator(zero + num_edges_, graph),
                            flags_.data() + size_t{index} * num_edges_, end, IsFlagged{});
      ++index;
    };
    (pack(graphs), ...);
    flags_.Reset();
    ForestOfGraphEdges(sys_, active.data(), total, nullptr, num_nodes, out);
  }

 private:
  System& sys_;
  uint32_t num_edges_;
  Buffer<uint8_t, System> flags_;
  Buffer<unsigned long long, System> cycle_max_;
};

/// The minimum spanning forest of the graph whose edges are `edges` (one entry per edge, weights
/// unique; loops and, unless `out` keeps them, kNeverRank edges are no graph edges) over nodes
/// 0..num_nodes, reported as `out` asks; `cycles` (num_cycles of them) prune it first. `edges` is
/// used as working space (clobbered).
template <class System>
void SpanningForest(System& sys, WeightedEdge* edges, uint32_t num_edges, uint32_t num_nodes, EdgeCycles cycles,
                    uint32_t num_cycles, const ForestOutputs& out) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<WeightedEdge, System> active(sys, num_edges);
  uint32_t num_active = 0;
  {
    Buffer<unsigned long long, System> cycle_max(sys, num_cycles);
    thrust::fill_n(policy, cycle_max.data(), num_cycles, 0ull);
    thrust::for_each_n(policy, zero, num_edges,
                       OfferWeightToCycles<EdgeAt>{EdgeAt{edges}, cycles, cycle_max.data(), out.keep_never});
    num_active = static_cast<uint32_t>(
        thrust::copy_if(policy, edges, edges + num_edges, zero, active.data(),
                        IsForestCandidate<EdgeAt>{EdgeAt{edges}, cycles, cycle_max.data(), out.keep_never}) -
        active.data());
  }
  ForestOfGraphEdges(sys, active.data(), num_active, edges, num_nodes, out);
}

/// What the curves are computed from (device or host arrays of the system).
struct TopologyCurvesIn {
  uint32_t num_points, num_unique, num_tri, num_edges, num_ranks;
  const EdgeIdx* edges;
  const EdgeTris* edge_tris;
  const uint32_t* representative;
  const uint32_t* tri_rank;
  const uint32_t* edge_rho;
  const uint32_t* edge_mu_low;
  const uint32_t* edge_mu_high;
  const uint32_t* vertex_tri_low;
  /// Given, the general graph breaks ties by canonical position and keeps its kNeverRank edges:
  /// its forest is then the persistence diagram's primal forest, marked in
  /// TopologyCurvesOut::general_forest_mark.
  const uint32_t* edge_position = nullptr;
};

/// The curves of one family over levels 0..num_ranks.
struct TopologyCurvesOut {
  uint32_t* components;              ///< b0 of the general complex
  uint32_t* solid_components;        ///< interior triangles joined through edges (CGAL's)
  uint32_t* holes;                   ///< b1 of the general complex
  uint32_t* regularized_components;  ///< b0 of the regularized complex (triangles joined at vertices)
  uint32_t* regularized_holes;       ///< b1 of the regularized complex
  /// With TopologyCurvesIn::edge_position: the general forest's edges marked 1 by canonical
  /// position (the others 0); one byte an edge.
  uint8_t* general_forest_mark = nullptr;
};

/// The component and hole curves over levels 0..num_ranks: GENERAL components (every distinct
/// point from level 0, joined by edges at their births), solid components (triangles from their
/// births, joined by edges becoming interior), and the components and holes of the regularized
/// complex (its vertices and edges arrive with their first triangle); holes by b1 = E - T - F.
template <class System>
void TopologyCurves(System& sys, const TopologyCurvesIn& in, const TopologyCurvesOut& out) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t levels = in.num_ranks + 1;
  auto prefix = [&](uint32_t* counts) { thrust::inclusive_scan(policy, counts, counts + levels, counts); };

  // The three forests in one run, over disjoint node ranges: the general graph (points, edges at
  // their births), the regularized graph (points, edges with their first triangle) and the solid
  // graph (triangles, joined by edges as they become interior). Their merges are counted where
  // the curves go (each curve is written over its own merge counts below).
  const uint64_t num_nodes = 2 * uint64_t{in.num_points} + in.num_tri;
  if (num_nodes >= UINT32_MAX) {  // 4n at most, and the input has at most 2^30 points
    throw EngineError(EngineError::Kind::kInternal, "too many points and triangles for the component curves");
  }
  const GeneralGraphEdge general{in.edges, in.edge_rho, in.edge_mu_low, 0, in.edge_position};
  const bool primal_forest = in.edge_position != nullptr && out.general_forest_mark != nullptr;
  const RegularizedGraphEdge regularized{in.edges, in.edge_mu_low, in.num_points};
  const SolidGraphEdge solid{in.edge_tris, in.edge_mu_high, 2 * in.num_points};
  const EdgeCycles triangles{in.edge_tris, nullptr}, fans{nullptr, in.edges};
  uint32_t* general_merges = out.components;
  uint32_t* regularized_merges = out.regularized_components;
  uint32_t* solid_merges = out.solid_components;
  {
    ForestRun<System> run(sys, in.num_edges, in.num_tri > in.num_points ? in.num_tri : in.num_points, 3);
    // The primal forest keeps the edges never born (they join last, and change no curve).
    run.Flag(0, general, triangles, in.num_tri, /*keep_never=*/primal_forest);
    run.Flag(1, regularized, triangles, in.num_tri);
    run.Flag(2, solid, fans, in.num_points);
    for (uint32_t* merges : {general_merges, regularized_merges, solid_merges}) {
      thrust::fill_n(policy, merges, levels, 0u);
    }
    ForestOutputs forest_out;
    forest_out.merges_at_rank = general_merges;
    forest_out.part_begin[0] = in.num_points;
    forest_out.part_begin[1] = 2 * in.num_points;
    forest_out.part_merges[0] = regularized_merges;
    forest_out.part_merges[1] = solid_merges;
    if (primal_forest) {
      thrust::fill_n(policy, out.general_forest_mark, in.num_edges, uint8_t{0});
      forest_out.forest_mark = out.general_forest_mark;
    }
    run.Run(static_cast<uint32_t>(num_nodes), forest_out, general, regularized, solid);
  }
  prefix(general_merges);
  prefix(regularized_merges);
  prefix(solid_merges);

  // Triangles, edges (both senses) and regularized vertices present at each level (prefix counts),
  // counted after the forests, whose working space is gone by then.
  Buffer<uint32_t, System> births(sys, levels), edge_births(sys, levels), regularized_edge_births(sys, levels),
      regularized_vertices(sys, levels);
  {
    uint32_t* const totals[4] = {births.data(), edge_births.data(), regularized_edge_births.data(),
                                 regularized_vertices.data()};
    // With one replica a level (many levels: uniform input), the totals are the counters: no
    // replicated array to fill and sum.
    const uint32_t replicas = CounterReplicas(levels);
    const size_t replicated = size_t{replicas} * levels;
    Buffer<uint32_t, System> counters(sys, replicas > 1 ? 4 * replicated : 0);
    const auto replicas_of = [&](int k) {
      return replicas > 1 ? ReplicatedCounts{counters.data() + k * replicated, static_cast<uint32_t>(levels), replicas}
                          : ReplicatedCounts{totals[k], static_cast<uint32_t>(levels), 1};
    };
    for (int k = 0; k < 4; ++k) thrust::fill_n(policy, replicas_of(k).counts, replicated, 0u);
    thrust::for_each_n(policy, zero, in.num_tri, CountTriangleBirth{in.tri_rank, replicas_of(0)});
    thrust::for_each_n(policy, zero, in.num_edges,
                       CountEdgeBirths{in.edge_rho, in.edge_mu_low, replicas_of(1), replicas_of(2)});
    thrust::for_each_n(policy, zero, in.num_points,
                       CountRegularizedVertex{in.representative, in.vertex_tri_low, replicas_of(3)});
    if (replicas > 1) {
      for (int k = 0; k < 4; ++k) thrust::for_each_n(policy, zero, levels, SumReplicas{replicas_of(k), totals[k]});
    }
  }
  prefix(births.data());
  prefix(edge_births.data());
  prefix(regularized_edge_births.data());
  prefix(regularized_vertices.data());

  // The holes read the forests' merges before the component curves overwrite them.
  thrust::transform(policy, zero, zero + levels, out.holes, HolesAt{edge_births.data(), births.data(), general_merges});
  thrust::transform(policy, zero, zero + levels, out.regularized_holes,
                    HolesAt{regularized_edge_births.data(), births.data(), regularized_merges});
  thrust::transform(policy, zero, zero + levels, out.components, CurveAt{nullptr, general_merges, in.num_unique});
  thrust::transform(policy, zero, zero + levels, out.regularized_components,
                    CurveAt{regularized_vertices.data(), regularized_merges, 0u});
  thrust::transform(policy, zero, zero + levels, out.solid_components, CurveAt{births.data(), solid_merges, 0u});
}

}  // namespace galpha::detail
