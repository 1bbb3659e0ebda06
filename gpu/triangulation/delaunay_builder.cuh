// The Delaunay mesh under construction, written once over an execution system (CpuSystem or
// CudaSystem): insertion rounds with Lawson flips, then the repair of the hull. Its own header so
// that the pipeline around it (delaunay_impl.cuh) reads as its stages.
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include <thrust/copy.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/zip_iterator.h>
#include <thrust/remove.h>
#include <thrust/scan.h>
#include <thrust/sort.h>
#include <thrust/transform_scan.h>
#include <thrust/unique.h>
#include <cuda/atomic>

#include "core/exact/power.hpp"
#include "core/exact/predicates.hpp"
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_flip.cuh"
#include "gpu/triangulation/delaunay_insert.cuh"
#include "gpu/triangulation/mesh.cuh"
#include "gpu/triangulation/regular_removal.cuh"

namespace galpha::detail {

struct IsSet {
  GALPHA_HD bool operator()(uint8_t x) const { return x != 0; }
};

struct IsClear {
  GALPHA_HD bool operator()(uint8_t x) const { return x == 0; }
};

struct IsNonNegative {
  GALPHA_HD bool operator()(int32_t x) const { return x >= 0; }
  GALPHA_HD bool operator()(int8_t x) const { return x >= 0; }
};

struct IsFlatFiniteTriangle {
  MeshView mesh;
  GALPHA_HD bool operator()(int32_t t) const { return IsFlatTriangle(mesh, t); }
};

/// Weighted, after the flips and the hull repair: marks the vertices the mesh shows hidden, the
/// reflex vertex of every non-regular edge that could not flip (MeshView::BlockedVertex) and every
/// hull vertex that lies between its two hull neighbours on their line with its lift above theirs,
/// and counts the marks (a vertex may be counted twice; only zero matters). Marks are
/// kHiddenInMesh: hidden, still in the mesh.
struct MarkRedundantVertices {
  MeshView mesh;
  uint8_t* hidden;  // per vertex
  uint32_t* count;
  GALPHA_HD void Mark(int32_t v) const {
    if (hidden[v] != 0) return;
    hidden[v] = kHiddenInMesh;
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(*count).fetch_add(1u);
  }
  GALPHA_HD void operator()(int32_t t) const {
    const Tri x = mesh.tri[t];
    if (IsDeadTriangle(x)) return;
    int inf_pos = -1;
    for (int k = 0; k < 3; ++k) {
      if (x.v[k] == mesh.inf) inf_pos = k;
    }
    if (inf_pos < 0) {
      for (int k = 0; k < 3; ++k) {
        const int32_t v = mesh.BlockedVertex(t, k);
        if (v >= 0) Mark(v);
      }
      return;
    }
    // Hull edge u -> w; w's other hull edge lies in the infinite triangle across (w, inf).
    const int32_t u = x.v[Next(inf_pos)], w = x.v[Prev(inf_pos)];
    const int32_t other = mesh.NextHullVertex(t, Next(inf_pos), w);
    if (other == w || other == u) return;
    const Point2* pts = mesh.pts;
    if (Orient2dSign(pts[u], pts[w], pts[other]) == 0 && mesh.OnOpenSegment(u, other, w) &&
        CollinearPowerSign(pts[u], mesh.weight[u], pts[other], mesh.weight[other], pts[w], mesh.weight[w]) < 0) {
      Mark(w);
    }
  }
};

/// A packed build's sets as the builder sees them (delaunay_batch.cuh): many meshes, one a set, in
/// one mesh's arrays. Empty (num_sets 0) for a build of one set.
struct MeshSets {
  const uint32_t* vertex_set = nullptr;  // per vertex
  const int32_t* set_center = nullptr;   // per set, the vertices of its first triangle (MeshView)
  uint32_t num_sets = 0;                 // sets numbered below it (vertex_set's values)
};

/// A mesh's first four triangles, in slots base to base + 3 of `tri` and `nbr`: the first triangle
/// (a, b, c), counter-clockwise, and the three infinite triangles on its edges, linked.
GALPHA_HD inline void WriteFirstTriangles(int32_t a, int32_t b, int32_t c, int32_t inf, int32_t base, Tri* tri,
                                          TriNbr* nbr) {
  const Tri init[4] = {{{a, b, c}}, {{b, a, inf}}, {{c, b, inf}}, {{a, c, inf}}};
  for (int t = 0; t < 4; ++t) {
    TriNbr links{};
    for (int k = 0; k < 3; ++k) {
      const int32_t p = init[t].v[Next(k)], q = init[t].v[Prev(k)];
      for (int u = 0; u < 4; ++u) {
        for (int i = 0; i < 3; ++i) {
          if (u != t && init[u].v[Next(i)] == q && init[u].v[Prev(i)] == p) links.n[k] = base + u;
        }
      }
    }
    tri[base + t] = init[t];
    nbr[base + t] = links;
  }
}

/// The first four triangles of a set's mesh (WriteFirstTriangles), in slots 4j to 4j + 3 for the
/// j-th set with a mesh (`mesh_set[j]`), from its first triangle (MeshView::set_center).
struct StartSetMesh {
  MeshView mesh;
  const uint32_t* mesh_set;
  uint32_t* set_triangles;  // SetRoundState::triangles
  GALPHA_HD void operator()(uint32_t j) const {
    const int32_t* center = mesh.set_center + 3 * static_cast<size_t>(mesh_set[j]);
    WriteFirstTriangles(center[0], center[1], center[2], mesh.inf, 4 * static_cast<int32_t>(j), mesh.tri, mesh.nbr);
    set_triangles[mesh_set[j]] = 4;
  }
};

/// Marks the sets that hold a flat finite triangle (a packed build leaves them to builds of their
/// own: the hull repair chooses parallel or serial rounds, and the device or the host, globally).
struct MarkSetOfFlatTriangle {
  MeshView mesh;
  uint8_t* set_has_flat;
  GALPHA_HD void operator()(int32_t t) const {
    if (IsFlatTriangle(mesh, t)) set_has_flat[mesh.vertex_set[mesh.tri[t].v[0]]] = 1;
  }
};

/// The working state of one triangulation and the steps that change it.
///
/// Weighted (`weight` set), it builds the regular triangulation of the points it is given, with
/// the points it finds hidden on the way marked in `hidden` (per vertex) and left out; a point that
/// turns out hidden only after it was inserted is found by MarkRedundant and removed in place by
/// RemoveMarked (regular_removal.cuh), or, on the hull, by the caller building again without it
/// (delaunay_impl.cuh).
///
/// Packed (`sets` not empty): the disjoint meshes of many sets, each started from its own first
/// triangle (StartSets), whose insertion rounds are each the rounds its set would have alone
/// (SetRoundState): every set's triangles then take the slots, in the same order, that they take in
/// a build of that set alone, and its output is that build's (delaunay_batch.cuh).
template <class System>
class DelaunayBuilder {
 public:
  DelaunayBuilder(System& sys, const Point2* vertex_points, const uint32_t* sos, const uint32_t* sos_rank,
                  const double* weight, uint8_t* hidden, uint32_t m, int32_t a, int32_t b, int32_t c,
                  MeshSets sets = {})
      : sys_(sys),
        hidden_(hidden),
        m_(m),
        capacity_(2 * m),
        tri_(sys, capacity_),
        nbr_(sys, capacity_),
        tri_vote_(sys, capacity_),
        edge_vote_(sys, capacity_),
        edge_third_vote_(sys, 0),
        split_count_or_nb_(sys, capacity_),
        flip_vote_(sys, capacity_),
        partner_(sys, capacity_),
        stamp_(sys, capacity_),
        active_(sys, capacity_),
        active_mask_(sys, capacity_),
        candidate_mask_(sys, 2 * capacity_),
        proposal_edge_(sys, capacity_),
        flags_(sys, 4),
        counts_(sys, kNumCounts),
        num_sets_(sets.num_sets),
        set_flags_(sys, num_sets_),
        set_counts_(sys, 5 * static_cast<size_t>(num_sets_)) {
    mesh_ = MeshView{vertex_points, sos, tri_.data(), nbr_.data(), static_cast<int32_t>(m), a, b, c, sos_rank, weight};
    mesh_.vertex_set = sets.vertex_set;
    mesh_.set_center = sets.set_center;
    if (num_sets_ > 0) {
      thrust::fill(sys_.policy(), set_flags_.begin(), set_flags_.end(), uint8_t{0});
      thrust::fill(sys_.policy(), set_counts_.begin(), set_counts_.end(), 0u);
    }
    thrust::fill(sys_.policy(), flip_vote_.begin(), flip_vote_.end(), kNoFlipVote);
    thrust::fill(sys_.policy(), partner_.begin(), partner_.end(), kNoPartner);
    thrust::fill(sys_.policy(), stamp_.begin(), stamp_.end(), 0u);
    thrust::fill(sys_.policy(), flags_.begin(), flags_.end(), 0);
    thrust::fill(sys_.policy(), counts_.begin(), counts_.end(), 0u);
  }

