// One insertion round of the gDel2D scheme: every triangle elects the uninserted point nearest its
// circumcentre (atomic minimum over packed keys), elected points split their triangle 1-to-3, then
// the split triangles' outside neighbours are re-linked. A finite triangle may also have a second
// winner, which splits the child that holds it in the same round (PickSecondWinners).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include <cuda/atomic>

#include "core/base/hd.hpp"
#include "gpu/system/atomic_increment.cuh"
#include "gpu/triangulation/mesh.cuh"

namespace galpha::detail {

constexpr unsigned long long kNoVote = ~0ull;

/// Sets a flag word to 1, read first so that the many threads that raise one flag write it once.
GALPHA_HD inline void RaiseFlag(uint32_t* flag) {
  cuda::atomic_ref<uint32_t, cuda::thread_scope_device> word(*flag);
  if (word.load(cuda::memory_order_relaxed) == 0) word.store(1u, cuda::memory_order_relaxed);
}

/// A packed build's per-set round state (delaunay_batch.cuh): what a build of one set decides on
/// the host between rounds (DelaunayBuilder::InsertAll), decided for every set on the device
/// (DecideSetRounds), so that each set's rounds are the ones it would have alone.
struct SetRoundState {
  // Per set: kSetSecondWinners, kSetSectorPairs and kSetThirds, for the round under way.
  uint8_t* flags = nullptr;
  // Per set: points on an edge's line voted this round; splits and splits of infinite triangles
  // (points added to the hull) of the previous round.
  uint32_t* saw_edge = nullptr;
  uint32_t* splits = nullptr;
  uint32_t* sector_splits = nullptr;
  // Per set: its points that voted this round, the pending points of a build of the set alone
  // (its rounds end where none is left, and it then decides nothing more).
  uint32_t* voted = nullptr;
  // Per set: the triangles of its mesh, a build of the set alone's count (SliverEdgeWait).
  uint32_t* triangles = nullptr;
};
// The round picks second winners (one build's `second_winners`).
constexpr uint8_t kSetSecondWinners = 1;
// Points outside the hull vote for their sector's two supports (one build's `sector_pairs`).
constexpr uint8_t kSetSectorPairs = 2;
// Votes by thirds are on: set from the first round after one that picked second winners, and kept
// (one build allocates their buffer then, and keeps it).
constexpr uint8_t kSetThirds = 4;

/// Where the three children of a split triangle live: child 2 reuses the parent's slot, children
/// 0 and 1 take two fresh slots after the current triangles. `split_count` is the inclusive scan of
/// HasWinner, so a split parent is the (split_count - 1)-th split of the round.
GALPHA_HD inline int32_t ChildSlot(int32_t parent, int k, int32_t split_count, int32_t num_tri) {
  return k == 2 ? parent : num_tri + 2 * (split_count - 1) + k;
}

/// VoteForInsertion's count of a triangle's points that vote on a sliver's edge line (the low bits),
/// with this bit set once a point votes on an edge line by thirds (SliverEdgeWait).
constexpr uint32_t kVotedByThirds = 0x80000000u;

/// Sets kVotedByThirds in a triangle's count, read first (as RaiseFlag) so that the points of one
/// triangle, thousands of them in a grid's first rounds, do not each take an atomic on one word.
GALPHA_HD inline void MarkVotedByThirds(uint32_t* count) {
  cuda::atomic_ref<uint32_t, cuda::thread_scope_device> word(*count);
  if ((word.load(cuda::memory_order_relaxed) & kVotedByThirds) == 0) {
    word.fetch_or(kVotedByThirds, cuda::memory_order_relaxed);
  }
}

/// Whether a triangle's points on its edges' lines wait for a later round: where its points vote
/// on the edge line of a sliver (VoteForInsertion: one winner nearest the circumcentre, the
/// middle of the edge's points) and number fewer than the pending points per triangle of the whole
/// mesh. Why: on two crossing lines of points each round splits every edge of either line once, so
/// that where one line is ahead of the other in the first rounds (pairs of points elected from both
/// sides of one edge, an edge split in thirds), it stays ahead by the same factor in every round:
/// the lagging line's vertices face fans of the other's points, 25 to 80 of them, and each of its
/// late points takes such a fan over one flip an iteration, while the points still pending walk
/// across it. A sliver whose points are few against the average is where its line is ahead; its
/// points wait until the others' rounds bring the average down to them. Counted on the CPU backend
/// at 1M (bench/README.md, twenty-seventh session), two_lines: one-block flip iterations 407 -> 121,
/// relocation walk steps 46.2M -> 33.0M, rounds unchanged (23). Only slivers' points wait: with
/// every edge line's points counted, grid took 17 rounds instead of 14 and tiny 23 instead of 20.
///
/// Every round still inserts a point: were every counted triangle waiting, with c_t of its points
/// counted and P points pending in T triangles, c_t * T < P for each would sum (over at most T
/// triangles) to P * T < P * T when every pending point is counted; a point that is not counted
/// (inside a triangle, outside the hull, by thirds) votes where it is. A packed build counts each
/// set's pending points and triangles, the counts of a build of the set alone.
struct SliverEdgeWait {
  const uint32_t* sliver_edge_points = nullptr;  // per triangle (VoteForInsertion); nullptr: none wait
  // One build: its pending points (the device's count) and triangles.
  const uint32_t* pending_count = nullptr;
  int32_t num_tri = 0;
  // A packed build: the triangles' vertices and each vertex's set, and the sets' round state.
  const Tri* tri = nullptr;
  const uint32_t* vertex_set = nullptr;
  SetRoundState sets{};

