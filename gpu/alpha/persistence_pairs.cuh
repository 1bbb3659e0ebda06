// The persistence diagram of a family on the engine's backend (CUDA or OpenMP, one source): the
// same diagram, pair for pair, as the host's union-finds (core/family/persistence.cpp, which
// defines it and stays its oracle), computed without a sequential pass over the filtration.
//
// Both dimensions are the elder rule over a spanning forest: H0 over the primal graph (vertices,
// edges in filtration order, the elder of two components the one with the lowest vertex index),
// H1 over the dual graph (triangles and the outer face, edges in reverse filtration order, the
// elder the latest triangle in the filtration, the outer face before all). In both, the edges that
// join two components are the minimum spanning forest of the processing order: the primal one
// Borůvka's rounds find in parallel (component_curve.cuh), the dual one is its complement
// (OutsideForest says why), and each forest edge kills the younger of the two components' eldest
// members. Which those are is what Kruskal's order decides, and what
// PairBySplicing computes without following it edge by edge (see there for why it is exact).
//
// Keys. The filtration orders edges by (birth rank, canonical position): one 64-bit key,
// birth << 32 | (position + 1), unique, and never 0 or ~0 (the forest's "no edge"), so the primal
// forest takes the keys as weights and the dual forest their complements (the reverse order).
// A dual node's age is the complement of its triangle's key (rank << 32 | position), the outer
// face's 0: the smaller the age, the elder, in both forests.
#pragma once

#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scatter.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "core/family/alpha_ranks.hpp"
#include "core/family/persistence_pair.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/alpha/component_curve.cuh"
#include "gpu/alpha/persistence_report.hpp"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

/// What the diagram is computed from (arrays in the system's memory): the family's simplices and
/// birth ranks, as AlphaRanks holds them.
struct PersistenceIn {
  uint32_t num_points, num_edges, num_tri;
  const EdgeIdx* edges;
  const EdgeTris* edge_tris;  ///< incident triangles, -1 for none
  const TriIdx* triangles;
  const uint32_t* edge_rho_rank;
  const uint32_t* edge_mu_low;
  const uint32_t* tri_rank;
  const uint32_t* representative;
  const uint8_t* hidden;  ///< weighted families: 1 for a hidden point; null otherwise
};

/// The diagram as core/family/persistence.hpp defines it: H0 pairs first (num_h0 of them).
struct PersistenceOut {
  HostVector<PersistencePair> pairs;
  size_t num_h0 = 0;
  PersistenceReport report;
};

/// The diagram of `out` (its pairs moved out) in core/family/persistence.hpp's form.
inline PersistenceDiagram TakeDiagram(PersistenceOut* out) {
  PersistenceDiagram diagram;
  diagram.pairs = std::move(out->pairs);
  diagram.dimension_begin[0] = 0;
  diagram.dimension_begin[1] = out->num_h0;
  diagram.dimension_begin[2] = diagram.pairs.size();
  return diagram;
}

// ---- Canonical positions -------------------------------------------------------------------------

struct EdgeVertexKey {
  const EdgeIdx* edges;
  GALPHA_HD uint64_t operator()(uint32_t e) const {
    const uint32_t a = edges[e].v[0], b = edges[e].v[1];
    return (static_cast<uint64_t>(a < b ? a : b) << 32) | (a < b ? b : a);
  }
};

/// A triangle's ascending vertices.
GALPHA_HD inline void SortedVertices(const TriIdx& t, uint32_t* lo, uint32_t* mid, uint32_t* hi) {
  uint32_t a = t.v[0], b = t.v[1], c = t.v[2];
  if (a > b) {
    const uint32_t s = a;
    a = b;
    b = s;
  }
  if (b > c) {
    const uint32_t s = b;
    b = c;
    c = s;
  }
  if (a > b) {
    const uint32_t s = a;
    a = b;
    b = s;
  }
  *lo = a;
  *mid = b;
  *hi = c;
}

struct TriangleLastVertex {
  const TriIdx* triangles;
  GALPHA_HD uint32_t operator()(uint32_t t) const {
    uint32_t a, b, c;
    SortedVertices(triangles[t], &a, &b, &c);
    return c;
  }
};

struct TriangleFirstVertices {
  const TriIdx* triangles;
  GALPHA_HD uint64_t operator()(uint32_t t) const {
    uint32_t a, b, c;
    SortedVertices(triangles[t], &a, &b, &c);
    return (static_cast<uint64_t>(a) << 32) | b;
  }
};

/// position[order[p]] = p.
struct InvertOrder {
  const uint32_t* order;
  uint32_t* position;
  GALPHA_HD void operator()(uint32_t p) const { position[order[p]] = p; }
};

/// Ids in canonical order (ascending vertex tuples, core/family/canonical_order.hpp) and each id's
/// position in it. Tuples are unique, so any sort gives the one order.
template <class System>
void CanonicalEdgeOrder(System& sys, const PersistenceIn& in, Buffer<uint32_t, System>* order,
                        Buffer<uint32_t, System>* position) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint64_t, System> keys(sys, in.num_edges);
  thrust::transform(policy, zero, zero + in.num_edges, keys.data(), EdgeVertexKey{in.edges});
  thrust::sequence(policy, order->data(), order->data() + in.num_edges);
  thrust::sort_by_key(policy, keys.data(), keys.data() + in.num_edges, order->data());
  thrust::for_each_n(policy, zero, in.num_edges, InvertOrder{order->data(), position->data()});
}