  /// Frees everything but the mesh once it is final (before the output stage).
  void ReleaseWorkspace() {
    tri_vote_.Reset();
    edge_vote_.Reset();
    edge_third_vote_.Reset();
    split_count_or_nb_.Reset();
    flip_vote_.Reset();
    partner_.Reset();
    stamp_.Reset();
    active_.Reset();
    active_mask_.Reset();
    candidate_mask_.Reset();
    proposal_edge_.Reset();
  }

  int32_t num_triangles() const { return num_tri_; }
  const MeshView& mesh() const { return mesh_; }
  int rounds() const { return rounds_; }

  /// Starts from the triangle (a, b, c), counter-clockwise, and its three infinite neighbours.
  void Start(int32_t a, int32_t b, int32_t c) {
    Tri init[4];
    TriNbr links[4];
    WriteFirstTriangles(a, b, c, mesh_.inf, 0, init, links);
    sys_.FromHost(tri_.data(), init, 4);
    sys_.FromHost(nbr_.data(), links, 4);
    num_tri_ = 4;
  }

  /// Packed: starts each of `num_meshes` sets from its first triangle (MeshSets::set_center of
  /// `mesh_set[j]`) as Start does, in slots 4j to 4j + 3.
  void StartSets(const uint32_t* mesh_set, uint32_t num_meshes) {
    thrust::for_each(sys_.policy(), thrust::counting_iterator<uint32_t>(0),
                     thrust::counting_iterator<uint32_t>(num_meshes),
                     StartSetMesh{mesh_, mesh_set, set_rounds().triangles});
    num_tri_ = 4 * static_cast<int32_t>(num_meshes);
  }

