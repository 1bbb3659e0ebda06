// The packed triangulation of many point sets (issue 20: one hull per feature): one build on the
// system whose mesh arrays hold a mesh per set, apart, instead of one build a set. Written once over
// an execution system, as the one-set pipeline (delaunay_impl.cuh) is, from its stages.
//
// Why each set's output is the one a build of the set alone gives, bit for bit (triangles in the
// same order, the same neighbours and edges): the sets are sorted apart at every step (by set, then
// as one set is), so every set's vertex ids, pending points and triangle slots keep the relative
// order they have alone; the mesh's kernels only follow a triangle's own links, which never leave
// its set, and decide ties by those orders (votes by smallest index, flips by smallest triangle; a
// relocation walk's first edge depends on the point's id, which changes its path but not the one
// triangle it ends in);
// what a build decides for all its points between rounds, each set decides for itself
// (SetRoundState, DecideSetRounds); each set starts from its own first triangle, and its walks
// outside the hull turn around that triangle's centre (MeshView::set_center). Two global choices
// are not made per set, so the sets they concern are built alone afterwards: a set all on one line
// (or of fewer than three distinct points) is its chain of points, written here as one build writes
// it; a set whose mesh holds a flat triangle after insertion (the hull repair chooses between
// parallel and serial rounds by the whole mesh's count; no generator leaves one) is flagged, and the
// caller builds it alone.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <thrust/binary_search.h>
#include <thrust/copy.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/partition.h>
#include <thrust/reduce.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>
#include <cuda/atomic>

#include "gpu/triangulation/delaunay_backend.hpp"
#include "gpu/triangulation/delaunay_impl.cuh"

