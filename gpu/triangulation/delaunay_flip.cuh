// Parallel Lawson flips (gDel2D): every active triangle proposes to flip its first non-Delaunay
// edge; a proposal wins when it holds the minimum vote on both triangles it touches, so no
// triangle takes part in two flips at once. Also the repair of hull triangles that are flat
// in reality but not in the symbolic perturbation.
#pragma once

#include <cstdint>

#include <cuda/atomic>

#include "core/base/hd.hpp"
#include "core/exact/predicates.hpp"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/system/block_lanes.hpp"
#include "gpu/triangulation/mesh.cuh"

namespace galpha::detail {

constexpr uint32_t kNoFlipVote = ~0u;
constexpr int32_t kNoPartner = -1;

/// Flips the edge of triangle t opposite position k, shared with triangle nb. Before: t = (r, p, q)
/// with the edge p-q opposite k, and nb = (s, q, p) with s at position j. After: t = (r, p, s), nb =
/// (s, q, r). Edges (r,p) and (s,q) stay in their slots; edge (p,s) moves from nb to t and (q,r) from
/// t to nb. Outside neighbours are the old ones (the caller re-links). Both triangles are loaded
/// together, before j is looked for (one memory latency, not two).
GALPHA_HD inline void WriteFlip(const MeshView& mesh, int32_t t, int k, int32_t nb) {
  const Tri x = mesh.tri[t], y = mesh.tri[nb];
  const TriNbr nx = mesh.nbr[t], ny = mesh.nbr[nb];
  const int j = ApexPos(y, x.v[Prev(k)], x.v[Next(k)]);
  const int32_t r = x.v[k], p = x.v[Next(k)];
  const int32_t s = y.v[j], q = y.v[Next(j)];
  const int32_t across_rp = nx.n[Prev(k)], across_qr = nx.n[Next(k)];
  const int32_t across_ps = ny.n[Next(j)], across_sq = ny.n[Prev(j)];
  mesh.tri[t] = Tri{{r, p, s}};
  mesh.nbr[t] = TriNbr{{across_ps, nb, across_rp}};
  mesh.tri[nb] = Tri{{s, q, r}};
  mesh.nbr[nb] = TriNbr{{across_qr, t, across_sq}};
}

/// Edge masks of active triangles: which positions may have stopped being locally Delaunay. After a
/// 1-to-3 split only a child's outside edge (position 2) can be; after a flip only the four outer
/// edges of the quadrilateral (positions 0 and 2 of both triangles), never the new diagonal.
constexpr uint8_t kCheckOutsideEdge = 0b100;
constexpr uint8_t kCheckFlipOuterEdges = 0b101;
constexpr uint8_t kCheckAllEdges = 0b111;

/// Each active triangle proposes its first edge that must flip and votes on both triangles
/// (kWeighted: by the regular triangulation's predicates, MeshView::FirstEdgeToFlip).
template <bool kWeighted>
struct ProposeFlips {
  MeshView mesh;
  const int32_t* active;
  const uint8_t* active_mask;
  int8_t* proposal_edge;  // per active entry: k, or -1
  int32_t* proposal_nb;   // per active entry: the neighbour across that edge
  uint32_t* flip_vote;    // per triangle, kNoFlipVote when untouched
  bool hull_may_change;

  GALPHA_HD void operator()(uint32_t i) const {
    const int32_t t = active[i];
    int32_t nb = -1;
    const int k = mesh.template FirstEdgeToFlip<kWeighted>(t, active_mask[i], hull_may_change, &nb);
    proposal_edge[i] = static_cast<int8_t>(k);
    if (k < 0) return;
    proposal_nb[i] = nb;
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(flip_vote[t]).fetch_min(static_cast<uint32_t>(t));
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(flip_vote[nb]).fetch_min(static_cast<uint32_t>(t));
  }
};

/// Performs the proposals that won both votes, and records each triangle's flip partner.
struct ExecuteFlips {
  MeshView mesh;
  const int32_t* active;
  int8_t* proposal_edge;  // set to 3 for a winner (re-linked next), kept for losers
  const int32_t* proposal_nb;
  const uint32_t* flip_vote;
  int32_t* partner;