  /// Packed: marks in `set_has_flat` (per set, cleared by the caller) the sets whose mesh holds a
  /// flat finite triangle, in place of RepairHull.
  void MarkSetsWithFlatTriangles(uint8_t* set_has_flat) {
    const thrust::counting_iterator<int32_t> tfirst(0);
    thrust::for_each(sys_.policy(), tfirst, tfirst + num_tri_, MarkSetOfFlatTriangle{mesh_, set_has_flat});
  }

  /// Inserts every pending vertex in rounds; `location` starts at a triangle of the mesh.
  ///
  /// Each round waits for the device once, for the number of points elected (the mesh's size on
  /// the host sizes the next launches). The other counts stay on the device: the pending points
  /// left after a round are counted there, the next round's vote strides over that count, and the
  /// host learns it with the round's one wait.
  void InsertAll(int32_t* pending, int32_t* location, uint8_t* inserted, uint32_t num_pending) {
    auto pol = sys_.policy();
    uint32_t* pending_count = counts_.data() + kPendingCount;
    thrust::fill(pol, pending_count, pending_count + 1, num_pending);
    Relocate(pending, location, inserted, num_pending);
    if (hidden_ != nullptr) {
      // The points the first triangle hides leave before the first votes (later rounds drop theirs
      // after relocating). The host learns the new count with the first round's wait.
      auto zipped = thrust::make_zip_iterator(thrust::make_tuple(pending, location));
      sys_.SelectFlaggedInPlace(zipped, inserted, num_pending, IsClear(), pending_count);
      thrust::fill(pol, inserted, inserted + num_pending, uint8_t{0});
    }
    uint32_t* second_count = counts_.data() + kSecondCount;
    uint32_t* saw_edge_point = counts_.data() + kSawEdgePoint;
    // Second winners need points on edges' lines; a round whose votes saw none (uniform input,
    // every round; a circle's points) makes the next one run without them, and without the two
    // passes they cost.
    bool second_winners = true;
    // Points outside the hull vote for two supports of their sector (VoteForInsertion) in rounds
    // after one where at least a quarter of the splits added a hull vertex: a circle's points,
    // all hull vertices, then split each arc in three parts a round instead of two (at 1M: 22
    // rounds and 214 one-block flip iterations instead of 28 and 288; uniform input takes 21 and
    // 68). Later rounds of uniform input add few hull vertices, and run without the second
    // winners' passes. Unweighted only.
    bool sector_pairs = false;
    uint32_t sector_splits_before = 0;
    uint32_t last_splits = 0;
    // Packed, each set decides these for its own rounds (DecideSetRounds); the host's then say
    // whether any set's round has them.
    const SetRoundState sets = set_rounds();
    uint32_t* sets_with_second_winners = counts_.data() + kSetsWithSecondWinners;
    if (num_sets_ > 0) {
      thrust::for_each(pol, thrust::counting_iterator<uint32_t>(0), thrust::counting_iterator<uint32_t>(num_sets_),
                       StartSetRounds{sets});
    }
    for (;;) {
      ++rounds_;
      unsigned long long* edge_vote = second_winners ? edge_vote_.data() : nullptr;
      // Votes by thirds (VoteForInsertion), unweighted only, from the round after one that saw a
      // point on an edge's line: their slots are allocated then, so that input without such
      // points (uniform) never holds them.
      unsigned long long* edge_third_vote =
          second_winners && edge_third_vote_.size() > 0 ? edge_third_vote_.data() : nullptr;
      // Points on slivers' edge lines are counted where they may wait (SliverEdgeWait): rounds
      // with second winners, unweighted.
      uint32_t* sliver_edge_points = second_winners && hidden_ == nullptr ? sliver_edge_counts() : nullptr;
      const thrust::counting_iterator<int32_t> tfirst(0);
      thrust::for_each(
          pol, tfirst, tfirst + num_tri_,
          ResetVotes{tri_vote_.data(), edge_vote, edge_third_vote, second_count, saw_edge_point, sliver_edge_points});
      WithWeightedness([&](auto weighted) {
        sys_.ForEachBelow(pending_count,
                          VoteForInsertion<decltype(weighted)::value>{
                              mesh_, pending, location, tri_vote_.data(), edge_vote, saw_edge_point, edge_third_vote,
                              sector_pairs, mesh_.vertex_set, sets, sliver_edge_points});
      });
      if (second_winners) {
        const SliverEdgeWait wait{sliver_edge_points, pending_count, num_tri_, mesh_.tri, mesh_.vertex_set, sets};
        thrust::for_each(pol, tfirst, tfirst + num_tri_,
                         PickSecondWinners{tri_vote_.data(), edge_vote_.data(), edge_third_vote, second_count, wait});
      }
      // Inclusive, so that its last entry is the number of splits.
      thrust::transform_inclusive_scan(pol, tri_vote_.data(), tri_vote_.data() + num_tri_, split_count_or_nb_.data(),
                                       HasWinner(), thrust::plus<int32_t>());
      if (num_sets_ > 0) {
        thrust::fill(pol, sets_with_second_winners, sets_with_second_winners + 1, 0u);
        thrust::for_each(pol, thrust::counting_iterator<uint32_t>(0), thrust::counting_iterator<uint32_t>(num_sets_),
                         DecideSetRounds{sets, hidden_ != nullptr, sets_with_second_winners});
      }
      // The round's one wait: splits, second splits, pending points, and whether a relocation
      // walk failed or the last round's flip loop reached its cap.
      int32_t num_split = 0;
      uint32_t num_second = 0;
      int32_t walk_failed = 0;
      int32_t second_left_parent = 0;
      int32_t flips_capped = 0;
      uint32_t saw_edge = 0;
      uint32_t sector_splits = 0;
      uint32_t num_sets_with_second = 0;
      std::vector<HostCopy> round_counts{{&num_split, split_count_or_nb_.data() + num_tri_ - 1, sizeof(int32_t)},
                                         {&sector_splits, counts_.data() + kSectorSplits, sizeof(uint32_t)},
                                         {&num_second, second_count, sizeof(uint32_t)},
                                         {&saw_edge, saw_edge_point, sizeof(uint32_t)},
                                         {&num_pending, pending_count, sizeof(uint32_t)},
                                         {&walk_failed, flags_.data(), sizeof(int32_t)},
                                         {&second_left_parent, flags_.data() + 2, sizeof(int32_t)},
                                         {&flips_capped, flags_.data() + kFlipLoopCapped, sizeof(int32_t)}};
      if (num_sets_ > 0) round_counts.push_back({&num_sets_with_second, sets_with_second_winners, sizeof(uint32_t)});
      sys_.Download(round_counts);
      if (flips_capped != 0) throw EngineError(EngineError::Kind::kInternal, "flipping did not terminate");
      if (second_left_parent != 0) {
        throw EngineError(EngineError::Kind::kInternal, "a second winner of an insertion round left its triangle");
      }
      if (walk_failed != 0) throw EngineError(EngineError::Kind::kInternal, "point location walk did not terminate");
      if (num_pending == 0) return;
      if (num_split == 0) throw EngineError(EngineError::Kind::kInternal, "insertion round elected no point");
      // The previous round's splits (first and second) and how many of them were on the hull.
      const uint32_t last_sector_splits = sector_splits - sector_splits_before;
      sector_splits_before = sector_splits;
      sector_pairs = hidden_ == nullptr && 4 * uint64_t{last_sector_splits} >= last_splits && last_splits > 0;
      last_splits = static_cast<uint32_t>(num_split) + num_second;
      second_winners = num_sets_ > 0 ? num_sets_with_second > 0 : saw_edge != 0 || sector_pairs;
      if (second_winners && hidden_ == nullptr && edge_third_vote_.size() == 0) {
        edge_third_vote_ = Buffer<unsigned long long, System>(sys_, capacity_);
      }
      SplitElected(pending, inserted, num_split, /*num_listed=*/3, 0);
      if (num_second > 0) {
        // The second winners split the children that hold them; the number of those splits is
        // known without a wait (one per triangle that had a second winner).
        const int32_t num_tri_before = num_tri_ - 2 * num_split;
        thrust::fill(pol, tri_vote_.data(), tri_vote_.data() + num_tri_, kNoVote);
        thrust::for_each(
            pol, tfirst, tfirst + num_tri_before,
            PlaceSecondWinners{mesh_, pending, edge_vote_.data(), split_count_or_nb_.data(), num_tri_before,
                               tri_vote_.data(), flags_.data(), flags_.data() + 2, m_ + 16u});
        thrust::transform_inclusive_scan(pol, tri_vote_.data(), tri_vote_.data() + num_tri_, split_count_or_nb_.data(),
                                         HasWinner(), thrust::plus<int32_t>());
        SplitElected(pending, inserted, static_cast<int32_t>(num_second), /*num_listed=*/2, 3 * num_split);
      }
      const uint32_t num_active = static_cast<uint32_t>(3 * num_split) + 2 * num_second;
      thrust::fill(pol, active_mask_.data(), active_mask_.data() + num_active, kCheckOutsideEdge);
      RestoreDelaunay(num_active, /*hull_may_change=*/true);

      Relocate(pending, location, inserted, num_pending);
      auto zipped = thrust::make_zip_iterator(thrust::make_tuple(pending, location));
      sys_.SelectFlaggedInPlace(zipped, inserted, num_pending, IsClear(), pending_count);
      thrust::fill(pol, inserted, inserted + num_pending, uint8_t{0});
    }
  }