/// Triangles: by the last vertex, then stably by the first two (least significant field first).
template <class System>
void CanonicalTriangleOrder(System& sys, const PersistenceIn& in, Buffer<uint32_t, System>* order,
                            Buffer<uint32_t, System>* position) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  thrust::sequence(policy, order->data(), order->data() + in.num_tri);
  {
    Buffer<uint32_t, System> last(sys, in.num_tri);
    thrust::transform(policy, zero, zero + in.num_tri, last.data(), TriangleLastVertex{in.triangles});
    thrust::stable_sort_by_key(policy, last.data(), last.data() + in.num_tri, order->data());
  }
  Buffer<uint64_t, System> first(sys, in.num_tri);
  thrust::transform(policy, order->data(), order->data() + in.num_tri, first.data(),
                    TriangleFirstVertices{in.triangles});
  thrust::stable_sort_by_key(policy, first.data(), first.data() + in.num_tri, order->data());
  thrust::for_each_n(policy, zero, in.num_tri, InvertOrder{order->data(), position->data()});
}

/// A family's canonical orders: ids by position, and each id's position.
template <class System>
struct CanonicalOrders {
  Buffer<uint32_t, System> edge_order, edge_position, triangle_order, triangle_position;
};

template <class System>
CanonicalOrders<System> CanonicalOrdersOf(System& sys, const PersistenceIn& in) {
  CanonicalOrders<System> orders{Buffer<uint32_t, System>(sys, in.num_edges),
                                 Buffer<uint32_t, System>(sys, in.num_edges), Buffer<uint32_t, System>(sys, in.num_tri),
                                 Buffer<uint32_t, System>(sys, in.num_tri)};
  CanonicalEdgeOrder(sys, in, &orders.edge_order, &orders.edge_position);
  CanonicalTriangleOrder(sys, in, &orders.triangle_order, &orders.triangle_position);
  return orders;
}

// ---- The two graphs -------------------------------------------------------------------------------

/// An edge's filtration key: birth << 32 | (canonical position + 1).
struct EdgeFiltrationKey {
  const uint32_t* rho;
  const uint32_t* mu_low;
  const uint32_t* edge_position;
  GALPHA_HD uint64_t operator()(uint32_t e) const {
    return (static_cast<uint64_t>(EdgeBirthRank(rho[e], mu_low[e])) << 32) | (edge_position[e] + 1u);
  }
};

/// The primal graph in filtration order: vertices joined by edges, weighted by their keys.
struct PrimalEdge {
  const EdgeIdx* edges;
  EdgeFiltrationKey key;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const { return WeightedEdge{edges[e].v[0], edges[e].v[1], key(e)}; }
};

/// The dual graph in reverse filtration order: an edge joins the triangles on its sides (the
/// outer face, node num_tri, where there is none), weighted by the complement of its key.
struct DualEdge {
  const EdgeTris* edge_tris;
  uint32_t num_tri;
  EdgeFiltrationKey key;
  GALPHA_HD WeightedEdge operator()(uint32_t e) const {
    const int32_t s0 = edge_tris[e].t[0], s1 = edge_tris[e].t[1];
    return WeightedEdge{s0 < 0 ? num_tri : static_cast<uint32_t>(s0), s1 < 0 ? num_tri : static_cast<uint32_t>(s1),
                        ~key(e)};
  }
};

/// A dual node's age: the complement of its triangle's filtration key (rank << 32 | canonical
/// position; the latest triangle is the eldest), the outer face 0 (eldest of all).
struct DualNodeAge {
  const uint32_t* tri_rank;
  const uint32_t* tri_position;
  uint32_t num_tri;
  GALPHA_HD uint64_t operator()(uint32_t t) const {
    if (t == num_tri) return 0;
    return ~((static_cast<uint64_t>(tri_rank[t]) << 32) | tri_position[t]);
  }
};

struct IdentityAge {
  GALPHA_HD uint64_t operator()(uint32_t v) const { return v; }
};

// ---- The elder rule over a spanning forest ---------------------------------------------------------

/// No node: the path minimum of a hook root (nothing above it).
constexpr uint32_t kNoNode = 0xFFFFFFFFu;

/// A path-minimum word: the eldest node seen so far on the path up the hooks (high half; kNoNode
/// for none) and how far the path has been read (low half: the node the next jump reads). One
/// 64-bit word, so that a jump reads a consistent pair while others rewrite theirs.
GALPHA_HD inline uint64_t PathWord(uint32_t eldest_node, uint32_t reached) {
  return (static_cast<uint64_t>(eldest_node) << 32) | reached;
}
GALPHA_HD inline uint32_t PathEldest(uint64_t word) { return static_cast<uint32_t>(word >> 32); }
GALPHA_HD inline uint32_t PathReached(uint64_t word) { return static_cast<uint32_t>(word); }