namespace galpha::detail {

/// A set whose distinct points are sorted positions [begin[s], begin[s + 1]) of `unique` (by
/// (x, y)) is off one line when some point is off the line of its first and last: AllCollinear's
/// test, for every set at once. Sets of fewer than three distinct points stay on a line.
struct MarkSetOffLine {
  const Point2* input;
  const uint32_t* unique;
  const uint32_t* unique_set;
  const uint32_t* set_unique_begin;
  uint32_t* off_line;  // per set
  GALPHA_HD void operator()(uint32_t k) const {
    const uint32_t set = unique_set[k];
    const uint32_t begin = set_unique_begin[set], end = set_unique_begin[set + 1];
    if (end - begin < 3) return;
    if (Orient2dSign(input[unique[begin]], input[unique[end - 1]], input[unique[k]]) != 0) RaiseFlag(off_line + set);
  }
};

/// Sorted position k of a set on one line starts an edge of its chain (WriteCollinearChain's).
struct StartsChainEdge {
  const uint32_t* unique_set;
  const uint32_t* set_unique_begin;
  const uint32_t* off_line;
  GALPHA_HD bool operator()(uint32_t k) const {
    const uint32_t set = unique_set[k];
    return off_line[set] == 0 && k + 1 < set_unique_begin[set + 1];
  }
};

/// The chain edge that starts at sorted position positions[j] (WriteChainEdge's edge).
struct WriteChainEdgeAt {
  const uint32_t* unique;
  const uint32_t* positions;
  EdgePair* edges;
  GALPHA_HD void operator()(uint32_t j) const {
    const uint32_t a = unique[positions[j]], b = unique[positions[j] + 1];
    edges[j] = EdgePair{{a < b ? a : b, a < b ? b : a}};
  }
};

/// Whether a set (by id) has a mesh.
struct SetHasMesh {
  const uint32_t* off_line;
  GALPHA_HD bool operator()(uint32_t set) const { return off_line[set] != 0; }
};

/// For each set, the smallest vertex past its first two that is off their line (FindFirstTriangle's
/// c), as an atomic minimum.
struct FindSetThirdVertex {
  const Point2* vertex_points;
  const uint32_t* vertex_set;
  const uint32_t* set_vertex_begin;
  int32_t* third;  // per set, from INT32_MAX
  GALPHA_HD void operator()(int32_t v) const {
    const uint32_t set = vertex_set[v];
    const auto first = static_cast<int32_t>(set_vertex_begin[set]);
    if (v < first + 2) return;
    if (Orient2dSign(vertex_points[first], vertex_points[first + 1], vertex_points[v]) != 0) {
      cuda::atomic_ref<int32_t, cuda::thread_scope_device>(third[set]).fetch_min(v);
    }
  }
};

/// Each set's first triangle, counter-clockwise (FindFirstTriangle's), as its centre
/// (MeshView::set_center), and the slot of its first triangle (StartSetMesh's 4j).
struct WriteSetFirstTriangle {
  const Point2* vertex_points;
  const uint32_t* mesh_set;
  const uint32_t* set_vertex_begin;
  const int32_t* third;
  int32_t* set_center;
  int32_t* set_first_slot;
  GALPHA_HD void operator()(uint32_t j) const {
    const uint32_t set = mesh_set[j];
    int32_t a = static_cast<int32_t>(set_vertex_begin[set]), b = a + 1;
    const int32_t c = third[set];
    if (Orient2dSign(vertex_points[a], vertex_points[b], vertex_points[c]) < 0) {
      const int32_t swap = a;
      a = b;
      b = swap;
    }
    set_center[3 * size_t{set}] = a;
    set_center[3 * size_t{set} + 1] = b;
    set_center[3 * size_t{set} + 2] = c;
    set_first_slot[set] = 4 * static_cast<int32_t>(j);
  }
};

/// A vertex that is not one of its set's first triangle's.
struct NotSetInitialVertex {
  const uint32_t* vertex_set;
  const int32_t* set_center;
  GALPHA_HD bool operator()(int32_t v) const {
    const int32_t* c = set_center + 3 * size_t{vertex_set[v]};
    return v != c[0] && v != c[1] && v != c[2];
  }
};

/// A pending vertex's first location: its set's first triangle.
struct SetFirstSlot {
  const uint32_t* vertex_set;
  const int32_t* set_first_slot;
  GALPHA_HD int32_t operator()(int32_t v) const { return set_first_slot[vertex_set[v]]; }
};

/// The four extreme vertices InsertRemainingVertices inserts first, of a run of vertices: the
/// first and last in (x, y) order and in (y, x) order.
struct Extremes {
  int32_t v[4];
};

struct VertexAsExtremes {
  GALPHA_HD Extremes operator()(int32_t v) const { return {{v, v, v, v}}; }
};

/// Merges two runs' extremes. CUB's reduce-by-key also applies the operator to the unloaded
/// values past the input's end (their results are dropped), so an operand outside the `m`
/// vertices is never read: the other one is taken (the unchecked version read far outside the
/// points on the device, compute-sanitizer's memcheck found it).
struct MergeExtremes {
  const Point2* pts;
  int32_t m;
  GALPHA_HD Extremes operator()(const Extremes& a, const Extremes& b) const {
    const VertexLexLess xy{pts};
    const VertexLexLessYX yx{pts};
    Extremes out;
    for (int k = 0; k < 4; ++k) {
      const int32_t x = a.v[k], y = b.v[k];
      const bool x_valid = x >= 0 && x < m, y_valid = y >= 0 && y < m;
      if (!x_valid || !y_valid) {
        out.v[k] = x_valid ? x : y;
        continue;
      }
      // 0: first in (x, y) order; 1: last; 2: first in (y, x) order; 3: last.
      const bool take_y = k == 0 ? xy(y, x) : k == 1 ? xy(x, y) : k == 2 ? yx(y, x) : yx(x, y);
      out.v[k] = take_y ? y : x;
    }
    return out;
  }
};

/// Scatters the reduced value of key j to its set.
template <class T>
struct ScatterBySet {
  const uint32_t* keys;
  const T* values;
  T* by_set;
  GALPHA_HD void operator()(uint32_t j) const { by_set[keys[j]] = values[j]; }
};

/// Whether a vertex is one of its set's extremes.
struct IsSetExtremeVertex {
  const uint32_t* vertex_set;
  const Extremes* set_extremes;
  GALPHA_HD bool operator()(int32_t v) const {
    const Extremes& e = set_extremes[vertex_set[v]];
    return v == e.v[0] || v == e.v[1] || v == e.v[2] || v == e.v[3];
  }
};

/// The set of an output triangle (of its first vertex, an input index).
struct TriangleSet {
  const uint32_t* input_set;
  const Tri* tri;
  GALPHA_HD uint32_t operator()(uint32_t t) const { return input_set[tri[t].v[0]]; }
};

/// new_position[order[k]] = k.
struct WriteNewPosition {
  const uint32_t* order;
  int32_t* new_position;
  GALPHA_HD void operator()(uint32_t k) const { new_position[order[k]] = static_cast<int32_t>(k); }
};

/// Output triangle k of the grouped order: the old triangle order[k], its neighbours renamed.
struct GatherGroupedTriangle {
  const uint32_t* order;
  const Tri* tri;
  const TriNbr* nbr;
  const int32_t* new_position;
  Tri* grouped_tri;
  TriNbr* grouped_nbr;
  GALPHA_HD void operator()(uint32_t k) const {
    const uint32_t old = order[k];
    grouped_tri[k] = tri[old];
    TriNbr n = nbr[old];
    for (int j = 0; j < 3; ++j) n.n[j] = n.n[j] < 0 ? n.n[j] : new_position[n.n[j]];
    grouped_nbr[k] = n;
  }
};

/// Puts the output's triangles (finite, by input index, slot order) in order of their set, each
/// set's in its slot order (a stable sort), with their neighbours renamed: a set's triangles are
/// then one run, in the order of its build alone, and the edges written from them (OutputEdges)
/// too. The runs' starts (num_sets + 1) go to `set_triangle_begin` on the host.
template <class System>
void GroupTrianglesBySet(System& sys, const uint32_t* input_set, uint32_t num_sets, SystemTriangulation<System>* result,
                         std::vector<uint32_t>* set_triangle_begin) {
  auto pol = sys.policy();
  const thrust::counting_iterator<uint32_t> first(0);
  const auto num_tri = static_cast<uint32_t>(result->tri.size());
  Buffer<uint32_t, System> order(sys, num_tri);
  {
    Buffer<uint32_t, System> keys(sys, num_tri);
    thrust::transform(pol, first, first + num_tri, keys.begin(), TriangleSet{input_set, result->tri.data()});
    thrust::sequence(pol, order.begin(), order.end());
    thrust::stable_sort_by_key(pol, keys.begin(), keys.end(), order.begin());
    Buffer<uint32_t, System> begin(sys, size_t{num_sets} + 1);
    thrust::lower_bound(pol, keys.begin(), keys.end(), first, first + num_sets + 1, begin.begin());
    *set_triangle_begin = begin.ToHostVector(size_t{num_sets} + 1);
  }
  Buffer<int32_t, System> new_position(sys, num_tri);
  thrust::for_each(pol, first, first + num_tri, WriteNewPosition{order.data(), new_position.data()});
  Buffer<Tri, System> tri(sys, num_tri);
  Buffer<TriNbr, System> nbr(sys, num_tri);
  thrust::for_each(pol, first, first + num_tri,
                   GatherGroupedTriangle{order.data(), result->tri.data(), result->nbr.data(), new_position.data(),
                                         tri.data(), nbr.data()});
  result->tri = std::move(tri);
  result->nbr = std::move(nbr);
}

/// The packed build's result in the system's memory: every set's mesh in `mesh` (each set's
/// triangles one run, set after set; representatives for every input index; the input kept when
/// asked for), the chains of the sets on one line apart, and every input index's set.
template <class System>
struct PackedTriangulation {
  explicit PackedTriangulation(System& sys) : mesh(sys), chain(sys, 0), input_set(sys, 0) {}
  SystemTriangulation<System> mesh;
  Buffer<EdgePair, System> chain;
  Buffer<uint32_t, System> input_set;
  /// Where each set's run of triangles starts (num_sets + 1 entries; empty when no set has a mesh).
  std::vector<uint32_t> set_triangle_begin;
  /// Per set: 1 where its mesh held a flat triangle (DelaunaySetsOutput::build_alone).
  std::vector<uint8_t> build_alone;
};

/// Triangulates the `num_sets` sets of `n` host points (set s: points [set_begin[s],
/// set_begin[s + 1])) in one build on `sys`; the result stays there. With `keep_points` the
/// uploaded input is kept in the result. One stage a call.
template <class System>
PackedTriangulation<System> TriangulateSetsOnSystem(System& sys, const Point2* host_points,
                                                    const uint32_t* host_set_begin, uint32_t num_sets, uint32_t n,
                                                    bool keep_points, StageTimer<System>& timer) {
  auto pol = sys.policy();
  const thrust::counting_iterator<uint32_t> first(0);
  const thrust::counting_iterator<int32_t> vfirst(0);
  PackedTriangulation<System> packed(sys);
  SystemTriangulation<System>& result = packed.mesh;
  Buffer<Point2, System> input = UploadPoints(sys, host_points, n);
  Buffer<uint32_t, System> set_begin(sys, size_t{num_sets} + 1);
  sys.FromHost(set_begin.data(), host_set_begin, size_t{num_sets} + 1);
  packed.input_set = Buffer<uint32_t, System>(sys, n);
  Buffer<uint32_t, System>& input_set = packed.input_set;
  // Set s holds indices below set_begin[s + 1]: the first bound above i names i's set.
  thrust::upper_bound(pol, set_begin.begin() + 1, set_begin.end(), first, first + n, input_set.begin());
  timer.EndStage("upload");

  DistinctPoints<System> distinct = FindDistinctPoints(sys, input, nullptr, &result, input_set.data());
  const uint32_t m_all = distinct.m;
  Buffer<uint32_t, System> unique_set(sys, m_all);
  thrust::transform(pol, first, first + m_all, unique_set.begin(),
                    SetOfIndex{input_set.data(), distinct.unique.data()});
  Buffer<uint32_t, System> set_unique_begin(sys, size_t{num_sets} + 1);
  thrust::lower_bound(pol, unique_set.begin(), unique_set.end(), first, first + num_sets + 1, set_unique_begin.begin());
  timer.EndStage("dedupe");

  // Sets on one line: their chains, from the (x, y) order; the others keep their points for a mesh.
  Buffer<uint32_t, System> off_line(sys, num_sets);
  thrust::fill(pol, off_line.begin(), off_line.end(), 0u);
  thrust::for_each(pol, first, first + m_all,
                   MarkSetOffLine{input.data(), distinct.unique.data(), unique_set.data(), set_unique_begin.data(),
                                  off_line.data()});
  {
    Buffer<uint32_t, System> chain_start(sys, m_all);
    const auto num_chain_edges = static_cast<uint32_t>(
        thrust::copy_if(pol, first, first + m_all, chain_start.begin(),
                        StartsChainEdge{unique_set.data(), set_unique_begin.data(), off_line.data()}) -
        chain_start.begin());
    packed.chain = Buffer<EdgePair, System>(sys, num_chain_edges);
    thrust::for_each(pol, first, first + num_chain_edges,
                     WriteChainEdgeAt{distinct.unique.data(), chain_start.data(), packed.chain.data()});
  }
  {
    Buffer<uint32_t, System> mesh_unique(sys, m_all);
    const auto m =
        static_cast<uint32_t>(thrust::copy_if(pol, distinct.unique.begin(), distinct.unique.begin() + m_all,
                                              unique_set.begin(), mesh_unique.begin(), SetHasMesh{off_line.data()}) -
                              mesh_unique.begin());
    distinct.unique = std::move(mesh_unique);
    distinct.m = m;
  }
  unique_set.Reset();
  set_unique_begin.Reset();
  timer.EndStage("collinear_chain");

  packed.build_alone.assign(num_sets, 0);
  const uint32_t m = distinct.m;
  if (m > 0) {
    // Every set's box and power of two, as a build of it alone computes them (over its input).
    Buffer<BoundingBox, System> set_box(sys, num_sets);
    Buffer<int, System> set_scale_exponent(sys, num_sets);
    {
      Buffer<uint32_t, System> keys(sys, num_sets);
      Buffer<BoundingBox, System> boxes(sys, num_sets);
      Buffer<double, System> smallest(sys, num_sets);
      const auto box_end = thrust::reduce_by_key(
          pol, input_set.begin(), input_set.end(), thrust::make_transform_iterator(input.begin(), PointToBox()),
          keys.begin(), boxes.begin(), thrust::equal_to<uint32_t>(), MergeBoxes());
      const auto num_nonempty = static_cast<uint32_t>(box_end.first - keys.begin());
      thrust::reduce_by_key(pol, input_set.begin(), input_set.end(),
                            thrust::make_transform_iterator(input.begin(), SmallestNonzeroMagnitude()),
                            thrust::make_discard_iterator(), smallest.begin(), thrust::equal_to<uint32_t>(), Minimum());
      const std::vector<uint32_t> host_keys = keys.ToHostVector(num_nonempty);
      const std::vector<BoundingBox> host_boxes = boxes.ToHostVector(num_nonempty);
      const std::vector<double> host_smallest = smallest.ToHostVector(num_nonempty);
      std::vector<int> exponent(num_sets, 0);
      for (uint32_t j = 0; j < num_nonempty; ++j) {
        exponent[host_keys[j]] = ExactScaleExponent(host_boxes[j], [&] { return host_smallest[j]; });
      }
      sys.FromHost(set_scale_exponent.data(), exponent.data(), num_sets);
      thrust::for_each(pol, first, first + num_nonempty,
                       ScatterBySet<BoundingBox>{keys.data(), boxes.data(), set_box.data()});
    }
    const InputSets sets{input_set.data(), set_box.data(), set_scale_exponent.data()};
    VertexWeights<System> no_weights(sys);
    Buffer<Point2, System> vertex_points = HilbertOrder(sys, input, nullptr, &distinct, &no_weights, &sets);
    set_box.Reset();
    set_scale_exponent.Reset();
    timer.EndStage("hilbert_sort");

    Buffer<uint32_t, System> vertex_set(sys, m);
    thrust::transform(pol, first, first + m, vertex_set.begin(), SetOfIndex{input_set.data(), distinct.unique.data()});
    Buffer<uint32_t, System> set_vertex_begin(sys, size_t{num_sets} + 1);
    thrust::lower_bound(pol, vertex_set.begin(), vertex_set.end(), first, first + num_sets + 1,
                        set_vertex_begin.begin());
    Buffer<uint32_t, System> mesh_set(sys, num_sets);
    const auto num_meshes = static_cast<uint32_t>(
        thrust::copy_if(pol, first, first + num_sets, mesh_set.begin(), SetHasMesh{off_line.data()}) -
        mesh_set.begin());
    Buffer<int32_t, System> set_center(sys, 3 * size_t{num_sets});
    Buffer<int32_t, System> set_first_slot(sys, num_sets);
    {
      Buffer<int32_t, System> third(sys, num_sets);
      thrust::fill(pol, third.begin(), third.end(), INT32_MAX);
      thrust::for_each(
          pol, vfirst, vfirst + m,
          FindSetThirdVertex{vertex_points.data(), vertex_set.data(), set_vertex_begin.data(), third.data()});
      thrust::for_each(pol, first, first + num_meshes,
                       WriteSetFirstTriangle{vertex_points.data(), mesh_set.data(), set_vertex_begin.data(),
                                             third.data(), set_center.data(), set_first_slot.data()});
    }
    std::optional<DelaunayBuilder<System>> builder;
    builder.emplace(sys, vertex_points.data(), distinct.unique.data(), distinct.unique.data(), nullptr, nullptr, m, 0,
                    0, 0, MeshSets{vertex_set.data(), set_center.data(), num_sets});
    builder->StartSets(mesh_set.data(), num_meshes);
    {
      // InsertRemainingVertices, for every set at once: each set's extremes first, then the rest.
      const uint32_t num_pending = m - 3 * num_meshes;
      Buffer<int32_t, System> pending(sys, num_pending);
      Buffer<int32_t, System> location(sys, num_pending);
      Buffer<uint8_t, System> inserted(sys, num_pending);
      thrust::copy_if(pol, vfirst, vfirst + m, pending.begin(),
                      NotSetInitialVertex{vertex_set.data(), set_center.data()});
      thrust::fill(pol, inserted.begin(), inserted.end(), uint8_t{0});
      Buffer<Extremes, System> set_extremes(sys, num_sets);
      {
        Buffer<uint32_t, System> keys(sys, num_meshes);
        Buffer<Extremes, System> extremes(sys, num_meshes);
        thrust::reduce_by_key(pol, vertex_set.begin(), vertex_set.end(),
                              thrust::make_transform_iterator(vfirst, VertexAsExtremes()), keys.begin(),
                              extremes.begin(), thrust::equal_to<uint32_t>(),
                              MergeExtremes{vertex_points.data(), static_cast<int32_t>(m)});
        thrust::for_each(pol, first, first + num_meshes,
                         ScatterBySet<Extremes>{keys.data(), extremes.data(), set_extremes.data()});
      }
      const IsSetExtremeVertex extreme{vertex_set.data(), set_extremes.data()};
      const auto num_first = static_cast<uint32_t>(thrust::count_if(pol, pending.begin(), pending.end(), extreme));
      if (num_first > 0) thrust::stable_partition(pol, pending.begin(), pending.end(), extreme);
      thrust::transform(pol, pending.begin(), pending.end(), location.begin(),
                        SetFirstSlot{vertex_set.data(), set_first_slot.data()});
      if (num_first > 0) builder->InsertAll(pending.data(), location.data(), inserted.data(), num_first);
      builder->InsertAll(pending.data() + num_first, location.data() + num_first, inserted.data() + num_first,
                         num_pending - num_first);
    }
    timer.EndStage("insert_and_flip");
    {
      Buffer<uint8_t, System> flat(sys, num_sets);
      thrust::fill(pol, flat.begin(), flat.end(), uint8_t{0});
      builder->MarkSetsWithFlatTriangles(flat.data());
      sys.ToHost(packed.build_alone.data(), flat.data(), num_sets);
    }
    timer.EndStage("hull_repair");
    builder->ReleaseWorkspace();
    OutputTriangles(sys, *builder, &result);
    builder.reset();
    vertex_points.Reset();
    distinct.unique.Reset();
    GroupTrianglesBySet(sys, input_set.data(), num_sets, &result, &packed.set_triangle_begin);
    if (result.tri.size() > 0) OutputEdges(sys, &result);
    timer.EndStage("output");
  }
  if (keep_points) result.points = std::move(input);
  return packed;
}

/// Triangulates the `num_sets` sets of `n` host points in one build on `sys` and downloads the
/// result into `out`.
template <class System>
void RunSetsTriangulation(System& sys, const Point2* host_points, const uint32_t* host_set_begin, uint32_t num_sets,
                          uint32_t n, DelaunaySetsOutput* out) {
  StageTimer<System> timer(sys, &out->meshes.stage_times);
  PackedTriangulation<System> packed =
      TriangulateSetsOnSystem(sys, host_points, host_set_begin, num_sets, n, /*keep_points=*/false, timer);
  const size_t num_chain_edges = packed.chain.size();
  out->chain_edges.resize(num_chain_edges);
  if (num_chain_edges > 0) {
    sys.ToHost(reinterpret_cast<EdgePair*>(out->chain_edges.data()), packed.chain.data(), num_chain_edges);
  }
  out->set_triangle_begin = std::move(packed.set_triangle_begin);
  out->build_alone = std::move(packed.build_alone);
  DownloadTriangulation(sys, packed.mesh, n, &out->meshes);
  timer.EndStage("download");
  timer.Finish();
  out->meshes.peak_memory_bytes = sys.peak_bytes();
}

}  // namespace galpha::detail