  /// Weighted: marks the vertices the finished mesh shows hidden (MarkRedundantVertices) and
  /// returns how many it marked; zero means the mesh is the regular triangulation of its vertices.
  uint32_t MarkRedundant() {
    uint32_t* count = counts_.data() + kRedundantCount;
    thrust::fill(sys_.policy(), count, count + 1, 0u);
    const thrust::counting_iterator<int32_t> tfirst(0);
    thrust::for_each(sys_.policy(), tfirst, tfirst + num_tri_, MarkRedundantVertices{mesh_, hidden_, count});
    return sys_.Read(count);
  }

  /// Weighted: removes the vertices MarkRedundant marked from the mesh in place, in rounds of
  /// independent stars (regular_removal.cuh), then flips what they left to regular. Returns how
  /// many marked vertices are left in the mesh (hull vertices, or too many neighbours): the caller
  /// builds again without them.
  uint32_t RemoveMarked() {
    auto pol = sys_.policy();
    const thrust::counting_iterator<int32_t> vfirst(0);
    const thrust::counting_iterator<int32_t> tfirst(0);
    const thrust::counting_iterator<uint32_t> first(0);
    Buffer<int32_t, System> candidates(sys_, m_);
    auto num_candidates = static_cast<uint32_t>(
        thrust::copy_if(pol, vfirst, vfirst + m_, candidates.data(), IsHiddenInMesh{hidden_}) - candidates.data());
    if (num_candidates == 0) return 0;
    Buffer<int32_t, System> vertex_tri(sys_, m_);
    thrust::fill(pol, vertex_tri.begin(), vertex_tri.end(), -1);
    Buffer<unsigned long long, System> claim(sys_, static_cast<size_t>(num_tri_));
    Buffer<uint8_t, System> created(sys_, static_cast<size_t>(num_tri_));
    thrust::fill(pol, created.begin(), created.end(), uint8_t{0});
    uint32_t* removed = counts_.data() + kRedundantCount;
    thrust::for_each(pol, tfirst, tfirst + num_tri_, FindStarStart{mesh_, hidden_, vertex_tri.data()});
    for (;;) {
      thrust::fill(pol, claim.begin(), claim.end(), kNoClaim);
      thrust::fill(pol, removed, removed + 1, 0u);
      thrust::for_each(pol, first, first + num_candidates,
                       ClaimStar{mesh_, candidates.data(), vertex_tri.data(), claim.data()});
      thrust::for_each(pol, first, first + num_candidates,
                       RemoveClaimedStar{mesh_, candidates.data(), vertex_tri.data(), claim.data(), hidden_,
                                         created.data(), removed});
      if (sys_.Read(removed) == 0) break;
      num_candidates = static_cast<uint32_t>(
          thrust::remove_if(pol, candidates.data(), candidates.data() + num_candidates, RemovedFromMesh{hidden_}) -
          candidates.data());
      if (num_candidates == 0) break;
    }
    const auto num_active = static_cast<uint32_t>(
        thrust::copy_if(pol, tfirst, tfirst + num_tri_, created.data(), active_.data(), IsSet()) - active_.data());
    thrust::fill(pol, active_mask_.data(), active_mask_.data() + num_active, kCheckAllEdges);
    RestoreDelaunay(num_active, /*hull_may_change=*/false);
    return num_candidates;
  }