  GALPHA_HD void operator()(uint32_t i) const {
    const int k = proposal_edge[i];
    if (k < 0) return;
    const int32_t t = active[i], nb = proposal_nb[i];
    if (flip_vote[t] != static_cast<uint32_t>(t) || flip_vote[nb] != static_cast<uint32_t>(t)) return;
    WriteFlip(mesh, t, k, nb);
    partner[t] = nb;
    partner[nb] = t;
    proposal_edge[i] = 3;
  }
};

/// After ExecuteFlips: points each flipped triangle's outside edges at their current owners, and
/// untouched neighbours of a moved edge back at the flipped triangle. One writer per slot.
///
/// Everything a flip's four re-links read is loaded first, side by side: the pass reads the
/// vertices of triangles (which it never writes), partners (never written), and the neighbours of
/// the flipped pair (written only by the pair's own thread, in slots it has read by then; an
/// outside triangle's neighbours, which it also writes, belong to triangles that did not flip and
/// are read by no thread). Re-linked one after the other, the four were a chain of dependent loads.
struct LinkFlips {
  MeshView mesh;
  const int32_t* active;
  const int8_t* proposal_edge;
  const int32_t* proposal_nb;
  const int32_t* partner;

  /// Slot `pos` of flipped triangle y (vertices `yv`), whose old neighbour there was x (vertices
  /// `xv`, flip partner `px`); `moved`: the edge came from y's partner.
  GALPHA_HD void Relink(int32_t y, const Tri& yv, int pos, int32_t x, const Tri& xv, int32_t px, bool moved) const {
    const int32_t a = yv.v[Next(pos)], b = yv.v[Prev(pos)];
    if (px != kNoPartner) {
      mesh.nbr[y].n[pos] = EdgePosIn(xv, b, a) >= 0 ? x : px;
    } else if (moved) {
      mesh.nbr[x].n[EdgePosIn(xv, b, a)] = y;
    }
  }

  GALPHA_HD void operator()(uint32_t i) const {
    if (proposal_edge[i] != 3) return;
    const int32_t t = active[i], nb = proposal_nb[i];
    const Tri tv = mesh.tri[t], nbv = mesh.tri[nb];
    const TriNbr tn = mesh.nbr[t], nbn = mesh.nbr[nb];
    const int32_t x[4] = {tn.n[0], tn.n[2], nbn.n[0], nbn.n[2]};
    Tri xv[4];
    int32_t px[4];
    for (int e = 0; e < 4; ++e) {
      xv[e] = mesh.tri[x[e]];
      px[e] = partner[x[e]];
    }
    Relink(t, tv, 0, x[0], xv[0], px[0], true);
    Relink(t, tv, 2, x[1], xv[1], px[1], false);
    Relink(nb, nbv, 0, x[2], xv[2], px[2], true);
    Relink(nb, nbv, 2, x[3], xv[3], px[3], false);
  }
};

/// Starts a flip iteration: zeroes the count of the next list and moves to a new generation of
/// stamps. One thread.
struct StartFlipIteration {
  uint32_t* next_count;
  uint32_t* generation;
  GALPHA_HD void operator()(uint32_t) const {
    *next_count = 0;
    *generation += 1;
  }
};

/// Clears the votes and partners one iteration used, and lists the triangles to check next: both
/// triangles of a flip, and the proposer of a flip that lost. `stamp` de-duplicates the list.
struct CollectNextActive {
  const int32_t* active;
  const int8_t* proposal_edge;
  const int32_t* proposal_nb;
  uint32_t* flip_vote;
  int32_t* partner;
  uint32_t* stamp;
  const uint32_t* generation;
  int32_t* candidates;  // two per active entry, -1 when unused
  uint8_t* candidate_mask;

  GALPHA_HD bool Claim(int32_t t, uint32_t now) const {
    return cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(stamp[t]).exchange(now) != now;
  }

