// Weighted (regular) triangulations: removing hidden vertices from the mesh in place.
//
// A vertex v that MarkRedundantVertices found hidden after its insertion (the reflex end of a
// non-regular edge that cannot flip) is removed by cutting ears off the polygon of its neighbours
// (its link) until three remain, then merging the last three triangles into one: d triangles
// around v become d - 2, and two slots die. The ear at link vertex w_i, between w_(i-1) and
// w_(i+1), may be cut when it turns left and leaves v on the left of the new edge w_(i-1) ->
// w_(i+1): then the rest of the link stays star-shaped from v, so an ear always exists while
// more than three neighbours remain (with the mesh's never-zero SoS orientation). The polygon's
// triangulation is arbitrary; the flips that follow make it regular, and may block on further
// hidden vertices, which the next pass removes.
//
// Many vertices are removed at once, one thread each. A thread claims its star and the triangles
// across the star's outer edges (whose links it rewrites) by an atomic minimum of its key (a hash
// of its vertex id, the id below it: vertices next to each other along a chain have unrelated
// keys, so about a third of a chain wins a round, where ids in Hilbert order would let one win);
// it proceeds only if it holds them all, so that no two threads touch one triangle. Losers retry
// in the next round. Hull vertices, and vertices with more than kMaxRemovalDegree neighbours, are
// left to the caller (which rebuilds without them).
#pragma once

#include <cstdint>

#include <cuda/atomic>

#include "core/base/hd.hpp"
#include "gpu/triangulation/mesh.cuh"