  /// Removes symbolically flat hull triangles, then re-flips the finite triangles to Delaunay
  /// with the hull fixed. Returns the number of repair flips.
  int32_t RepairHull() {
    auto pol = sys_.policy();
    const thrust::counting_iterator<int32_t> tfirst(0);
    const thrust::counting_iterator<uint32_t> first(0);
    // Found in the (larger, idle) candidate buffer, then moved to one of their own size.
    uint32_t num_flat = static_cast<uint32_t>(
        thrust::copy_if(pol, tfirst, tfirst + num_tri_, candidates(), IsFlatFiniteTriangle{mesh_}) - candidates());
    if (num_flat == 0) return 0;
    Buffer<int32_t, System> flat_now(sys_, num_flat);
    thrust::copy(pol, candidates(), candidates() + num_flat, flat_now.begin());
    // Each flat triangle is repaired by one flip of two triangles.
    Buffer<int32_t, System> flat_next(sys_, num_flat);
    Buffer<uint8_t, System> still_flat(sys_, num_flat);
    Buffer<int32_t, System> touched(sys_, 2 * static_cast<size_t>(num_flat));
    int32_t* flat = flat_now.data();
    int32_t* next = flat_next.data();
    uint32_t num_touched = 0;
    while (num_flat > 0) {
      thrust::for_each(
          pol, first, first + num_flat,
          ProposeFlatRepairs{mesh_, flat, proposal_edge_.data(), split_count_or_nb_.data(), flip_vote_.data()});
      thrust::for_each(pol, first, first + num_flat,
                       ExecuteFlips{mesh_, flat, proposal_edge_.data(), split_count_or_nb_.data(), flip_vote_.data(),
                                    partner_.data()});
      thrust::for_each(pol, first, first + num_flat,
                       LinkFlips{mesh_, flat, proposal_edge_.data(), split_count_or_nb_.data(), partner_.data()});
      thrust::for_each(pol, first, first + num_flat,
                       CollectFlatRepairs{flat, proposal_edge_.data(), split_count_or_nb_.data(), flip_vote_.data(),
                                          partner_.data(), candidates(), still_flat.data()});
      num_touched = static_cast<uint32_t>(thrust::copy_if(pol, candidates(), candidates() + 2 * num_flat,
                                                          touched.data() + num_touched, IsNonNegative()) -
                                          touched.data());
      const uint32_t remaining =
          static_cast<uint32_t>(thrust::copy_if(pol, flat, flat + num_flat, still_flat.data(), next, IsSet()) - next);
      std::swap(flat, next);
      // The smallest proposer always wins both of its votes, so every round repairs at least
      // one. Flat triangles wait on each other in chains and a round repairs one per chain: when a
      // round repairs fewer than one round costs in steps of the one-thread walk, that thread
      // walks the chains instead, depth-first, in time linear in what is left.
      const bool chains = num_flat - remaining < System::kRepairStepsPerRound;
      num_flat = remaining;
      if (num_flat > 0 && chains) {
        num_touched += RepairChainsSerially(flat, num_flat, next, touched.data() + num_touched);
        num_flat = 0;
      }
    }
    flat_now.Reset();
    flat_next.Reset();
    // Only triangles a repair flip changed can hold an edge that is no longer locally Delaunay.
    // A triangle may appear twice (two repair flips): de-duplicate before flipping in parallel.
    thrust::sort(pol, touched.begin(), touched.begin() + num_touched);
    const uint32_t num_active = static_cast<uint32_t>(
        thrust::unique_copy(pol, touched.begin(), touched.begin() + num_touched, active_.data()) - active_.data());
    thrust::fill(pol, active_mask_.data(), active_mask_.data() + num_active, kCheckAllEdges);
    RestoreDelaunay(num_active, /*hull_may_change=*/false);
    return static_cast<int32_t>(num_touched / 2);
  }