  /// Clears entry i's votes and partners and calls keep(slot, triangle, edge mask) for each of its
  /// (up to two) triangles to check next, slot 0 for the proposer and 1 for its partner.
  template <class Keep>
  GALPHA_HD void ForEachNext(uint32_t i, Keep&& keep) const {
    const int edge = proposal_edge[i];
    if (edge < 0) return;
    const uint32_t now = *generation;
    const int32_t t = active[i], nb = proposal_nb[i];
    flip_vote[t] = kNoFlipVote;
    flip_vote[nb] = kNoFlipVote;
    const bool flipped = edge == 3;
    if (Claim(t, now)) {
      // A losing proposer may also have been flipped as another flip's neighbour, and only one
      // of its two claims lands: check every edge so that neither reason is lost.
      keep(0, t, flipped ? kCheckFlipOuterEdges : kCheckAllEdges);
    }
    if (flipped) {
      partner[t] = kNoPartner;
      partner[nb] = kNoPartner;
      if (Claim(nb, now)) keep(1, nb, kCheckFlipOuterEdges);
    }
  }

  /// The grid's pass: entry i's triangles go to candidates[2i] and [2i+1] (-1 when unused), which
  /// AppendIf then compacts.
  GALPHA_HD void operator()(uint32_t i) const {
    candidates[2 * i] = -1;
    candidates[2 * i + 1] = -1;
    ForEachNext(i, [&](int slot, int32_t t, uint8_t mask) {
      candidates[2 * i + slot] = t;
      candidate_mask[2 * i + slot] = mask;
    });
  }
};

/// The flip iterations of a short active list, in one block: the same steps as a grid iteration
/// (StartFlipIteration, ProposeFlips, ExecuteFlips, LinkFlips, CollectNextActive and the append of
/// the next list), with a barrier between steps instead of one launch each. The result of an
/// iteration does not depend on the order in which its items run, so it is the grid's, bit for
/// bit. Why: on collinear input a new point takes over the fan of a neighbour one flip per
/// iteration (two_lines at 1M: ~3,700 iterations, most of them with 2 to 7 active triangles; its
/// insertion took 122 ms on an H100, ~30 us an iteration of five launches), while an iteration in
/// one block costs a few memory latencies.
///
/// The lists alternate between `active` and `candidates` (with their masks): CollectNextActive
/// appends the next list straight into the other array, where the grid's pass writes two slots an
/// entry and compacts them after; the next iteration's start is made by the step that ends the
/// previous one. Five barriers an iteration instead of seven, and one pass fewer.
///
/// Runs while the list is nonempty and at most `max_count` long (it returns at once when it starts
/// longer: the grid's launches take over, and take it back when it is short again). The list is in
/// `active` and its count in `*count` on return; `scratch_count` holds the next list's count while
/// an iteration builds it. `*iterations_run` counts its iterations over the whole build: past
/// `max_iterations` it runs no more, so that a flip loop that did not end would go on in the grid's
/// launches, where the loop's cap reports it (DelaunayBuilder::RestoreDelaunay; without the budget,
/// each of those launches could run a loop of its own).
template <bool kWeighted>
struct FlipTailInOneBlock {
  MeshView mesh;
  int32_t* active;
  uint8_t* active_mask;
  int8_t* proposal_edge;
  int32_t* proposal_nb;
  uint32_t* flip_vote;
  int32_t* partner;
  uint32_t* stamp;
  uint32_t* generation;
  int32_t* candidates;  // at least 2 * max_count entries: the alternate list
  uint8_t* candidate_mask;
  uint32_t* count;
  uint32_t* scratch_count;
  uint32_t* iterations_run;
  uint32_t max_count;
  uint32_t max_iterations;
  bool hull_may_change;