/// Each live node hooks across its lightest live edge (Borůvka's hooks: trees whose edges get
/// lighter towards a root pair of nodes that chose the same edge); the elder of a root pair is the
/// root. The path above a node starts at its hook target.
struct StartHookPath {
  const uint32_t* nodes;
  const unsigned long long* best;
  const uint32_t* target;
  const uint64_t* eldest;
  uint64_t* path;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t x = nodes[i];
    if (best[x] == ~0ull) {  // no live edge left at this node
      path[x] = PathWord(kNoNode, x);
      return;
    }
    const uint32_t t = target[x];
    const bool root = best[t] == best[x] && eldest[x] < eldest[t];
    path[x] = root ? PathWord(kNoNode, x) : PathWord(t, t);
  }
};

/// One pointer jump up the hooks: a node's path takes in the part its current end has read.
/// Racing writes only extend a path read by another node, whose word stays consistent.
struct JumpHookPath {
  const uint32_t* nodes;
  const uint64_t* eldest;
  uint64_t* path;
  uint32_t* changed;  // set when a word moved; null: not reported
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t x = nodes[i];
    const uint64_t mine = path[x];
    const uint32_t reached = PathReached(mine);
    const uint64_t theirs = path[reached];
    if (PathReached(theirs) == reached) return;  // reached the root: complete
    uint32_t best = PathEldest(mine);
    const uint32_t other = PathEldest(theirs);
    if (other != kNoNode && (best == kNoNode || eldest[other] < eldest[best])) best = other;
    path[x] = PathWord(best, PathReached(theirs));
    if (changed != nullptr) *changed = 1;
  }
};

/// A node younger than the eldest node P on its hook path is spliced into P: its lightest live
/// edge kills it (recorded at that edge's index), and its other edges become P's. See
/// PairBySplicing for why this is Kruskal's answer. P itself is never spliced (it is the eldest of
/// its own path too), so one hop relabels every edge.
struct SpliceYoungNode {
  const uint32_t* nodes;
  const unsigned long long* best;
  const uint64_t* eldest;
  const uint64_t* path;
  uint32_t* parent;
  uint64_t* killed_age;
  uint32_t mark_xor;
  uint32_t* spliced;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t x = nodes[i];
    const uint32_t p = PathEldest(path[x]);
    if (p == kNoNode || eldest[p] > eldest[x]) return;
    killed_age[(static_cast<uint32_t>(best[x]) ^ mark_xor) - 1u] = eldest[x];
    parent[x] = p;
    AtomicIncrement(spliced);
  }
};

/// Nodes stay live while they are not spliced and had a live edge this round.
struct StaysLive {
  const uint32_t* parent;
  const unsigned long long* best;
  GALPHA_HD bool operator()(uint32_t x) const { return parent[x] == x && best[x] != ~0ull; }
};

/// The round's bookkeeping after the compactions (one thread).
struct TakeKeptItems {
  uint32_t* live_edges;
  uint32_t* kept_edges;
  uint32_t* live_nodes;
  uint32_t* kept_nodes;
  uint32_t* spliced;
  uint32_t* spliced_last;
  GALPHA_HD void operator()(uint32_t) const {
    *live_edges = *kept_edges;
    *kept_edges = 0;
    *live_nodes = *kept_nodes;
    *kept_nodes = 0;
    *spliced_last = *spliced;
    *spliced = 0;
  }
};

/// The eldest of both ends of a live edge, for the host's finish.
struct GatherEndAges {
  const WeightedEdge* edges;
  const uint64_t* eldest;
  uint64_t* ages;
  GALPHA_HD void operator()(uint32_t i) const {
    ages[2 * i] = eldest[edges[i].a];
    ages[2 * i + 1] = eldest[edges[i].b];
  }
};

struct ScatterKilled {
  const uint32_t* index;
  const uint64_t* age;
  uint64_t* killed_age;
  GALPHA_HD void operator()(uint32_t i) const { killed_age[index[i]] = age[i]; }
};