  GALPHA_HD bool Waits(int32_t t) const {
    if (sliver_edge_points == nullptr) return false;
    const uint32_t counted = sliver_edge_points[t];
    if (counted == 0 || (counted & kVotedByThirds) != 0) return false;
    uint64_t pending, triangles;
    if (vertex_set != nullptr) {
      const uint32_t set = vertex_set[tri[t].v[0]];  // finite: counted points lie on an edge's line
      pending = sets.voted[set];
      triangles = sets.triangles[set];
    } else {
      pending = *pending_count;
      triangles = static_cast<uint64_t>(num_tri);
    }
    return uint64_t{counted} * triangles < pending;
  }
};

/// Maps a float to an unsigned key with the same order (negative values included).
GALPHA_HD inline uint32_t OrderedFloatKey(float f) {
  uint32_t bits;
  memcpy(&bits, &f, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

/// Binary exponent of the largest magnitude among the given differences (0 when all are zero).
/// Scores are computed on coordinates divided by 2^exponent (exact: a power of two), so that
/// subnormal or huge inputs neither underflow to ties nor overflow.
GALPHA_HD inline int ScoreExponent(double a, double b, double c, double d) {
  const double m = fmax(fmax(fabs(a), fabs(b)), fmax(fabs(c), fabs(d)));
  return m > 0.0 ? ilogb(m) : 0;
}

/// Each uninserted point votes for itself in the triangle that contains it; the smallest key wins.
/// Finite triangles prefer the point nearest the circumcentre (gDel2D's choice: it keeps triangles
/// well shaped); infinite ones the point farthest outside their hull edge. The choice is a
/// heuristic only, so approximate doubles are fine here; but ties must be rare, or the smallest
/// index (an end of a run of points along a line, in Hilbert order) wins every round.
///
/// A finite triangle's points are voted in two classes: those on one of its edges' lines (in
/// doubles; a heuristic too) in `edge_vote`, the others in `tri_vote`. PickSecondWinners then
/// makes the better of the two the round's winner and keeps the other class's best for a second
/// split of the same triangle in the same round. Two crossing lines of points need it: near the
/// crossing one triangle holds the second line's points inside it and the first line's on its
/// edge, and with one winner a round the two lines took turns there, so the second line fell
/// behind by a factor that doubled every two rounds and its late points then took over fans of
/// the first line's hundreds of points, one flip an iteration (bench/README.md, two_lines).
///
/// Points on an edge's line of a triangle that is not a sliver (that edge at least a quarter of
/// its longest; `edge_third_vote` set) are voted by thirds instead: those on the edge's first half
/// in `edge_vote`, nearest the point a third along it, those on its second half in
/// `edge_third_vote`, nearest two thirds along. A triangle whose only points lie on its edge then
/// inserts both, and the edge's points are split in three parts a round, not two: a line of
/// points (parallel_lines, a grid's rows) takes log3 rounds instead of log2, and every round costs
/// a relocation of all the points still pending. Slivers keep the one vote nearest the
/// circumcentre: two crossing lines' long fans (a far point and the many close points of the other
/// line) took more flip iterations by thirds, not fewer (measured: bench/README.md).
template <bool kWeighted>
struct VoteForInsertion {
  MeshView mesh;
  const int32_t* pending;         // vertex of each uninserted point
  const int32_t* location;        // triangle containing it
  unsigned long long* tri_vote;   // per triangle, kNoVote when nobody voted
  unsigned long long* edge_vote;  // per triangle: the votes of points on an edge's line; nullptr:
                                  // they vote in tri_vote (a round without second winners)
  uint32_t* saw_edge_point;       // set when a point on an edge's line voted
  // Per triangle: the votes of points on the second half of an edge's line, by thirds; nullptr:
  // no votes by thirds (weighted builds, and rounds before any point on an edge's line was seen).
  unsigned long long* edge_third_vote;
  // Points outside the hull vote twice, for the two supports of their sector (SupportSlope):
  // in tri_vote toward the hull edge's first end, in edge_vote toward its second. Needs edge_vote.
  bool sector_pairs;
  // A packed build: the set of each vertex, and each set's round state, whose flags replace
  // `sector_pairs` and the null `edge_vote` and `edge_third_vote` of a set's rounds without them
  // (those pointers are then set when any set's round has them), and whose `saw_edge` replaces
  // `saw_edge_point`. nullptr: one set.
  const uint32_t* vertex_set = nullptr;
  SetRoundState sets{};
  // Per triangle, zeroed: its points voting on a sliver's edge line, kVotedByThirds once one votes
  // by thirds (SliverEdgeWait). nullptr: not counted (rounds without second winners, weighted).
  uint32_t* sliver_edge_points = nullptr;

  /// The slope of a sector's support direction away from its hull edge's normal, toward one end:
  /// tan(turn / 6), approximated by tan(turn / 2) / 3, where `turn` is the hull's turning angle
  /// at that end between the edges `in` and `out` (scaled vectors). On a circle's arcs, whose
  /// neighbours were split alike, the turn is about twice an arc's half angle, and the two supports
  /// are then the arc's points a third and two thirds along it: the arc is split in three parts a
  /// round. Any slope keeps the choice a support point of the sector's points, a vertex of their
  /// convex hull (as the farthest point is), so that points beyond a blob's hull edge still elect
  /// points of its outline. Capped at 1 (45 degrees), which is also the slope where the
  /// turn is a half turn or undefined.
  GALPHA_HD static double SupportSlope(double in_x, double in_y, double out_x, double out_y) {
    const double cross = fabs(in_x * out_y - in_y * out_x);
    const double dot = in_x * out_x + in_y * out_y;
    const double denominator = sqrt((in_x * in_x + in_y * in_y) * (out_x * out_x + out_y * out_y)) + dot;
    if (!(denominator > 0.0)) return 1.0;
    const double slope = cross / denominator / 3.0;
    return slope < 1.0 ? slope : 1.0;
  }

  /// The vote by thirds of point i, at `along` (its position along the edge's line, 0 and 1 at
  /// the edge's ends): the half it lies in picks the slot, its distance from the third or the two
  /// thirds the key.
  GALPHA_HD static void VoteByThirds(uint32_t i, int32_t t, double along, unsigned long long* edge_vote,
                                     unsigned long long* edge_third_vote) {
    const bool second_half = along >= 0.5;
    const double off = along - (second_half ? 2.0 / 3.0 : 1.0 / 3.0);
    const float score = static_cast<float>(off * off);
    const unsigned long long key = (static_cast<unsigned long long>(OrderedFloatKey(score)) << 32) | i;
    cuda::atomic_ref<unsigned long long, cuda::thread_scope_device> slot(second_half ? edge_third_vote[t]
                                                                                     : edge_vote[t]);
    slot.fetch_min(key);
  }

  GALPHA_HD void operator()(uint32_t i) const {
    // This point's round: the build's, or in a packed build its set's.
    unsigned long long* edge_vote = this->edge_vote;
    unsigned long long* edge_third_vote = this->edge_third_vote;
    uint32_t* saw_edge_point = this->saw_edge_point;
    bool sector_pairs = this->sector_pairs;
    if (vertex_set != nullptr) {
      const uint32_t set = vertex_set[pending[i]];
      const uint8_t flags = sets.flags[set];
      if ((flags & kSetSecondWinners) == 0) edge_vote = nullptr;
      if ((flags & kSetSecondWinners) == 0 || (flags & kSetThirds) == 0) edge_third_vote = nullptr;
      sector_pairs = (flags & kSetSectorPairs) != 0;
      saw_edge_point = sets.saw_edge + set;
      AtomicIncrement(sets.voted + set);
    }
    const int32_t t = location[i];
    const Point2 p = mesh.pts[pending[i]];
    const Tri x = mesh.tri[t];
    float score;
    bool on_edge_line = false;
    int inf_pos = -1;
    for (int k = 0; k < 3; ++k) {
      if (x.v[k] == mesh.inf) inf_pos = k;
    }
    if (inf_pos >= 0) {
      // Farthest outside first (the hull grows as in quickhull). Points on the hull edge's line
      // (grids, collinear data) all score 0 that way: among them prefer the one nearest the
      // edge's midpoint, so a line of n such points is split in halves, O(log n) rounds, not n.
      const Point2 u = mesh.pts[x.v[Next(inf_pos)]], w = mesh.pts[x.v[Prev(inf_pos)]];
      const int e = ScoreExponent(w.x - u.x, w.y - u.y, 0.0, 0.0);
      const double wx = ldexp(w.x - u.x, -e), wy = ldexp(w.y - u.y, -e);
      const double px = ldexp(p.x - u.x, -e), py = ldexp(p.y - u.y, -e);
      const double outside = wx * py - wy * px;
      if (outside > 0.0 && sector_pairs) {
        // The sector's two supports (SupportSlope): toward u, the direction of largest outside -
        // s_u * along; toward w, outside + s_w * along (along: the position along the edge).
        const int32_t u_prev = mesh.NextHullVertex(t, Prev(inf_pos), x.v[Next(inf_pos)]);
        const int32_t w_next = mesh.NextHullVertex(t, Next(inf_pos), x.v[Prev(inf_pos)]);
        const Point2 before = mesh.pts[u_prev], after = mesh.pts[w_next];
        const double bx = ldexp(before.x - u.x, -e), by = ldexp(before.y - u.y, -e);
        const double ax = ldexp(after.x - w.x, -e), ay = ldexp(after.y - w.y, -e);
        const double slope_u = SupportSlope(-bx, -by, wx, wy);
        const double slope_w = SupportSlope(wx, wy, ax, ay);
        const double along = wx * px + wy * py;
        const float toward_u = -static_cast<float>(outside - slope_u * along);
        const float toward_w = -static_cast<float>(outside + slope_w * along);
        cuda::atomic_ref<unsigned long long, cuda::thread_scope_device>(tri_vote[t])
            .fetch_min((static_cast<unsigned long long>(OrderedFloatKey(toward_u)) << 32) | i);
        cuda::atomic_ref<unsigned long long, cuda::thread_scope_device>(edge_vote[t])
            .fetch_min((static_cast<unsigned long long>(OrderedFloatKey(toward_w)) << 32) | i);
        return;
      }
      if (outside > 0.0) {
        score = -static_cast<float>(outside);
      } else if constexpr (!kWeighted) {
        const double dx = px - 0.5 * wx, dy = py - 0.5 * wy;
        score = static_cast<float>(dx * dx + dy * dy);
      } else {
        // Weighted: the point whose lift lies deepest below the lifted segment u-w (its power
        // with respect to the segment's smallest orthogonal circle), so that a heavy point on a
        // hull line is inserted before the points of the line it hides. A point on a hull line
        // is hidden or not by the points of that line alone.
        const double wu = mesh.weight[x.v[Next(inf_pos)]];
        const double lift_w = wx * wx + wy * wy - ldexp(mesh.weight[x.v[Prev(inf_pos)]] - wu, -2 * e);
        const double lift_p = px * px + py * py - ldexp(mesh.weight[pending[i]] - wu, -2 * e);
        const double along = wx * wx + wy * wy;
        const double t = along > 0.0 ? (wx * px + wy * py) / along : 0.0;
        const double depth = lift_p - t * lift_w;
        score = (depth == depth && depth < 3.0e38 && depth > -3.0e38) ? static_cast<float>(depth)
                                                                      : (depth < 0 ? -3.0e38f : 3.0e38f);
      }
    } else {
      // Nearest the circumcentre o means the smallest power |p - o|^2 - R^2 (same order), but the
      // power is computed from coordinates relative to a vertex, without R^2: for a sliver, whose
      // circumcentre is far away, |p - o|^2 rounds to the same float for every point, and the
      // index would then pick an end of the sliver (linear rounds on collinear data) instead of
      // its middle (a point on a chord has power -|p - a| |p - b|, lowest at the midpoint).
      const Point2 a = mesh.pts[x.v[0]], b = mesh.pts[x.v[1]], c = mesh.pts[x.v[2]];
      const int e = ScoreExponent(b.x - a.x, b.y - a.y, c.x - a.x, c.y - a.y);
      const double bx = ldexp(b.x - a.x, -e), by = ldexp(b.y - a.y, -e);
      const double cx = ldexp(c.x - a.x, -e), cy = ldexp(c.y - a.y, -e);
      const double px = ldexp(p.x - a.x, -e), py = ldexp(p.y - a.y, -e);
      const double d = bx * cy - by * cx;
      const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
      const bool on_ab = bx * py - by * px == 0.0, on_ac = cx * py - cy * px == 0.0;
      const bool on_bc = (cx - bx) * (py - by) - (cy - by) * (px - bx) == 0.0;
      on_edge_line = on_ab || on_ac || on_bc;
      if constexpr (!kWeighted) {
        if (on_edge_line && edge_third_vote != nullptr) {
          // The edge from u to u + (ex, ey) whose line holds p (relative to a, scaled).
          const double ux = on_ab || on_ac ? 0.0 : bx, uy = on_ab || on_ac ? 0.0 : by;
          const double ex = (on_ab ? bx : cx) - ux, ey = (on_ab ? by : cy) - uy;
          const double edge2 = ex * ex + ey * ey;
          const double longest2 = fmax(fmax(b2, c2), (cx - bx) * (cx - bx) + (cy - by) * (cy - by));
          if (16.0 * edge2 >= longest2) {
            RaiseFlag(saw_edge_point);
            if (sliver_edge_points != nullptr) MarkVotedByThirds(sliver_edge_points + t);
            VoteByThirds(i, t, ((px - ux) * ex + (py - uy) * ey) / edge2, edge_vote, edge_third_vote);
            return;
          }
        }
      }
      if (d != 0.0) {
        // Weighted, the same height of p's lift over the triangle's lifted plane, with lifts less
        // their weight relative to a's: the deepest point wins, and a heavy point, which hides the
        // points around it, is inserted before them (they are then hidden on relocation, not
        // after their own insertion, which would cost a rebuild).
        double lift_b = b2, lift_c = c2, lift_p = px * px + py * py;
        if constexpr (kWeighted) {
          const double wa = mesh.weight[x.v[0]];
          lift_b -= ldexp(mesh.weight[x.v[1]] - wa, -2 * e);
          lift_c -= ldexp(mesh.weight[x.v[2]] - wa, -2 * e);
          lift_p -= ldexp(mesh.weight[pending[i]] - wa, -2 * e);
        }
        const double power = lift_p - (px * (cy * lift_b - by * lift_c) + py * (bx * lift_c - cx * lift_b)) / d;
        score = (power == power && power < 3.0e38 && power > -3.0e38) ? static_cast<float>(power)
                                                                      : (power < 0 ? -3.0e38f : 3.0e38f);
      } else {
        // A triangle flat in doubles (collinear vertices, kept by the symbolic perturbation): it
        // has no circumcentre, and every point would tie. Its points lie on its long edge's line;
        // the one nearest that edge's midpoint splits the edge's points in halves, as on the hull.
        const double a2 = (bx - cx) * (bx - cx) + (by - cy) * (by - cy);
        double mx = 0.5 * (bx + cx), my = 0.5 * (by + cy);  // the long edge b-c, unless...
        if (b2 >= a2 && b2 >= c2) {
          mx = 0.5 * bx;  // a-b
          my = 0.5 * by;
        } else if (c2 >= a2 && c2 >= b2) {
          mx = 0.5 * cx;  // a-c
          my = 0.5 * cy;
        }
        const double dx = px - mx, dy = py - my;
        score = static_cast<float>(dx * dx + dy * dy);
      }
    }
    const unsigned long long key = (static_cast<unsigned long long>(OrderedFloatKey(score)) << 32) | i;
    if (on_edge_line) RaiseFlag(saw_edge_point);
    if (on_edge_line && edge_vote != nullptr && sliver_edge_points != nullptr) AtomicIncrement(sliver_edge_points + t);
    cuda::atomic_ref<unsigned long long, cuda::thread_scope_device> slot(
        on_edge_line && edge_vote != nullptr ? edge_vote[t] : tri_vote[t]);
    slot.fetch_min(key);
  }
};

/// Clears a round's votes (`edge_vote`, `edge_third_vote` and `sliver_edge_points` too unless
/// nullptr) and, in thread 0, its counts of second winners and of points on an edge's line: one
/// launch for what were three.
struct ResetVotes {
  unsigned long long* tri_vote;
  unsigned long long* edge_vote;
  unsigned long long* edge_third_vote;
  uint32_t* second_count;
  uint32_t* saw_edge_point;
  uint32_t* sliver_edge_points = nullptr;
  GALPHA_HD void operator()(int32_t t) const {
    tri_vote[t] = kNoVote;
    if (edge_vote != nullptr) edge_vote[t] = kNoVote;
    if (edge_third_vote != nullptr) edge_third_vote[t] = kNoVote;
    if (sliver_edge_points != nullptr) sliver_edge_points[t] = 0;
    if (t == 0) {
      *second_count = 0;
      *saw_edge_point = 0;
    }
  }
};

/// Per triangle: the better of its two classes' votes becomes the round's winner (`tri_vote`),
/// the other class's best, where both voted, its second winner (`edge_vote`, else kNoVote),
/// counted into `*num_second`. With votes by thirds (`edge_third_vote` set), a triangle with
/// points inside takes the better of its two edge votes as its edge class's; one without takes
/// its first-half edge vote as the inside class's and its second-half one as the edge class's, so
/// that an edge's points alone still give two winners. A triangle whose edge points wait
/// (SliverEdgeWait) has no edge class this round.
struct PickSecondWinners {
  unsigned long long* tri_vote;
  unsigned long long* edge_vote;
  const unsigned long long* edge_third_vote;
  uint32_t* num_second;
  SliverEdgeWait wait{};
  GALPHA_HD void operator()(int32_t t) const {
    const bool edge_points_wait = wait.Waits(t);
    unsigned long long inside = tri_vote[t], on_edge = edge_points_wait ? kNoVote : edge_vote[t];
    if (edge_third_vote != nullptr) {
      const unsigned long long second_half = edge_points_wait ? kNoVote : edge_third_vote[t];
      if (inside == kNoVote) {
        inside = on_edge != kNoVote ? on_edge : second_half;
        on_edge = on_edge != kNoVote ? second_half : kNoVote;
      } else {
        on_edge = on_edge < second_half ? on_edge : second_half;
      }
    }
    tri_vote[t] = inside < on_edge ? inside : on_edge;
    // A sector's two supports (VoteForInsertion::sector_pairs) may be one point.
    const bool both = inside != kNoVote && on_edge != kNoVote && (inside & 0xffffffffull) != (on_edge & 0xffffffffull);
    edge_vote[t] = both ? (inside < on_edge ? on_edge : inside) : kNoVote;
    if (both) {
      cuda::atomic_ref<uint32_t, cuda::thread_scope_device> count(*num_second);
      count.fetch_add(1u);
    }
  }
};

/// After the first splits of a round: each second winner walks from its triangle's slot (now the
/// first split's child 2) to the child that holds it, and votes there alone (`second_vote`,
/// cleared to kNoVote for every triangle beforehand). A parent writes only into its own
/// children, so no two second winners meet in one child. The walk cannot leave the three
/// children: the point was inside its triangle by the same symbolic orientations that split it.
/// Should a walk fail or leave them anyway, the flag is raised (and read with the next round's
/// wait, which throws) and the vote still goes to the parent's own slot, so that the round splits
/// as many triangles as the host counted and every index stays in the mesh until then.
struct PlaceSecondWinners {
  MeshView mesh;
  const int32_t* pending;
  const unsigned long long* edge_vote;  // PickSecondWinners's, per triangle before the splits
  const int32_t* split_count;           // the first splits' inclusive scan
  int32_t num_tri_before;               // triangles before the first splits
  unsigned long long* second_vote;
  int32_t* walk_failed;
  int32_t* left_parent;
  uint32_t max_steps;
  GALPHA_HD void operator()(int32_t t) const {
    const unsigned long long vote = edge_vote[t];
    if (vote == kNoVote) return;
    const int32_t child = mesh.Locate(t, pending[static_cast<uint32_t>(vote & 0xffffffffu)], max_steps);
    if (child < 0) {
      *walk_failed = 1;
      second_vote[t] = vote;
      return;
    }
    if (child != t && child != ChildSlot(t, 0, split_count[t], num_tri_before) &&
        child != ChildSlot(t, 1, split_count[t], num_tri_before)) {
      *left_parent = 1;
      second_vote[t] = vote;
      return;
    }
    second_vote[child] = vote;
  }
};

/// A packed build, after a round's votes: every set decides its next round as DelaunayBuilder::
/// InsertAll decides a build's (second winners where the round saw a point on an edge's line or
/// the next has sector pairs; sector pairs after a round where at least a quarter of the splits
/// were on the hull; votes by thirds from the first round with second winners on, unweighted),
/// from its own counts, which it then clears; the sets whose next round has second winners are
/// counted into `*with_second_winners`.
struct DecideSetRounds {
  SetRoundState sets;
  bool weighted;
  uint32_t* with_second_winners;
  GALPHA_HD void operator()(uint32_t set) const {
    if (sets.voted[set] == 0) return;  // the set's rounds are over: it decides nothing
    sets.voted[set] = 0;
    const uint32_t last_splits = sets.splits[set];
    const bool sector_pairs =
        !weighted && last_splits > 0 && 4 * static_cast<uint64_t>(sets.sector_splits[set]) >= last_splits;
    const bool second_winners = sets.saw_edge[set] != 0 || sector_pairs;
    uint8_t flags = sets.flags[set] & kSetThirds;
    if (sector_pairs) flags |= kSetSectorPairs;
    if (second_winners) {
      flags |= kSetSecondWinners;
      if (!weighted) flags |= kSetThirds;
      AtomicIncrement(with_second_winners);
    }
    sets.flags[set] = flags;
    sets.saw_edge[set] = 0;
    sets.splits[set] = 0;
    sets.sector_splits[set] = 0;
  }
};

/// A packed build, before its first round of insertions: every set starts as a build starts
/// InsertAll (second winners on, sector pairs off, no splits counted), its votes by thirds kept.
struct StartSetRounds {
  SetRoundState sets;
  GALPHA_HD void operator()(uint32_t set) const {
    sets.flags[set] = static_cast<uint8_t>((sets.flags[set] & kSetThirds) | kSetSecondWinners);
    sets.voted[set] = 0;
    sets.saw_edge[set] = 0;
    sets.splits[set] = 0;
    sets.sector_splits[set] = 0;
  }
};

/// 1 where a triangle won a point this round.
struct HasWinner {
  GALPHA_HD int32_t operator()(unsigned long long vote) const { return vote != kNoVote ? 1 : 0; }
};

/// Splits every elected triangle (a, b, c) around its point w into (b, c, w), (c, a, w), (a, b, w):
/// child k keeps the parent's edge opposite vertex k. Outside neighbours still name the parent
/// afterwards; LinkSplitChildren repairs them.
struct SplitTriangles {
  MeshView mesh;
  const unsigned long long* tri_vote;
  const int32_t* split_count;  // inclusive scan of HasWinner
  const int32_t* pending;
  uint8_t* inserted;  // per uninserted point
  int32_t num_tri;
  uint32_t* sector_splits;  // the build's count of split infinite triangles (points added to the hull)
  SetRoundState sets{};     // a packed build: the splits are also counted per set (mesh.vertex_set)

  GALPHA_HD void operator()(int32_t t) const {
    const unsigned long long vote = tri_vote[t];
    if (vote == kNoVote) return;
    const uint32_t winner = static_cast<uint32_t>(vote & 0xffffffffu);
    inserted[winner] = 1;
    const int32_t w = pending[winner];
    const Tri x = mesh.tri[t];
    const bool infinite = mesh.IsInfinite(t);
    if (infinite) AtomicIncrement(sector_splits);
    if (mesh.vertex_set != nullptr) {
      const uint32_t set = mesh.vertex_set[w];
      AtomicIncrement(sets.splits + set);
      cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(sets.triangles[set]).fetch_add(2u);
      if (infinite) AtomicIncrement(sets.sector_splits + set);
    }
    const TriNbr nx = mesh.nbr[t];
    int32_t child[3];
    for (int k = 0; k < 3; ++k) child[k] = ChildSlot(t, k, split_count[t], num_tri);
    for (int k = 0; k < 3; ++k) {
      mesh.tri[child[k]] = Tri{{x.v[Next(k)], x.v[Prev(k)], w}};
      mesh.nbr[child[k]] = TriNbr{{child[Next(k)], child[Prev(k)], nx.n[k]}};
    }
  }
};

/// Re-links the outside edge of each child: to the matching child when the neighbour split in the
/// same round, else by pointing the untouched neighbour back at the child. Each write has one
/// writer, so the pass is race-free.
struct LinkSplitChildren {
  MeshView mesh;
  const unsigned long long* tri_vote;
  const int32_t* split_count;  // inclusive scan of HasWinner
  int32_t num_tri;

  GALPHA_HD void operator()(int32_t t) const {
    if (tri_vote[t] == kNoVote) return;
    for (int k = 0; k < 3; ++k) {
      const int32_t c = ChildSlot(t, k, split_count[t], num_tri);
      const int32_t p = mesh.tri[c].v[0], q = mesh.tri[c].v[1];
      const int32_t x = mesh.nbr[c].n[2];
      if (tri_vote[x] != kNoVote) {
        for (int j = 0; j < 3; ++j) {
          const int32_t cx = ChildSlot(x, j, split_count[x], num_tri);
          if (mesh.tri[cx].v[0] == q && mesh.tri[cx].v[1] == p) mesh.nbr[c].n[2] = cx;
        }
      } else {
        mesh.nbr[x].n[mesh.EdgePos(x, q, p)] = c;
      }
    }
  }
};

/// Lists the children of every split triangle: the first triangles to check for flips. A second
/// split lists only its two fresh children (`num_listed` 2): its child 2 keeps the slot of a
/// first split's child, which is listed already.
struct ListSplitChildren {
  const unsigned long long* tri_vote;
  const int32_t* split_count;  // inclusive scan of HasWinner
  int32_t* active;
  int32_t num_tri;
  int num_listed;

  GALPHA_HD void operator()(int32_t t) const {
    if (tri_vote[t] == kNoVote) return;
    for (int k = 0; k < num_listed; ++k) {
      active[num_listed * (split_count[t] - 1) + k] = ChildSlot(t, k, split_count[t], num_tri);
    }
  }
};

/// Relocates a point that is still uninserted, walking from the triangle that held it. Weighted, a
/// point the triangle hides (MeshView::Hidden) is marked in `hidden` and leaves the pending points
/// with the inserted ones (`inserted` 2).
template <bool kWeighted>
struct RelocatePoint {
  MeshView mesh;
  const int32_t* pending;
  uint8_t* inserted;
  int32_t* location;
  uint8_t* hidden;  // per vertex; weighted only
  int32_t* walk_failed;
  uint32_t max_steps;

  GALPHA_HD void operator()(uint32_t i) const {
    if (inserted[i]) return;
    const int32_t t = mesh.Locate(location[i], pending[i], max_steps);
    if (t < 0) {
      *walk_failed = 1;
      return;
    }
    location[i] = t;
    if constexpr (kWeighted) {
      if (mesh.Hidden(t, pending[i])) {
        hidden[pending[i]] = 1;
        inserted[i] = 2;
      }
    }
  }
};

}  // namespace galpha::detail