  GALPHA_HD void operator()(const BlockLanes& lanes) const {
    int32_t* list[2] = {active, candidates};
    uint8_t* list_mask[2] = {active_mask, candidate_mask};
    int now = 0;  // which array holds the current list
    bool started = false;
    for (;;) {
      // The same for every lane: written (by lane 0) before the last barrier, and not again
      // before the next one.
      const uint32_t n = *count;
      if (n == 0 || n > max_count || *iterations_run >= max_iterations) {
        // Leave the list where the grid's launches read it.
        if (now == 1) {
          for (uint32_t i = lanes.id; i < n; i += lanes.count) {
            active[i] = candidates[i];
            active_mask[i] = candidate_mask[i];
          }
        }
        return;
      }
      if (!started) {
        if (lanes.id == 0) StartFlipIteration{scratch_count, generation}(0);
        lanes.Sync();
        started = true;
      }
      int32_t* const current = list[now];
      int32_t* const next = list[1 - now];
      uint8_t* const next_mask = list_mask[1 - now];
      const ProposeFlips<kWeighted> propose{mesh,        current,   list_mask[now], proposal_edge,
                                            proposal_nb, flip_vote, hull_may_change};
      for (uint32_t i = lanes.id; i < n; i += lanes.count) propose(i);
      lanes.Sync();
      const ExecuteFlips execute{mesh, current, proposal_edge, proposal_nb, flip_vote, partner};
      for (uint32_t i = lanes.id; i < n; i += lanes.count) execute(i);
      lanes.Sync();
      const LinkFlips link{mesh, current, proposal_edge, proposal_nb, partner};
      for (uint32_t i = lanes.id; i < n; i += lanes.count) link(i);
      lanes.Sync();
      const CollectNextActive collect{current, proposal_edge, proposal_nb, flip_vote, partner,
                                      stamp,   generation,    nullptr,     nullptr};
      for (uint32_t i = lanes.id; i < n; i += lanes.count) {
        collect.ForEachNext(i, [&](int, int32_t t, uint8_t mask) {
          const uint32_t slot = AtomicIncrement(scratch_count);
          next[slot] = t;
          next_mask[slot] = mask;
        });
      }
      lanes.Sync();
      if (lanes.id == 0) {
        *count = *scratch_count;
        *iterations_run += 1;
        StartFlipIteration{scratch_count, generation}(0);  // the next iteration's
      }
      lanes.Sync();
      now = 1 - now;
    }
  }
};

/// Whether finite triangle t is flat in reality: three collinear vertices on a hull line, made by
/// the symbolic perturbation.
GALPHA_HD inline bool IsFlatTriangle(const MeshView& mesh, int32_t t) {
  if (mesh.IsInfinite(t)) return false;
  const Tri& x = mesh.tri[t];
  return Orient2dSign(mesh.pts[x.v[0]], mesh.pts[x.v[1]], mesh.pts[x.v[2]]) == 0;
}

/// Position of the vertex of a flat triangle that lies between the other two.
GALPHA_HD inline int MiddlePosition(const MeshView& mesh, int32_t t) {
  const Tri& x = mesh.tri[t];
  for (int k = 0; k < 3; ++k) {
    const Point2 m = mesh.pts[x.v[k]], a = mesh.pts[x.v[Next(k)]], b = mesh.pts[x.v[Prev(k)]];
    if ((LexLess(a, m) && LexLess(m, b)) || (LexLess(b, m) && LexLess(m, a))) return k;
  }
  return -1;
}

/// The hull repair: flat triangles are removed so that points on a hull edge become hull vertices,
/// as in CGAL. A flat triangle (m between p and q) flips across its long edge p-q when the triangle
/// there is infinite (m joins the hull) or properly shaped (m joins that triangle's apex); such a
/// flip never makes a new flat triangle. When the triangle across is flat too, it waits for that
/// one's repair. Proposals are voted on and executed like Lawson flips (ExecuteFlips, LinkFlips),
/// in parallel rounds; a round's depth is the longest chain of flat triangles waiting on each other.
struct ProposeFlatRepairs {
  MeshView mesh;
  const int32_t* flat;    // flat triangles still to repair
  int8_t* proposal_edge;  // per entry: the long edge's position, or -1 while waiting
  int32_t* proposal_nb;
  uint32_t* flip_vote;

  GALPHA_HD void operator()(uint32_t i) const {
    const int32_t t = flat[i];
    proposal_edge[i] = -1;
    const int k = MiddlePosition(mesh, t);
    if (k < 0) return;
    const int32_t nb = mesh.nbr[t].n[k];
    if (IsFlatTriangle(mesh, nb)) return;
    proposal_edge[i] = static_cast<int8_t>(k);
    proposal_nb[i] = nb;
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(flip_vote[t]).fetch_min(static_cast<uint32_t>(t));
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(flip_vote[nb]).fetch_min(static_cast<uint32_t>(t));
  }
};

/// After a repair round: clears votes and partners, lists both triangles of every executed repair
/// (for the Lawson pass after), and marks the flat triangles that remain.
struct CollectFlatRepairs {
  const int32_t* flat;
  const int8_t* proposal_edge;  // 3 where ExecuteFlips flipped
  const int32_t* proposal_nb;
  uint32_t* flip_vote;
  int32_t* partner;
  int32_t* flipped_pairs;  // two per entry, -1 when unused
  uint8_t* still_flat;     // per entry