/// The elder rule in Kruskal's order over the forest edges that the rounds left (their clusters
/// contracted, each with its eldest age): a sequential union-find on the host, exact as Kruskal's
/// algorithm itself. Returns (edge index, killed age) pairs.
inline void FinishElderRuleOnHost(const std::vector<WeightedEdge>& edges, const std::vector<uint64_t>& end_ages,
                                  uint32_t mark_xor, std::vector<uint32_t>* index, std::vector<uint64_t>* killed) {
  const size_t m = edges.size();
  // Clusters by their eldest age (unique per cluster): compact ids.
  std::vector<uint64_t> ages(end_ages);
  std::sort(ages.begin(), ages.end());
  ages.erase(std::unique(ages.begin(), ages.end()), ages.end());
  auto id_of = [&](uint64_t age) {
    return static_cast<uint32_t>(std::lower_bound(ages.begin(), ages.end(), age) - ages.begin());
  };
  std::vector<uint32_t> parent(ages.size());
  std::iota(parent.begin(), parent.end(), 0u);  // a root is its component's eldest: ids follow ages
  auto find = [&](uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  std::vector<uint32_t> by_weight(m);
  std::iota(by_weight.begin(), by_weight.end(), 0u);
  std::sort(by_weight.begin(), by_weight.end(),
            [&](uint32_t x, uint32_t y) { return edges[x].weight < edges[y].weight; });
  index->resize(m);
  killed->resize(m);
  for (size_t k = 0; k < m; ++k) {
    const uint32_t i = by_weight[k];
    const uint32_t a = find(id_of(end_ages[2 * i])), b = find(id_of(end_ages[2 * i + 1]));
    if (a == b) throw EngineError(EngineError::Kind::kInternal, "persistence: a forest edge closes a loop");
    const uint32_t young = std::max(a, b), old = std::min(a, b);
    (*index)[k] = (static_cast<uint32_t>(edges[i].weight) ^ mark_xor) - 1u;
    (*killed)[k] = ages[young];
    parent[young] = old;
  }
}

/// The elder rule over the spanning forest `forest` (the forest edges of a graph over num_nodes
/// nodes, compacted; clobbered): for every forest edge, the age of the eldest member of the
/// younger of the two components it joins when edges join in weight order (Kruskal's order), into
/// killed_age[index] (index from the weight as ForestOutputs's).
///
/// Rounds contract the forest. In a round every live node x hooks across its lightest live edge
/// e; the hooks form trees whose edges get lighter towards a root (Borůvka's), so every edge on
/// the path above x is lighter than e and joins before it. If a node P on that path is elder than
/// x, then when e joins x's component, which is x alone (e is x's lightest edge), to the other,
/// that component already holds P: e kills x (its eldest), whatever else happens. And x's content
/// never matters again: x's other edges are heavier than e, so from their time on x is in P's
/// component, where P is elder than all of x. So x is spliced into the eldest node of its path,
/// which takes x's other edges; P is spliced nowhere (nothing above it on the path is elder), so
/// the spliced nodes with one P are a subtree around it, and the forest stays a forest. Splicing
/// every such node at once is the same as one at a time: a splice changes no other node's lightest
/// edge and no eldest node of a path. Each round splices at least the younger node of the lightest
/// live edge. Ages are unique, so the eldest of a contracted node is its own age throughout.
///
/// Rounds run while they splice at least an eighth of the live edges; a forest whose elder nodes
/// lie at the heavy ends of long paths splices a few a round, and its rest, like the last
/// thousand edges, is finished on the host in Kruskal's order over the contracted nodes, one
/// union-find step an edge (the same facts make that exact).
template <class System>
void PairBySplicing(System& sys, WeightedEdge* forest, uint32_t num_forest, uint32_t num_nodes, const uint64_t* eldest,
                    uint32_t mark_xor, bool host_finish, uint64_t* killed_age, ForestPairing* report) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<WeightedEdge, System> kept(sys, num_forest);
  Buffer<uint32_t, System> nodes(sys, num_nodes), kept_nodes(sys, num_nodes), parent(sys, num_nodes),
      target(sys, num_nodes);
  Buffer<uint64_t, System> path(sys, num_nodes);
  Buffer<unsigned long long, System> best(sys, num_nodes);
  thrust::sequence(policy, parent.data(), parent.data() + num_nodes);
  thrust::sequence(policy, nodes.data(), nodes.data() + num_nodes);
  thrust::fill_n(policy, best.data(), num_nodes, ~0ull);
  enum Count { kLiveEdges, kKeptEdges, kLiveNodes, kKeptNodes, kSpliced, kSplicedLast, kJumped, kNumCounts };
  Buffer<uint32_t, System> counts(sys, kNumCounts);
  uint32_t* count = counts.data();
  const uint32_t initial[kNumCounts] = {num_forest, 0, num_nodes, 0, 0, 0, 0};
  sys.FromHost(count, initial, kNumCounts);
  // Below this many live edges a round costs more than the host's steps for all of them.
  constexpr uint32_t kHostFinishBelow = 1024;
  constexpr int kJumpsPerCheck = 3;
  auto jump_group = [&] {
    for (int j = 0; j + 1 < kJumpsPerCheck; ++j) {
      sys.ForEachBelow(count + kLiveNodes, JumpHookPath{nodes.data(), eldest, path.data(), nullptr});
    }
    sys.RunSingle(ClearFlag{count + kJumped});
    sys.ForEachBelow(count + kLiveNodes, JumpHookPath{nodes.data(), eldest, path.data(), count + kJumped});
  };
  // Declared after the buffers: destroyed (after the stream's last replay) before them.
  typename System::Recording hook_round, more_jumps, splice_round;
  uint32_t live = num_forest;
  // One wait a round (more only while the jumps have not converged): the counts of the previous
  // round's splices are read with the hooks' convergence flag.
  for (uint32_t round = 0;; ++round) {
    if (round > num_forest + 1)
      throw EngineError(EngineError::Kind::kInternal, "persistence: forest rounds did not end");
    sys.Replay(hook_round, [&] {
      // Every live node's slot, so that a node whose edges are all gone hooks nowhere and leaves.
      sys.ForEachBelow(count + kLiveNodes, ResetBest{nodes.data(), best.data()});
      sys.ForEachBelow(count + kLiveEdges, OfferLightestEdge{forest, best.data()});
      sys.ForEachBelow(count + kLiveEdges, RecordHookTarget{forest, best.data(), target.data()});
      sys.ForEachBelow(count + kLiveNodes,
                       StartHookPath{nodes.data(), best.data(), target.data(), eldest, path.data()});
      jump_group();
    });
    uint32_t now[kNumCounts] = {};
    sys.Download({{now, count, sizeof(now)}});
    live = now[kLiveEdges];
    if (round > 0) {
      const uint32_t spliced = now[kSplicedLast];
      if (spliced == 0) throw EngineError(EngineError::Kind::kInternal, "persistence: a forest round spliced nothing");
      if (host_finish && static_cast<uint64_t>(spliced) * 8 < static_cast<uint64_t>(live) + spliced) break;
    }
    if (live == 0 || (host_finish && live < kHostFinishBelow)) break;
    report->rounds = round + 1;
    uint32_t jumped = now[kJumped];
    for (int group = 0; jumped != 0; ++group) {
      if (group > 32) throw EngineError(EngineError::Kind::kInternal, "persistence: pointer jumping did not converge");
      sys.Replay(more_jumps, jump_group);
      jumped = sys.Read(count + kJumped);
    }
    sys.Replay(splice_round, [&] {
      sys.ForEachBelow(count + kLiveNodes, SpliceYoungNode{nodes.data(), best.data(), eldest, path.data(),
                                                           parent.data(), killed_age, mark_xor, count + kSpliced});
      sys.ForEachBelow(count + kLiveEdges, RelabelEdge{forest, parent.data()});
      sys.AppendIf(count + kLiveEdges, 1, forest, forest, JoinsTwoComponents{}, kept.data(), count + kKeptEdges);
      sys.ForEachBelow(count + kKeptEdges, CopyItem<WeightedEdge>{kept.data(), forest});
      sys.AppendIf(count + kLiveNodes, 1, nodes.data(), nodes.data(), StaysLive{parent.data(), best.data()},
                   kept_nodes.data(), count + kKeptNodes);
      sys.ForEachBelow(count + kKeptNodes, CopyItem<uint32_t>{kept_nodes.data(), nodes.data()});
      sys.RunSingle(TakeKeptItems{count + kLiveEdges, count + kKeptEdges, count + kLiveNodes, count + kKeptNodes,
                                  count + kSpliced, count + kSplicedLast});
    });
  }
  report->forest_edges = num_forest;
  report->host_finished_edges = live;
  if (live == 0) return;
  Buffer<uint64_t, System> end_ages(sys, 2 * size_t{live});
  thrust::for_each_n(policy, zero, live, GatherEndAges{forest, eldest, end_ages.data()});
  std::vector<WeightedEdge> host_edges(live);
  std::vector<uint64_t> host_ages(2 * size_t{live});
  sys.Download({{host_edges.data(), forest, live * sizeof(WeightedEdge)},
                {host_ages.data(), end_ages.data(), host_ages.size() * sizeof(uint64_t)}});
  std::vector<uint32_t> index;
  std::vector<uint64_t> killed;
  FinishElderRuleOnHost(host_edges, host_ages, mark_xor, &index, &killed);
  Buffer<uint32_t, System> index_buffer(sys, live);
  Buffer<uint64_t, System> killed_buffer(sys, live);
  sys.Upload({{index.data(), index_buffer.data(), live * sizeof(uint32_t)},
              {killed.data(), killed_buffer.data(), live * sizeof(uint64_t)}});
  thrust::for_each_n(policy, zero, live, ScatterKilled{index_buffer.data(), killed_buffer.data(), killed_age});
}

