// Turns the working mesh (sphere with the vertex at infinity, Hilbert vertex ids) into the output:
// finite triangles named by input indices, neighbours, and the edge list by the ownership rule of
// the report "Computing 2D Alpha Shapes Using GPU" (sections 3.1 and 4.3.1).
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "gpu/triangulation/mesh.cuh"

namespace galpha::detail {

struct IsFiniteTriangle {
  MeshView mesh;
  GALPHA_HD int32_t operator()(int32_t t) const { return mesh.IsInfinite(t) ? 0 : 1; }
};

/// Output triangle and neighbours of every finite working triangle.
struct WriteFiniteTriangle {
  MeshView mesh;
  const int32_t* finite_id;  // exclusive scan of IsFiniteTriangle
  Tri* out_tri;              // input indices
  TriNbr* out_nbr;

  GALPHA_HD void operator()(int32_t t) const {
    if (mesh.IsInfinite(t)) return;
    const int32_t id = finite_id[t];
    Tri o;
    TriNbr on;
    for (int k = 0; k < 3; ++k) {
      o.v[k] = static_cast<int32_t>(mesh.sos[mesh.tri[t].v[k]]);
      const int32_t nb = mesh.nbr[t].n[k];
      on.n[k] = mesh.IsInfinite(nb) ? -1 : finite_id[nb];
    }
    out_tri[id] = o;
    out_nbr[id] = on;
  }
};

/// Local edge k runs from vertex k to vertex k+1 and lies opposite vertex k+2. A triangle owns it
/// when the indices increase along it or when it is a hull edge.
GALPHA_HD inline bool OwnsEdge(const Tri& t, const TriNbr& n, int k) {
  return static_cast<uint32_t>(t.v[k]) < static_cast<uint32_t>(t.v[Next(k)]) || n.n[Prev(k)] < 0;
}

struct CountOwnedEdges {
  const Tri* tri;
  const TriNbr* nbr;
  GALPHA_HD uint32_t operator()(int32_t t) const {
    uint32_t count = 0;
    for (int k = 0; k < 3; ++k) count += OwnsEdge(tri[t], nbr[t], k) ? 1u : 0u;
    return count;
  }
};

struct EdgePair {
  uint32_t v[2];
};

struct WriteOwnedEdges {
  const Tri* tri;
  const TriNbr* nbr;
  const uint32_t* edge_begin;
  EdgePair* edges;
  GALPHA_HD void operator()(int32_t t) const {
    uint32_t slot = edge_begin[t];
    for (int k = 0; k < 3; ++k) {
      if (!OwnsEdge(tri[t], nbr[t], k)) continue;
      const uint32_t a = static_cast<uint32_t>(tri[t].v[k]), b = static_cast<uint32_t>(tri[t].v[Next(k)]);
      edges[slot++] = EdgePair{{a < b ? a : b, a < b ? b : a}};
    }
  }
};

/// Degenerate output (all points on one line): the chain of the lexicographically sorted points.
struct WriteChainEdge {
  const uint32_t* sorted_unique;  // input indices in lexicographic order
  EdgePair* edges;
  GALPHA_HD void operator()(uint32_t i) const {
    const uint32_t a = sorted_unique[i], b = sorted_unique[i + 1];
    edges[i] = EdgePair{{a < b ? a : b, a < b ? b : a}};
  }
};

}  // namespace galpha::detail