 private:
  /// Runs RepairFlatChainsSerially over the `num_flat` flat triangles left; returns the number of
  /// entries it wrote to `touched`. One device thread walks at global-memory latency (~4 us a
  /// triangle on an H100), so when the chains are long compared with the mesh, the mesh goes to
  /// the host, is repaired there by the same functor, and comes back (~100 bytes a point each way,
  /// ~20 ns a point). Insertion makes the points of hull lines hull vertices itself (HullEdgeConflict),
  /// so no generator measured leaves flat triangles here any more; nothing rules them out, though.
  uint32_t RepairChainsSerially(const int32_t* flat, uint32_t num_flat, int32_t* stack, int32_t* touched) {
    constexpr uint32_t kPointsPerDeviceWalkStep = 200;
    int32_t flips = 0;
    if constexpr (!System::kHostMemory) {
      if (num_flat > m_ / kPointsPerDeviceWalkStep) {
        std::vector<Tri> tri(num_tri_);
        std::vector<TriNbr> nbr(num_tri_);
        std::vector<Point2> pts(m_);
        std::vector<int32_t> host_flat(num_flat), host_stack(num_flat), host_touched(2 * size_t{num_flat});
        std::vector<uint32_t> on_stack(num_tri_, kNoFlipVote);
        sys_.ToHost(tri.data(), tri_.data(), tri.size());
        sys_.ToHost(nbr.data(), nbr_.data(), nbr.size());
        sys_.ToHost(pts.data(), mesh_.pts, pts.size());
        sys_.ToHost(host_flat.data(), flat, num_flat);
        MeshView host_mesh = mesh_;
        host_mesh.pts = pts.data();
        host_mesh.sos = nullptr;  // the repair decides by exact orientation only, never by SoS
        host_mesh.sos_rank = nullptr;
        host_mesh.weight = nullptr;  // nor by weights
        host_mesh.tri = tri.data();
        host_mesh.nbr = nbr.data();
        int32_t failed = 0;
        RepairFlatChainsSerially{host_mesh,       host_flat.data(), num_flat, host_stack.data(),
                                 on_stack.data(), &failed,          &flips,   host_touched.data()}(0);
        if (failed != 0) throw EngineError(EngineError::Kind::kInternal, "flat hull triangles could not be repaired");
        sys_.FromHost(tri_.data(), tri.data(), tri.size());
        sys_.FromHost(nbr_.data(), nbr.data(), nbr.size());
        sys_.FromHost(touched, host_touched.data(), 2 * static_cast<size_t>(flips));
        return 2 * static_cast<uint32_t>(flips);
      }
    }
    auto pol = sys_.policy();
    thrust::fill(pol, flags_.begin(), flags_.end(), 0);
    thrust::for_each(pol, thrust::counting_iterator<uint32_t>(0), thrust::counting_iterator<uint32_t>(1),
                     RepairFlatChainsSerially{mesh_, flat, num_flat, stack, flip_vote_.data(), flags_.data(),
                                              flags_.data() + 1, touched});
    if (sys_.Read(flags_.data()) != 0) {
      throw EngineError(EngineError::Kind::kInternal, "flat hull triangles could not be repaired");
    }
    flips = sys_.Read(flags_.data() + 1);
    return 2 * static_cast<uint32_t>(flips);
  }

  /// Splits the `num_split` triangles that tri_vote_ elected (split_count_or_nb_ holds the
  /// inclusive scan of their votes), re-links them and lists `num_listed` children of each in
  /// active_ from `active_offset` on; the mesh grows by two triangles a split.
  void SplitElected(const int32_t* pending, uint8_t* inserted, int32_t num_split, int num_listed,
                    int32_t active_offset) {
    auto pol = sys_.policy();
    const thrust::counting_iterator<int32_t> tfirst(0);
    thrust::for_each(pol, tfirst, tfirst + num_tri_,
                     SplitTriangles{mesh_, tri_vote_.data(), split_count_or_nb_.data(), pending, inserted, num_tri_,
                                    counts_.data() + kSectorSplits, set_rounds()});
    thrust::for_each(pol, tfirst, tfirst + num_tri_,
                     LinkSplitChildren{mesh_, tri_vote_.data(), split_count_or_nb_.data(), num_tri_});
    thrust::for_each(pol, tfirst, tfirst + num_tri_,
                     ListSplitChildren{tri_vote_.data(), split_count_or_nb_.data(), active_.data() + active_offset,
                                       num_tri_, num_listed});
    num_tri_ += 2 * num_split;
  }