/// Whether a graph edge is one of the forest's (by its mark).
struct InForest {
  const uint8_t* mark;
  uint32_t mark_xor;
  GALPHA_HD bool operator()(const WeightedEdge& e) const {
    return mark[(static_cast<uint32_t>(e.weight) ^ mark_xor) - 1u] != 0;
  }
};

/// Marks by canonical position the minimum spanning forest of a graph whose edges are `graph` (one
/// per family edge, weighted by their filtration keys; clobbered as working space).
template <class System>
void MarkSpanningForest(System& sys, WeightedEdge* graph, uint32_t num_edges, uint32_t num_nodes, EdgeCycles cycles,
                        uint32_t num_cycles, uint8_t* forest_mark) {
  thrust::fill_n(sys.policy(), forest_mark, num_edges, uint8_t{0});
  ForestOutputs out;
  out.forest_mark = forest_mark;
  out.keep_never = true;
  SpanningForest(sys, graph, num_edges, num_nodes, cycles, num_cycles, out);
}

// ---- The pairs ---------------------------------------------------------------------------------

/// The dual forest is the primal forest's complement (tree-cotree duality). The mesh's edges form
/// a connected plane graph (the triangulation of the visible distinct points; hidden points and
/// duplicates are isolated nodes, in no edge), its faces the triangles and the outer face, and the
/// weights are unique. An edge e outside the primal minimum spanning tree T is the heaviest edge of
/// its fundamental cycle in T + e; the edges of a plane cycle are, in the dual, the edges of a cut,
/// so e is the heaviest edge of a dual cut, and the maximum spanning tree of the dual (the minimum
/// of the complemented weights: the dual forest) contains it (the cut property). So E \ T is in the
/// dual tree, and both have E - V + 1 = F - 1 edges (Euler: V - E + F = 2, F = T + 1 faces): they
/// are equal. The count is checked; the host's union-finds (core/family/persistence.cpp), which
/// find both forests independently and check the duality edge by edge, are the tests' oracle.
struct OutsideForest {
  const uint8_t* forest;
  GALPHA_HD uint8_t operator()(uint32_t p) const { return forest[p] == 0 ? 1 : 0; }
};