  GALPHA_HD void operator()(uint32_t i) const {
    const int32_t t = flat[i];
    flipped_pairs[2 * i] = -1;
    flipped_pairs[2 * i + 1] = -1;
    still_flat[i] = proposal_edge[i] != 3;
    if (proposal_edge[i] < 0) return;
    const int32_t nb = proposal_nb[i];
    flip_vote[t] = kNoFlipVote;
    flip_vote[nb] = kNoFlipVote;
    if (proposal_edge[i] == 3) {
      partner[t] = kNoPartner;
      partner[nb] = kNoPartner;
      flipped_pairs[2 * i] = t;
      flipped_pairs[2 * i + 1] = nb;
    }
  }
};

/// The repair of what the parallel rounds leave when flat triangles wait on each other in long
/// chains (along a hull line whose points the symbolic perturbation sank, chains can be O(n) long,
/// so parallel rounds would take O(n) rounds): one thread, depth-first with an explicit stack, so
/// that each flat triangle is visited O(1) times.
struct RepairFlatChainsSerially {
  MeshView mesh;
  const int32_t* flat;  // the flat triangles left
  uint32_t num_flat;
  int32_t* stack;      // num_flat entries
  uint32_t* on_stack;  // per triangle, kNoFlipVote (the idle flip votes) when not on the stack
  int32_t* failed;     // set when flat triangles remain (reported as an internal error)
  int32_t* flips_done;
  int32_t* touched;  // the two triangles of every repair flip, for the Lawson pass after

  GALPHA_HD void SerialFlip(int32_t t, int k) const {
    const int32_t nb = mesh.nbr[t].n[k];
    WriteFlip(mesh, t, k, nb);
    // The two moved edges: re-point their outside neighbours.
    for (int32_t y : {t, nb}) {
      const int32_t o = mesh.nbr[y].n[0];
      const int32_t a = mesh.tri[y].v[1], b = mesh.tri[y].v[2];
      mesh.nbr[o].n[mesh.EdgePos(o, b, a)] = y;
    }
  }

  /// Repairs flat triangle `first` and, before it, the flat triangles it waits for.
  GALPHA_HD void RepairFrom(int32_t first, int32_t* flips) const {
    uint32_t top = 0;
    stack[top++] = first;
    on_stack[first] = 0;
    while (top > 0) {
      const int32_t t = stack[top - 1];
      const int k = IsFlatTriangle(mesh, t) ? MiddlePosition(mesh, t) : -1;
      if (k >= 0) {
        const int32_t nb = mesh.nbr[t].n[k];
        if (IsFlatTriangle(mesh, nb)) {
          if (on_stack[nb] == kNoFlipVote && top < num_flat) {
            stack[top++] = nb;
            on_stack[nb] = 0;
            continue;
          }
          // A cycle: t stays flat for now, and a later pass tries again.
        } else {
          SerialFlip(t, k);
          touched[2 * *flips] = t;
          touched[2 * *flips + 1] = nb;
          ++*flips;
        }
      }
      on_stack[t] = kNoFlipVote;
      --top;
    }
  }

  GALPHA_HD void operator()(uint32_t) const {
    int32_t flips = 0;
    // Passes until every flat triangle is repaired; a pass that repairs none is a failure.
    for (bool remaining = true; remaining;) {
      remaining = false;
      const int32_t before = flips;
      for (uint32_t i = 0; i < num_flat; ++i) {
        if (IsFlatTriangle(mesh, flat[i])) RepairFrom(flat[i], &flips);
        remaining |= IsFlatTriangle(mesh, flat[i]);
      }
      if (remaining && flips == before) {
        *failed = 1;
        break;
      }
    }
    *flips_done = flips;
  }
};

}  // namespace galpha::detail