  /// Calls f(std::true_type) for a weighted build and f(std::false_type) for a Delaunay one: the
  /// kernels that evaluate predicates are compiled once for each, so that Delaunay builds run none
  /// of the regular triangulation's code (measured: up to 11% of insert_and_flip when they did).
  template <class F>
  void WithWeightedness(F&& f) {
    if (hidden_ != nullptr) {
      f(std::true_type{});
    } else {
      f(std::false_type{});
    }
  }

  /// Packed: each set's round state (empty pointers for a build of one set).
  SetRoundState set_rounds() {
    if (num_sets_ == 0) return {};
    uint32_t* counts = set_counts_.data();
    return SetRoundState{set_flags_.data(),
                         counts,
                         counts + num_sets_,
                         counts + 2 * size_t{num_sets_},
                         counts + 3 * size_t{num_sets_},
                         counts + 4 * size_t{num_sets_}};
  }

  /// The round's count of points on slivers' edge lines per triangle (SliverEdgeWait), in the
  /// split counts' buffer: the inclusive scan that fills it runs after PickSecondWinners reads them.
  uint32_t* sliver_edge_counts() {
    static_assert(sizeof(uint32_t) == sizeof(int32_t), "the counts share the split counts' buffer");
    return reinterpret_cast<uint32_t*>(split_count_or_nb_.data());
  }

  int32_t* candidates() {
    static_assert(sizeof(unsigned long long) == 2 * sizeof(int32_t), "candidates share the vote buffer");
    return reinterpret_cast<int32_t*>(tri_vote_.data());
  }

  /// Walks every pending point not inserted to the triangle that holds it now. A walk that fails
  /// leaves the point's old triangle and raises a flag, read with the round's count.
  void Relocate(const int32_t* pending, int32_t* location, uint8_t* inserted, uint32_t num_pending) {
    const thrust::counting_iterator<uint32_t> first(0);
    WithWeightedness([&](auto weighted) {
      thrust::for_each(sys_.policy(), first, first + num_pending,
                       RelocatePoint<decltype(weighted)::value>{mesh_, pending, inserted, location, hidden_,
                                                                flags_.data(), m_ + 16u});
    });
  }

  /// One parallel Lawson iteration over the `*count` triangles of active_: they propose flips,
  /// the winners flip and are re-linked, and what must be checked next replaces active_'s
  /// triangles, counted into `*next_count`. A short list is first flipped in one block
  /// (FlipTailInOneBlock), as many iterations as it takes, and leaves its result in active_ and
  /// `*count` (zero when done). Stream work only (recorded by RestoreDelaunay).
  void FlipIteration(uint32_t* count, uint32_t* next_count, bool hull_may_change) {
    uint32_t* generation = counts_.data() + kGeneration;
    WithWeightedness([&](auto weighted) {
      constexpr bool kWeighted = decltype(weighted)::value;
      sys_.RunInOneBlock(FlipTailInOneBlock<kWeighted>{
          mesh_, active_.data(), active_mask_.data(), proposal_edge_.data(), split_count_or_nb_.data(),
          flip_vote_.data(), partner_.data(), stamp_.data(), generation, candidates(), candidate_mask_.data(), count,
          counts_.data() + kTailCount, counts_.data() + kTailIterations, kFlipTailMaxCount, kFlipTailMaxIterations,
          hull_may_change});
      sys_.RunSingle(StartFlipIteration{next_count, generation});
      sys_.ForEachBelow(count,
                        ProposeFlips<kWeighted>{mesh_, active_.data(), active_mask_.data(), proposal_edge_.data(),
                                                split_count_or_nb_.data(), flip_vote_.data(), hull_may_change});
    });
    sys_.ForEachBelow(count, ExecuteFlips{mesh_, active_.data(), proposal_edge_.data(), split_count_or_nb_.data(),
                                          flip_vote_.data(), partner_.data()});
    sys_.ForEachBelow(
        count, LinkFlips{mesh_, active_.data(), proposal_edge_.data(), split_count_or_nb_.data(), partner_.data()});
    sys_.ForEachBelow(
        count, CollectNextActive{active_.data(), proposal_edge_.data(), split_count_or_nb_.data(), flip_vote_.data(),
                                 partner_.data(), stamp_.data(), generation, candidates(), candidate_mask_.data()});
    auto from = thrust::make_zip_iterator(thrust::make_tuple(candidates(), candidate_mask_.data()));
    auto to = thrust::make_zip_iterator(thrust::make_tuple(active_.data(), active_mask_.data()));
    sys_.AppendIf(count, 2, from, candidates(), IsNonNegative(), to, next_count);
  }