struct RecordVertexKiller {
  const uint8_t* primal_forest;
  const uint64_t* killed_age;
  uint32_t* killer_position;
  GALPHA_HD void operator()(uint32_t p) const {
    if (primal_forest[p] != 0) killer_position[static_cast<uint32_t>(killed_age[p])] = p;
  }
};

constexpr uint32_t kNoPosition = 0xFFFFFFFFu;

/// H0: a distinct, visible point's class; dropped (dimension 2) when killed at rank 0.
struct ComponentPair {
  const uint32_t* representative;
  const uint8_t* hidden;
  const uint32_t* killer_position;
  const uint32_t* edge_order;
  const uint32_t* rho;
  const uint32_t* mu_low;
  GALPHA_HD PersistencePair operator()(uint32_t v) const {
    PersistencePair pair;
    pair.dimension = 2;
    if (representative[v] != v || (hidden != nullptr && hidden[v] != 0)) return pair;
    pair.creator = v;
    pair.birth_rank = 0;
    const uint32_t p = killer_position[v];
    if (p == kNoPosition) {
      pair.dimension = 0;
      pair.death_rank = kNeverRank;
      pair.killer = kNoSimplex;
      return pair;
    }
    const uint32_t e = edge_order[p];
    const uint32_t death = EdgeBirthRank(rho[e], mu_low[e]);
    if (death == 0) return pair;
    pair.dimension = 0;
    pair.death_rank = death;
    pair.killer = death == kNeverRank ? kNoSimplex : e;
    return pair;
  }
};

/// H1: a dual forest edge's class (in canonical order of its creator edge); dropped (dimension 2)
/// when it dies where it is born.
struct HolePair {
  const uint8_t* dual_forest;
  const uint64_t* killed_age;
  const uint32_t* edge_order;
  const uint32_t* triangle_order;
  const uint32_t* rho;
  const uint32_t* mu_low;
  GALPHA_HD PersistencePair operator()(uint32_t p) const {
    PersistencePair pair;
    pair.dimension = 2;
    if (dual_forest[p] == 0) return pair;
    const uint64_t key = ~killed_age[p];  // the killing triangle's (rank, position); never the outer face's
    const uint32_t e = edge_order[p];
    const uint32_t birth = EdgeBirthRank(rho[e], mu_low[e]), death = static_cast<uint32_t>(key >> 32);
    if (death <= birth) return pair;
    pair.dimension = 1;
    pair.birth_rank = birth;
    pair.death_rank = death;
    pair.creator = e;
    pair.killer = death == kNeverRank ? kNoSimplex : triangle_order[static_cast<uint32_t>(key)];
    return pair;
  }
};

struct IsListed {
  GALPHA_HD bool operator()(const PersistencePair& pair) const { return pair.dimension != 2; }
};

struct DeathKey {
  GALPHA_HD uint32_t operator()(const PersistencePair& pair) const { return pair.death_rank; }
};

struct BirthDeathKey {
  GALPHA_HD uint64_t operator()(const PersistencePair& pair) const {
    return (static_cast<uint64_t>(pair.birth_rank) << 32) | pair.death_rank;
  }
};

/// The sort key of the candidate an index names.
template <class KeyOf>
struct KeyOfCandidate {
  const PersistencePair* candidates;
  KeyOf key_of;
  GALPHA_HD auto operator()(uint32_t i) const { return key_of(candidates[i]); }
};

/// The listed pairs of `candidates` (made in the order of their last sort field: H0 by vertex,
/// H1 by the creator's canonical position), stably sorted by `key`, into `*listed`; their number.
/// The sort moves 4-byte indices beside the keys, not the 20-byte pairs, which are gathered once
/// in the end (the same order: a stable sort of the same keys).
template <class System, class Key, class KeyOf>
uint32_t SortedPairs(System& sys, Buffer<PersistencePair, System>& candidates, uint32_t num_candidates, KeyOf key_of,
                     Buffer<PersistencePair, System>* listed) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> index(sys, num_candidates);
  const auto num_listed = static_cast<uint32_t>(
      thrust::copy_if(policy, zero, zero + num_candidates, candidates.data(), index.data(), IsListed{}) - index.data());
  {
    Buffer<Key, System> keys(sys, num_listed);
    thrust::transform(policy, index.data(), index.data() + num_listed, keys.data(),
                      KeyOfCandidate<KeyOf>{candidates.data(), key_of});
    thrust::stable_sort_by_key(policy, keys.data(), keys.data() + num_listed, index.data());
  }
  *listed = Buffer<PersistencePair, System>(sys, num_listed);
  thrust::gather(policy, index.data(), index.data() + num_listed, candidates.data(), listed->data());
  return num_listed;
}