namespace galpha::detail {

/// The most neighbours a vertex may have to be removed in place (its star is kept in registers).
constexpr int kMaxRemovalDegree = 32;
constexpr unsigned long long kNoClaim = ~0ull;

/// The claim key of vertex v: a 32-bit mix of v (murmur3's finalizer), then v (unique keys).
GALPHA_HD inline unsigned long long ClaimKey(int32_t v) {
  uint32_t h = static_cast<uint32_t>(v);
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return (static_cast<unsigned long long>(h) << 32) | static_cast<uint32_t>(v);
}
/// MarkRedundantVertices' mark: hidden, and still a vertex of the mesh.
constexpr uint8_t kHiddenInMesh = 2;

/// A dead slot: the vertex at infinity three times (IsInfinite: no output, never active).
GALPHA_HD inline bool IsDeadTriangle(const Tri& x) { return x.v[0] == x.v[1]; }

/// For every vertex still marked kHiddenInMesh, one live triangle holding it (once; removals keep
/// the map current for the vertices of the triangles they write).
struct FindStarStart {
  MeshView mesh;
  const uint8_t* hidden;
  int32_t* vertex_tri;
  GALPHA_HD void operator()(int32_t t) const {
    const Tri x = mesh.tri[t];
    if (IsDeadTriangle(x)) return;
    for (int k = 0; k < 3; ++k) {
      if (x.v[k] != mesh.inf && hidden[x.v[k]] == kHiddenInMesh) vertex_tri[x.v[k]] = t;
    }
  }
};

/// The triangles around vertex v, counter-clockwise from `start`: t_i = (v, w_i, w_(i+1)). Returns
/// the degree, or -1 when v is on the hull or has more than kMaxRemovalDegree neighbours.
GALPHA_HD inline int WalkStar(const MeshView& mesh, int32_t v, int32_t start, int32_t* star, int32_t* link) {
  int32_t t = start;
  for (int d = 0; d <= kMaxRemovalDegree; ++d) {
    if (d == kMaxRemovalDegree) return -1;
    const Tri x = mesh.tri[t];
    int k = 0;
    while (k < 3 && x.v[k] != v) ++k;
    if (k == 3) return -1;  // not v's triangle: the caller's map is stale (cannot happen)
    const int32_t a = x.v[Next(k)];
    if (a == mesh.inf || x.v[Prev(k)] == mesh.inf) return -1;
    star[d] = t;
    link[d] = a;
    t = mesh.nbr[t].n[Next(k)];  // across the edge from x.v[Prev(k)] to v: the next counter-clockwise
    // -1: a triangle another thread is rewriting (an ear's open side, a dead slot); the caller then
    // does not hold it and gives up.
    if (t < 0) return -1;
    if (t == start) return d + 1;
  }
  return -1;
}

/// Rotates the star and its link so that the link starts at its smallest vertex.
GALPHA_HD inline void RotateToSmallestLink(int32_t* star, int32_t* link, int d) {
  int first = 0;
  for (int j = 1; j < d; ++j) {
    if (link[j] < link[first]) first = j;
  }
  int32_t s[kMaxRemovalDegree], l[kMaxRemovalDegree];
  for (int j = 0; j < d; ++j) {
    s[j] = star[(first + j) % d];
    l[j] = link[(first + j) % d];
  }
  for (int j = 0; j < d; ++j) {
    star[j] = s[j];
    link[j] = l[j];
  }
}

/// Round step 1: each candidate claims its star and the triangles across its link edges.
struct ClaimStar {
  MeshView mesh;
  const int32_t* candidates;
  const int32_t* vertex_tri;
  unsigned long long* claim;  // per triangle
  GALPHA_HD void operator()(uint32_t i) const {
    const int32_t v = candidates[i];
    if (vertex_tri[v] < 0) return;
    const unsigned long long key = ClaimKey(v);
    int32_t star[kMaxRemovalDegree], link[kMaxRemovalDegree];
    const int d = WalkStar(mesh, v, vertex_tri[v], star, link);
    if (d < 0) return;
    for (int j = 0; j < d; ++j) {
      cuda::atomic_ref<unsigned long long, cuda::thread_scope_device>(claim[star[j]]).fetch_min(key);
      const Tri x = mesh.tri[star[j]];
      int k = 0;
      while (x.v[k] != v) ++k;
      const int32_t outer = mesh.nbr[star[j]].n[k];
      cuda::atomic_ref<unsigned long long, cuda::thread_scope_device>(claim[outer]).fetch_min(key);
    }
  }
};

/// Round step 2: a candidate that holds every claim it made removes its vertex (see the file
/// comment), marks it hidden (1), counts itself, flags the triangles it wrote in `created` and
/// points `vertex_tri` of their vertices that are still candidates at them.
struct RemoveClaimedStar {
  MeshView mesh;
  const int32_t* candidates;
  int32_t* vertex_tri;
  const unsigned long long* claim;
  uint8_t* hidden;
  uint8_t* created;  // per triangle
  uint32_t* removed;
  GALPHA_HD void operator()(uint32_t i) const {
    const int32_t v = candidates[i];
    const unsigned long long me = ClaimKey(v);
    const int32_t start = vertex_tri[v];
    if (start < 0 || claim[start] != me) return;  // another thread may be rewriting it: read nothing more
    int32_t star[kMaxRemovalDegree], link[kMaxRemovalDegree], outer[kMaxRemovalDegree];
    const int d = WalkStar(mesh, v, start, star, link);
    if (d < 3) return;
    for (int j = 0; j < d; ++j) {
      if (claim[star[j]] != me) return;
    }
    // Start the star at its smallest link vertex: which triangle `vertex_tri` names depends on the
    // order of racing writes, and the ears (so the slots the new triangles take, and the output's
    // order) must not; from here on everything is a function of the mesh alone.
    RotateToSmallestLink(star, link, d);
    for (int j = 0; j < d; ++j) {
      const Tri x = mesh.tri[star[j]];
      int k = 0;
      while (x.v[k] != v) ++k;
      outer[j] = mesh.nbr[star[j]].n[k];  // across the link edge w_j -> w_(j+1)
      if (claim[outer[j]] != me) return;
    }
    // Plan the ears on a copy of the link (nothing is written unless the plan completes).
    int32_t ring[kMaxRemovalDegree];
    int ear_at[kMaxRemovalDegree];
    for (int j = 0; j < d; ++j) ring[j] = link[j];
    int n = d;
    for (int cut = 0; n > 3; ++cut) {
      int found = -1;
      for (int j = 0; j < n && found < 0; ++j) {
        const int32_t a = ring[(j + n - 1) % n], b = ring[j], c = ring[(j + 1) % n];
        if (mesh.Orient(a, b, c) > 0 && mesh.Orient(v, a, c) > 0) found = j;
      }
      if (found < 0) return;  // cannot happen for a vertex inside its link (see the file comment)
      ear_at[cut] = found;
      for (int j = found; j + 1 < n; ++j) ring[j] = ring[j + 1];
      --n;
    }
    // Execute it. Ring edge j runs from ring[j] to ring[j + 1]; across it lies across[j].
    int32_t across[kMaxRemovalDegree];
    n = d;
    for (int j = 0; j < d; ++j) {
      ring[j] = link[j];
      across[j] = outer[j];
    }
    int next_slot = 0;
    // Writes triangle `slot` = (a, b, c) with the given neighbours and points each neighbour's
    // matching edge back at it (the neighbours are claimed or written here).
    auto write = [&](int32_t slot, int32_t a, int32_t b, int32_t c, int32_t across_bc, int32_t across_ca,
                     int32_t across_ab) {
      mesh.tri[slot] = Tri{{a, b, c}};
      mesh.nbr[slot] = TriNbr{{across_bc, across_ca, across_ab}};
      created[slot] = 1;
      for (const int32_t u : {a, b, c}) {
        if (hidden[u] == kHiddenInMesh) vertex_tri[u] = slot;
      }
      if (across_bc >= 0) mesh.nbr[across_bc].n[mesh.EdgePos(across_bc, c, b)] = slot;
      if (across_ab >= 0) mesh.nbr[across_ab].n[mesh.EdgePos(across_ab, b, a)] = slot;
      if (across_ca >= 0) mesh.nbr[across_ca].n[mesh.EdgePos(across_ca, a, c)] = slot;
    };
    for (int cut = 0; n > 3; ++cut) {
      const int j = ear_at[cut];
      const int before = (j + n - 1) % n;
      const int32_t slot = star[next_slot++];
      // The ear (ring[before], ring[j], ring[j+1]); its third side, the new ring edge, is linked
      // when a later triangle takes that edge.
      write(slot, ring[before], ring[j], ring[(j + 1) % n], across[j], -1, across[before]);
      across[before] = slot;
      for (int m = j; m + 1 < n; ++m) {
        ring[m] = ring[m + 1];
        across[m] = across[m + 1];
      }
      --n;
    }
    write(star[next_slot++], ring[0], ring[1], ring[2], across[1], across[2], across[0]);
    for (; next_slot < d; ++next_slot) {
      mesh.tri[star[next_slot]] = Tri{{mesh.inf, mesh.inf, mesh.inf}};
      mesh.nbr[star[next_slot]] = TriNbr{{-1, -1, -1}};
      created[star[next_slot]] = 0;
    }
    hidden[v] = 1;
    cuda::atomic_ref<uint32_t, cuda::thread_scope_device>(*removed).fetch_add(1u);
  }
};

/// A candidate removed in this round.
struct RemovedFromMesh {
  const uint8_t* hidden;
  GALPHA_HD bool operator()(int32_t v) const { return hidden[v] != kHiddenInMesh; }
};

struct IsHiddenInMesh {
  const uint8_t* hidden;
  GALPHA_HD bool operator()(int32_t v) const { return hidden[v] == kHiddenInMesh; }
};

}  // namespace galpha::detail