  /// Parallel Lawson flips from the `count` triangles in active_ until no edge needs a flip.
  ///
  /// Two iterations (their counts alternate between two words) are recorded once as the body of a
  /// loop that the device repeats while the list is not empty (System::ReplayWhile): the loop's
  /// hundreds of small kernels would otherwise be bound by the host's cost of launching them, and
  /// by its waits for the count. A loop that reaches kMaxFlipRuns raises a flag: the insertion
  /// round's wait reads it; here it is read at once for the other callers (hull repair, weighted
  /// removal), which are rare.
  void RestoreDelaunay(uint32_t count, bool hull_may_change) {
    if (count == 0) return;
    uint32_t* even = counts_.data() + kEvenIterationCount;
    uint32_t* odd = counts_.data() + kOddIterationCount;
    thrust::fill(sys_.policy(), even, even + 1, count);
    typename System::Recording& recording = hull_may_change ? insertion_flips_ : repair_flips_;
    const WhileCountNonzero more{even, counts_.data() + kFlipRuns, kMaxFlipRuns, flags_.data() + kFlipLoopCapped};
    sys_.ReplayWhile(recording, more, [&] {
      FlipIteration(even, odd, hull_may_change);
      FlipIteration(odd, even, hull_may_change);
    });
    if (!hull_may_change && sys_.Read(flags_.data() + kFlipLoopCapped) != 0) {
      throw EngineError(EngineError::Kind::kInternal, "flipping did not terminate");
    }
  }

  System& sys_;
  uint8_t* hidden_;  // per vertex, weighted only
  uint32_t m_;
  uint32_t capacity_;
  Buffer<Tri, System> tri_;
  Buffer<TriNbr, System> nbr_;
  // Insertion votes while splitting; while flipping, the same bytes hold 2 * capacity_ flip
  // candidates (int32): the two are never live at once, and sharing them saves 8 bytes a point.
  Buffer<unsigned long long, System> tri_vote_;
  // The votes of points on an edge's line (VoteForInsertion), then each triangle's second winner
  // (PickSecondWinners).
  Buffer<unsigned long long, System> edge_vote_;
  // The votes by thirds of points on the second half of an edge's line (VoteForInsertion); empty
  // until a round sees a point on an edge's line, and in weighted builds.
  Buffer<unsigned long long, System> edge_third_vote_;
  // Split counts (inclusive scan) while splitting, the neighbour of each flip proposal while
  // flipping: never both at once, so one buffer serves both.
  Buffer<int32_t, System> split_count_or_nb_;
  Buffer<uint32_t, System> flip_vote_;
  Buffer<int32_t, System> partner_;
  Buffer<uint32_t, System> stamp_;
  Buffer<int32_t, System> active_;
  Buffer<uint8_t, System> active_mask_;
  Buffer<uint8_t, System> candidate_mask_;
  Buffer<int8_t, System> proposal_edge_;
  // [0] walk or repair failed, [1] serial repair flips, [2] a second winner left its triangle,
  // [kFlipLoopCapped] a flip loop reached kMaxFlipRuns
  Buffer<int32_t, System> flags_;
  static constexpr int kFlipLoopCapped = 3;
  // Runs of RestoreDelaunay's loop body (two flip iterations each) before it gives up: far more
  // than any input measured needs (at 1M, a few a round: the one-block tail does most iterations).
  static constexpr uint32_t kMaxFlipRuns = 1u << 19;
  // Counts kept in system memory between the host's waits, and the flip stamps' generation.
  static constexpr int kPendingCount = 0;
  static constexpr int kEvenIterationCount = 1;
  static constexpr int kOddIterationCount = 2;
  static constexpr int kGeneration = 3;
  static constexpr int kTailCount = 4;
  static constexpr int kTailIterations = 5;
  static constexpr int kSecondCount = 6;
  static constexpr int kSawEdgePoint = 7;
  static constexpr int kRedundantCount = 8;
  static constexpr int kSectorSplits = 9;
  static constexpr int kFlipRuns = 10;  // WhileCountNonzero's runs of the loop under way
  static constexpr int kSetsWithSecondWinners = 11;
  static constexpr int kNumCounts = 12;
  // Lists of at most this many triangles are flipped in one block (FlipTailInOneBlock): one item a
  // lane of its 1,024, where a grid iteration's launches cost more than the block's passes.
  static constexpr uint32_t kFlipTailMaxCount = 1024;
  // The one-block iterations of a whole build: far more than any measured (two_lines at 1M: about
  // 3,700 flip iterations in all), and few enough (seconds, at a few us each) that a loop that did
  // not end soon reaches the grid's launches and the flip loop's cap (kMaxFlipRuns).
  static constexpr uint32_t kFlipTailMaxIterations = 1u << 20;
  Buffer<uint32_t, System> counts_;
  // Packed: the sets' round state (SetRoundState): flags, then saw_edge, splits, sector splits,
  // voted and triangles.
  uint32_t num_sets_;
  Buffer<uint8_t, System> set_flags_;
  Buffer<uint32_t, System> set_counts_;
  MeshView mesh_{};
  int32_t num_tri_ = 0;
  int rounds_ = 0;
  // The flip loop's two iterations, recorded once per build for each kind of flipping; declared
  // last, so that they are destroyed (after the stream's last replay) before the buffers.
  typename System::Recording insertion_flips_;
  typename System::Recording repair_flips_;
};

}  // namespace galpha::detail