/// The diagram of core/family/persistence.hpp, pair for pair, from the family's canonical
/// `orders`. `primal_forest_found`: the primal forest's edges marked by canonical position where the
/// build's component curves found them (TopologyCurvesOut::general_forest_mark: the same forest,
/// their general graph then having these weights and edges), or null to find it here.
/// `host_finish`: pair the forests' slow tails on the host (PairBySplicing); false runs every round
/// on the system (tests). Throws EngineError kInternal if the family's mesh is no connected plane
/// triangulation.
template <class System>
void PersistenceDiagramOnSystem(System& sys, const PersistenceIn& in, const CanonicalOrders<System>& orders,
                                const uint8_t* primal_forest_found, bool host_finish, StageTimer<System>& timer,
                                PersistenceOut* out) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_edges = in.num_edges, num_tri = in.num_tri;
  const uint32_t* edge_order = orders.edge_order.data();
  const uint32_t* triangle_order = orders.triangle_order.data();
  const EdgeFiltrationKey key{in.edge_rho_rank, in.edge_mu_low, orders.edge_position.data()};

  Buffer<WeightedEdge, System> graph(sys, num_edges);
  Buffer<uint8_t, System> primal_forest(sys, primal_forest_found != nullptr ? 0 : num_edges),
      dual_forest(sys, num_edges);
  const uint8_t* primal_marks = primal_forest_found != nullptr ? primal_forest_found : primal_forest.data();
  Buffer<uint64_t, System> primal_killed(sys, num_edges), dual_killed(sys, num_edges);
  {
    Buffer<uint64_t, System> age(sys, in.num_points);
    thrust::transform(policy, zero, zero + in.num_points, age.data(), IdentityAge{});
    if (primal_forest_found == nullptr) {
      thrust::transform(policy, zero, zero + num_edges, graph.data(), PrimalEdge{in.edges, key});
      // Cycles: each triangle's edges.
      MarkSpanningForest(sys, graph.data(), num_edges, in.num_points, EdgeCycles{in.edge_tris, nullptr}, num_tri,
                         primal_forest.data());
    }
    const auto num_forest = static_cast<uint32_t>(
        thrust::copy_if(policy, thrust::make_transform_iterator(zero, PrimalEdge{in.edges, key}),
                        thrust::make_transform_iterator(zero + num_edges, PrimalEdge{in.edges, key}), graph.data(),
                        InForest{primal_marks, 0u}) -
        graph.data());
    PairBySplicing(sys, graph.data(), num_forest, in.num_points, age.data(), 0u, host_finish, primal_killed.data(),
                   &out->report.forests[0]);
  }
  // H0's pairs go to the host while the dual forest is computed. The host array has room for
  // every H1 pair too (at most one a dual forest edge: num_tri); it is not zeroed first
  // (PersistencePair is trivial), so the copies are the first touch of what is used.
  Buffer<PersistencePair, System> components(sys, 0);
  uint32_t num_components = 0;
  {
    Buffer<uint32_t, System> killer_position(sys, in.num_points);
    thrust::fill_n(policy, killer_position.data(), in.num_points, kNoPosition);
    thrust::for_each_n(policy, zero, num_edges,
                       RecordVertexKiller{primal_marks, primal_killed.data(), killer_position.data()});
    Buffer<PersistencePair, System> candidates(sys, in.num_points);
    thrust::transform(policy, zero, zero + in.num_points, candidates.data(),
                      ComponentPair{in.representative, in.hidden, killer_position.data(), edge_order, in.edge_rho_rank,
                                    in.edge_mu_low});
    num_components = SortedPairs<System, uint32_t>(sys, candidates, in.num_points, DeathKey{}, &components);
  }
  out->pairs = HostVector<PersistencePair>(size_t{num_components} + num_tri);
  out->num_h0 = num_components;
  // Declared after `components`, which it reads: destroyed (waiting for the copy) before it.
  auto components_download =
      sys.DownloadAsync({{out->pairs.data(), components.data(), num_components * sizeof(PersistencePair)}});
  timer.EndStage("persistence_h0");
  {
    thrust::transform(policy, zero, zero + num_edges, dual_forest.data(), OutsideForest{primal_marks});
    const auto num_dual = static_cast<uint32_t>(
        thrust::copy_if(policy, thrust::make_transform_iterator(zero, DualEdge{in.edge_tris, num_tri, key}),
                        thrust::make_transform_iterator(zero + num_edges, DualEdge{in.edge_tris, num_tri, key}),
                        graph.data(), InForest{dual_forest.data(), 0xFFFFFFFFu}) -
        graph.data());
    if (num_dual != num_tri) {
      throw EngineError(EngineError::Kind::kInternal,
                        "persistence: the mesh is no connected plane triangulation (" + std::to_string(num_edges) +
                            " edges, " + std::to_string(num_edges - num_dual) + " in a spanning tree, " +
                            std::to_string(num_tri) + " triangles)");
    }
    Buffer<uint64_t, System> age(sys, size_t{num_tri} + 1);
    thrust::transform(policy, zero, zero + (num_tri + 1), age.data(),
                      DualNodeAge{in.tri_rank, orders.triangle_position.data(), num_tri});
    PairBySplicing(sys, graph.data(), num_dual, num_tri + 1, age.data(), 0xFFFFFFFFu, host_finish, dual_killed.data(),
                   &out->report.forests[1]);
  }
  timer.EndStage("persistence_h1");
  graph.Reset();
  Buffer<PersistencePair, System> holes(sys, 0);
  uint32_t num_holes = 0;
  {
    Buffer<PersistencePair, System> candidates(sys, num_edges);
    thrust::transform(
        policy, zero, zero + num_edges, candidates.data(),
        HolePair{dual_forest.data(), dual_killed.data(), edge_order, triangle_order, in.edge_rho_rank, in.edge_mu_low});
    num_holes = SortedPairs<System, uint64_t>(sys, candidates, num_edges, BirthDeathKey{}, &holes);
  }
  if (num_holes > num_tri) throw EngineError(EngineError::Kind::kInternal, "persistence: more holes than triangles");
  timer.EndStage("persistence_pairs");
  sys.Download({{out->pairs.data() + num_components, holes.data(), num_holes * sizeof(PersistencePair)}});
  components_download.Wait();
  out->pairs.resize(size_t{num_components} + num_holes);  // smaller: no copy, no fill
  timer.EndStage("persistence_download");
}

/// The diagram, its canonical orders and both forests computed here (stage "persistence_orders").
template <class System>
void PersistenceDiagramOnSystem(System& sys, const PersistenceIn& in, bool host_finish, StageTimer<System>& timer,
                                PersistenceOut* out) {
  const CanonicalOrders<System> orders = CanonicalOrdersOf(sys, in);
  timer.EndStage("persistence_orders");
  PersistenceDiagramOnSystem(sys, in, orders, nullptr, host_finish, timer, out);
}

/// The diagram from a family's arrays in host memory (`host`): the CUDA system uploads them first
/// (stage "persistence_upload"), the OpenMP system reads them where they are. Without
/// `upload_tables`, `host`'s edge triangles and rank tables are in the system's memory already (a
/// resident family's) and only the mesh is uploaded.
template <class System>
void PersistenceDiagramUploading(System& sys, const PersistenceIn& host, bool upload_tables, bool host_finish,
                                 PersistenceOut* out) {
  StageTimer<System> timer(sys, &out->report.stage_times);
  if constexpr (System::kHostMemory) {
    PersistenceDiagramOnSystem(sys, host, host_finish, timer, out);
  } else {
    const size_t tables_edges = upload_tables ? host.num_edges : 0, tables_tri = upload_tables ? host.num_tri : 0;
    Buffer<EdgeIdx, System> edges(sys, host.num_edges);
    Buffer<EdgeTris, System> edge_tris(sys, tables_edges);
    Buffer<TriIdx, System> triangles(sys, host.num_tri);
    Buffer<uint32_t, System> rho(sys, tables_edges), mu_low(sys, tables_edges), tri_rank(sys, tables_tri),
        representative(sys, host.num_points);
    Buffer<uint8_t, System> hidden(sys, host.hidden != nullptr ? host.num_points : 0);
    std::vector<HostCopy> copies = {
        {const_cast<EdgeIdx*>(host.edges), edges.data(), host.num_edges * sizeof(EdgeIdx)},
        {const_cast<TriIdx*>(host.triangles), triangles.data(), host.num_tri * sizeof(TriIdx)},
        {const_cast<uint32_t*>(host.representative), representative.data(), host.num_points * sizeof(uint32_t)}};
    if (upload_tables) {
      copies.push_back({const_cast<EdgeTris*>(host.edge_tris), edge_tris.data(), host.num_edges * sizeof(EdgeTris)});
      copies.push_back({const_cast<uint32_t*>(host.edge_rho_rank), rho.data(), host.num_edges * sizeof(uint32_t)});
      copies.push_back({const_cast<uint32_t*>(host.edge_mu_low), mu_low.data(), host.num_edges * sizeof(uint32_t)});
      copies.push_back({const_cast<uint32_t*>(host.tri_rank), tri_rank.data(), host.num_tri * sizeof(uint32_t)});
    }
    if (host.hidden != nullptr) {
      copies.push_back({const_cast<uint8_t*>(host.hidden), hidden.data(), host.num_points * sizeof(uint8_t)});
    }
    sys.Upload(copies);
    timer.EndStage("persistence_upload");
    const PersistenceIn in{host.num_points,
                           host.num_edges,
                           host.num_tri,
                           edges.data(),
                           upload_tables ? edge_tris.data() : host.edge_tris,
                           triangles.data(),
                           upload_tables ? rho.data() : host.edge_rho_rank,
                           upload_tables ? mu_low.data() : host.edge_mu_low,
                           upload_tables ? tri_rank.data() : host.tri_rank,
                           representative.data(),
                           host.hidden != nullptr ? hidden.data() : nullptr};
    PersistenceDiagramOnSystem(sys, in, host_finish, timer, out);
  }
  timer.Finish();
}

}  // namespace galpha::detail
