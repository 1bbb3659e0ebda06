// The triangulation pipeline, written once over an execution system (CpuSystem or CudaSystem):
// dedupe -> Hilbert order -> insertion rounds with Lawson flips -> hull repair -> output.
// Instantiated by delaunay_cpu.cpp (OpenMP) and delaunay_cuda.cu (CUDA).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/extrema.h>
#include <thrust/fill.h>
#include <thrust/find.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/discard_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/iterator/zip_iterator.h>
#include <thrust/partition.h>
#include <thrust/reduce.h>
#include <thrust/remove.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>
#include <thrust/transform_scan.h>
#include <thrust/unique.h>

#include "core/exact/predicates.hpp"
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_backend.hpp"
#include "gpu/triangulation/delaunay_builder.cuh"
#include "gpu/triangulation/delaunay_output.cuh"
#include "gpu/triangulation/mesh.cuh"
#include "gpu/triangulation/point_order.cuh"

namespace galpha::detail {

struct NotCollinearWith {
  const Point2* pts;
  Point2 a, b;
  GALPHA_HD bool operator()(uint32_t input_index) const { return Orient2dSign(a, b, pts[input_index]) != 0; }
};

struct NotCollinearWithVertices {
  const Point2* vp;
  GALPHA_HD bool operator()(int32_t v) const { return Orient2dSign(vp[0], vp[1], vp[v]) != 0; }
};

struct NotInitialVertex {
  int32_t a, b, c;
  GALPHA_HD bool operator()(int32_t v) const { return v != a && v != b && v != c; }
};

/// Weighted: input_hidden[input index] = 1 for every vertex found hidden.
struct RecordHiddenVertex {
  const uint32_t* unique;
  const uint8_t* vertex_hidden;
  uint8_t* input_hidden;
  GALPHA_HD void operator()(uint32_t v) const {
    if (vertex_hidden[v] != 0) input_hidden[unique[v]] = 1;
  }
};

struct IsOwnRepresentative {
  const uint32_t* representative;
  GALPHA_HD bool operator()(uint32_t i) const { return representative[i] == i; }
};

struct IsFiniteTri {
  MeshView mesh;
  GALPHA_HD bool operator()(int32_t t) const { return !mesh.IsInfinite(t); }
};

/// A triangulation in an execution system's memory, named by input indices: what the alpha
/// pipeline reads without a round trip through the host.
template <class System>
struct SystemTriangulation {
  explicit SystemTriangulation(System& sys)
      : points(sys, 0),
        weights(sys, 0),
        representative(sys, 0),
        hidden(sys, 0),
        tri(sys, 0),
        nbr(sys, 0),
        edge_begin(sys, 0),
        edges(sys, 0) {}
  /// The input as given (kept only when asked for), and its weights when weighted.
  Buffer<Point2, System> points;
  Buffer<double, System> weights;
  /// For every input index, its first occurrence.
  Buffer<uint32_t, System> representative;
  uint32_t num_unique = 0;
  /// Weighted: 1 for every input index whose point is hidden (not a vertex of the regular
  /// triangulation; duplicates are marked through their representative by the caller); else empty.
  Buffer<uint8_t, System> hidden;
  /// Finite triangles (input indices, counter-clockwise), neighbours (-1 on the hull), the first
  /// owned edge of each triangle, and the edges by the ownership rule.
  Buffer<Tri, System> tri;
  Buffer<TriNbr, System> nbr;
  Buffer<uint32_t, System> edge_begin;
  Buffer<EdgePair, System> edges;
};

// The host receives the triangulation byte for byte as std::arrays (RunTriangulation, the alpha family).
static_assert(sizeof(std::array<uint32_t, 3>) == sizeof(Tri), "triangle layout");
static_assert(sizeof(std::array<int32_t, 3>) == sizeof(TriNbr), "neighbour layout");
static_assert(sizeof(std::array<uint32_t, 2>) == sizeof(EdgePair), "edge layout");

/// The distinct points of the input: the input index of each one's first occurrence, sorted by
/// (x, y), then in Hilbert order (the mesh's vertex ids; Simulation of Simplicity reads them).
/// Weighted, "distinct" means distinct in position and weight, and only the heaviest point of a
/// position is kept.
template <class System>
struct DistinctPoints {
  Buffer<uint32_t, System> unique;
  uint32_t m;
};

/// Weighted input, per mesh vertex (Hilbert order): its scaled weight, its Simulation-of-Simplicity
/// rank and whether the build found it hidden. All empty when unweighted.
template <class System>
struct VertexWeights {
  explicit VertexWeights(System& sys) : weight(sys, 0), sos_rank(sys, 0), hidden(sys, 0) {}
  Buffer<double, System> weight;
  Buffer<uint32_t, System> sos_rank;
  Buffer<uint8_t, System> hidden;
  bool weighted() const { return weight.size() > 0; }
};

/// The input as given, in the system's memory.
template <class System>
Buffer<Point2, System> UploadPoints(System& sys, const Point2* host_points, uint32_t n) {
  Buffer<Point2, System> input(sys, n);
  sys.FromHost(input.data(), host_points, n);
  return input;
}

/// Exact duplicates: sort by (point, index); each run's head is the first occurrence. Writes every
/// input index's representative into `result`. Weighted (`weights` set: per input index), sorted by
/// (point, weight descending, index): a run is one point with one weight, and a run lighter than
/// another at its position is hidden (result->hidden) and is no vertex. Packed (`input_set` set:
/// the set of each input index; unweighted only), sorted by (set, point, index): duplicates are
/// duplicates within a set, and the distinct points come grouped by set.
template <class System>
DistinctPoints<System> FindDistinctPoints(System& sys, const Buffer<Point2, System>& input, const double* weights,
                                          SystemTriangulation<System>* result, const uint32_t* input_set = nullptr) {
  auto pol = sys.policy();
  const thrust::counting_iterator<uint32_t> first(0);
  const uint32_t n = static_cast<uint32_t>(input.size());
  Buffer<uint32_t, System> unique(sys, n);
  result->representative = Buffer<uint32_t, System>(sys, n);
  uint32_t m = 0;
  {
    Buffer<uint32_t, System> sorted(sys, n);
    Buffer<uint32_t, System> head(sys, n);
    // Sorted by (x, y, index): stable radix sorts by y, then by x, of the identity permutation.
    thrust::sequence(pol, sorted.begin(), sorted.end());
    {
      Buffer<uint64_t, System> keys(sys, n);
      if (weights != nullptr) {
        thrust::transform(pol, first, first + n, keys.begin(), DescendingWeightKey{weights, sorted.data()});
        thrust::stable_sort_by_key(pol, keys.begin(), keys.end(), sorted.begin());
      }
      for (const CoordinateKey::Axis axis : {CoordinateKey::kY, CoordinateKey::kX}) {
        thrust::transform(pol, first, first + n, keys.begin(), CoordinateKey{input.data(), sorted.data(), axis});
        thrust::stable_sort_by_key(pol, keys.begin(), keys.end(), sorted.begin());
      }
      if (input_set != nullptr) {
        // 32-bit keys: half the radix passes of the coordinates' 64.
        Buffer<uint32_t, System> set_keys(sys, n);
        thrust::transform(pol, first, first + n, set_keys.begin(), SetOfIndex{input_set, sorted.data()});
        thrust::stable_sort_by_key(pol, set_keys.begin(), set_keys.end(), sorted.begin());
      }
    }
    if (weights != nullptr) {
      thrust::transform(pol, first, first + n, head.begin(),
                        WeightedRunHeadPosition{input.data(), weights, sorted.data()});
    } else {
      thrust::transform(pol, first, first + n, head.begin(), RunHeadPosition{input.data(), sorted.data(), input_set});
    }
    thrust::inclusive_scan(pol, head.begin(), head.end(), head.begin(), thrust::maximum<uint32_t>());
    thrust::for_each(pol, first, first + n,
                     WriteRepresentative{sorted.data(), head.data(), result->representative.data()});
    const uint8_t* hidden = nullptr;
    if (weights != nullptr) {
      result->hidden = Buffer<uint8_t, System>(sys, n);
      thrust::for_each(pol, first, first + n,
                       MarkLighterAtSamePosition{input.data(), sorted.data(), head.data(), result->hidden.data()});
      hidden = result->hidden.data();
    }
    m = static_cast<uint32_t>(thrust::copy_if(pol, sorted.begin(), sorted.end(), first, unique.begin(),
                                              IsVisibleRunHead{head.data(), sorted.data(), hidden}) -
                              unique.begin());
  }
  // Weighted, the lighter points at a position are distinct points that are not vertices.
  result->num_unique = weights == nullptr
                           ? m
                           : static_cast<uint32_t>(thrust::count_if(
                                 pol, first, first + n, IsOwnRepresentative{result->representative.data()}));
  return {std::move(unique), m};
}

/// Whether the distinct points are fewer than three or all on one line (no triangles).
template <class System>
bool AllCollinear(System& sys, const Buffer<Point2, System>& input, DistinctPoints<System>& distinct) {
  const uint32_t m = distinct.m;
  bool collinear = m < 3;
  if (!collinear) {
    const Point2 a = sys.Read(input.data() + sys.Read(distinct.unique.data()));
    const Point2 b = sys.Read(input.data() + sys.Read(distinct.unique.data() + m - 1));
    collinear = thrust::find_if(sys.policy(), distinct.unique.begin(), distinct.unique.begin() + m,
                                NotCollinearWith{input.data(), a, b}) == distinct.unique.begin() + m;
  }
  return collinear;
}

/// No triangles: the edges of the sorted chain of distinct points. `unique` is not needed after it.
template <class System>
void WriteCollinearChain(System& sys, DistinctPoints<System>* distinct, SystemTriangulation<System>* result) {
  const thrust::counting_iterator<uint32_t> first(0);
  const uint32_t m = distinct->m;
  const uint32_t num_edges = m > 1 ? m - 1 : 0;
  result->edges = Buffer<EdgePair, System>(sys, num_edges);
  thrust::for_each(sys.policy(), first, first + num_edges,
                   WriteChainEdge{distinct->unique.data(), result->edges.data()});
  distinct->unique.Reset();
}

/// Weighted, no triangles: the regular triangulation of points on one line is the lower hull of
/// their lifts along it, a chain from which the points above it are hidden. Computed on the host
/// (a monotone chain over the sorted points, one exact collinear power test a step): input that is
/// all on one line is rare and the chain is sequential by nature. `unique` is not needed after it.
template <class System>
void WriteWeightedCollinearChain(System& sys, const Buffer<Point2, System>& input, const double* weights,
                                 DistinctPoints<System>* distinct, SystemTriangulation<System>* result) {
  const uint32_t m = distinct->m;
  const size_t n = input.size();
  std::vector<uint32_t> order = distinct->unique.ToHostVector(m);
  distinct->unique.Reset();
  const std::vector<Point2> pts = input.ToHostVector(n);
  std::vector<double> w(n);
  sys.ToHost(w.data(), weights, n);
  std::vector<uint8_t> hidden = result->hidden.ToHostVector(n);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return LexLess(pts[a], pts[b]); });
  std::vector<uint32_t> chain;
  for (const uint32_t c : order) {
    while (chain.size() >= 2) {
      const uint32_t a = chain[chain.size() - 2], b = chain.back();
      if (CollinearPowerSign(pts[a], w[a], pts[c], w[c], pts[b], w[b]) >= 0) break;
      hidden[b] = 1;
      chain.pop_back();
    }
    chain.push_back(c);
  }
  sys.FromHost(result->hidden.data(), hidden.data(), n);
  std::vector<EdgePair> edges;
  for (size_t i = 0; i + 1 < chain.size(); ++i) {
    const uint32_t a = chain[i], b = chain[i + 1];
    edges.push_back(EdgePair{{a < b ? a : b, a < b ? b : a}});
  }
  result->edges = Buffer<EdgePair, System>(sys, edges.size());
  if (!edges.empty()) sys.FromHost(result->edges.data(), edges.data(), edges.size());
}

/// A packed build's input (delaunay_batch.cuh): the set of every input index, and every set's
/// bounding box and power of two, as a build of the set alone computes them.
struct InputSets {
  const uint32_t* input_set;
  const BoundingBox* set_box;
  const int* set_scale_exponent;
};

/// Hilbert order of the distinct points: neighbours in the order are neighbours in the plane.
/// Returns the points in that order, scaled by an exact power of two (ExactScaleExponent), as the
/// mesh's vertices; `unique` is put in the same order. The output keeps the input's coordinates.
///
/// Weighted (`weights` per input index), also fills `vertex_weights`: the weights, scaled by the
/// square of the points' power of two, and the ranks in decreasing (x, y) order (`unique` arrives
/// in (x, y) order).
///
/// Packed (`sets` set; unweighted), the points are ordered by set, then along the curve over their
/// set's box, each scaled by its set's power of two: within a set, the order and the coordinates of
/// a build of that set alone.
template <class System>
Buffer<Point2, System> HilbertOrder(System& sys, Buffer<Point2, System>& input, const double* weights,
                                    DistinctPoints<System>* distinct, VertexWeights<System>* vertex_weights,
                                    const InputSets* sets = nullptr) {
  auto pol = sys.policy();
  const thrust::counting_iterator<uint32_t> first(0);
  const uint32_t m = distinct->m;
  Buffer<uint32_t, System>& unique = distinct->unique;
  Buffer<Point2, System> vertex_points(sys, m);
  Buffer<uint32_t, System> lexicographic_position(sys, weights != nullptr ? input.size() : 0);
  if (weights != nullptr) {
    thrust::for_each(pol, first, first + m, WriteLexicographicPosition{unique.data(), lexicographic_position.data()});
  }
  {
    BoundingBox box{};
    int scale_exponent = 0;
    if (sets == nullptr) {
      box = thrust::transform_reduce(pol, input.begin(), input.end(), PointToBox(),
                                     PointToBox()(sys.Read(input.data())), MergeBoxes());
      scale_exponent = ExactScaleExponent(box, [&] {
        return thrust::transform_reduce(pol, input.begin(), input.end(), SmallestNonzeroMagnitude(),
                                        static_cast<double>(INFINITY), Minimum());
      });
    }
    if (weights != nullptr) {
      scale_exponent = WeightedScaleExponent(
          scale_exponent, thrust::transform_reduce(pol, weights, weights + input.size(), SmallestNonzeroWeight(),
                                                   static_cast<double>(INFINITY), Minimum()));
    }
    Buffer<uint64_t, System> keys(sys, m);
    if (sets == nullptr) {
      thrust::transform(pol, first, first + m, keys.begin(), HilbertKey{input.data(), unique.data(), box});
    } else {
      thrust::transform(pol, first, first + m, keys.begin(),
                        SetHilbertKey{input.data(), unique.data(), sets->input_set, sets->set_box});
    }
    // Stable (ties keep the (x, y) order of `unique`), so that both backends number the same way.
    thrust::stable_sort_by_key(pol, keys.begin(), keys.end(), unique.begin());
    // Points that share a cell of the curve are ordered by a curve over their run's own box.
    Buffer<uint32_t, System> run_number(sys, m);
    thrust::transform_inclusive_scan(pol, first, first + m, run_number.begin(), StartsKeyRun{keys.data()},
                                     thrust::plus<uint32_t>());
    const uint32_t num_runs = sys.Read(run_number.data() + m - 1);
    if (num_runs < m) {
      Buffer<BoundingBox, System> run_box(sys, num_runs);
      thrust::reduce_by_key(pol, keys.begin(), keys.end(),
                            thrust::make_transform_iterator(first, PointBoxAt{input.data(), unique.data()}),
                            thrust::make_discard_iterator(), run_box.begin(), thrust::equal_to<uint64_t>(),
                            MergeBoxes());
      thrust::transform(pol, first, first + m, keys.begin(),
                        RunHilbertKey{input.data(), unique.data(), run_number.data(), run_box.data()});
      thrust::stable_sort_by_key(pol, keys.begin(), keys.end(), unique.begin());
    }
    if (sets == nullptr) {
      thrust::for_each(pol, first, first + m,
                       GatherVertex{input.data(), unique.data(), vertex_points.data(), scale_exponent});
    } else {
      thrust::for_each(pol, first, first + m,
                       GatherSetVertex{input.data(), unique.data(), sets->input_set, sets->set_scale_exponent,
                                       vertex_points.data()});
    }
    if (weights != nullptr) {
      vertex_weights->weight = Buffer<double, System>(sys, m);
      vertex_weights->sos_rank = Buffer<uint32_t, System>(sys, m);
      vertex_weights->hidden = Buffer<uint8_t, System>(sys, m);
      thrust::fill(pol, vertex_weights->hidden.begin(), vertex_weights->hidden.end(), uint8_t{0});
      thrust::for_each(
          pol, first, first + m,
          GatherWeightedVertex{weights, unique.data(), lexicographic_position.data(), m, vertex_weights->weight.data(),
                               vertex_weights->sos_rank.data(), scale_exponent});
    }
  }
  return vertex_points;
}

/// The first triangle of the mesh (vertex ids, counter-clockwise).
struct FirstTriangle {
  int32_t a, b, c;
};

/// Vertices 0, 1 and the first vertex off their line (there is one: not all are collinear).
template <class System>
FirstTriangle FindFirstTriangle(System& sys, const Buffer<Point2, System>& vertex_points, uint32_t m) {
  const thrust::counting_iterator<int32_t> vfirst(0);
  const int32_t c =
      *thrust::find_if(sys.policy(), vfirst + 2, vfirst + m, NotCollinearWithVertices{vertex_points.data()});
  int32_t a = 0, b = 1;
  if (Orient2dSign(sys.Read(vertex_points.data()), sys.Read(vertex_points.data() + 1),
                   sys.Read(vertex_points.data() + c)) < 0) {
    a = 1;
    b = 0;
  }
  return {a, b, c};
}

/// Weighted: whether a vertex is heavy enough to hide many others (its weight above the mean by 16
/// times the squared typical spacing: a disk covering some fifty points).
struct IsHeavyVertex {
  const double* weight;
  double threshold;
  GALPHA_HD bool operator()(int32_t v) const { return weight[v] > threshold; }
};

/// Orders vertex ids by their points in (x, y) order.
struct VertexLexLess {
  const Point2* pts;
  GALPHA_HD bool operator()(int32_t a, int32_t b) const { return LexLess(pts[a], pts[b]); }
};

/// Orders vertex ids by their points in (y, x) order.
struct VertexLexLessYX {
  const Point2* pts;
  GALPHA_HD bool operator()(int32_t a, int32_t b) const {
    return pts[a].y < pts[b].y || (pts[a].y == pts[b].y && pts[a].x < pts[b].x);
  }
};

/// Whether a vertex is one of the four extremes InsertRemainingVertices inserts first.
struct IsExtremeVertex {
  int32_t v[4];
  GALPHA_HD bool operator()(int32_t x) const { return x == v[0] || x == v[1] || x == v[2] || x == v[3]; }
};

/// The most heavy vertices inserted before the others (InsertRemainingVertices): the others then
/// walk from the first triangle through a mesh of at most this many vertices.
constexpr uint32_t kMaxHeavyFirst = 1024;

/// Inserts every vertex but the first triangle's into the builder's mesh, in rounds.
///
/// Unweighted, the first and last vertices in (x, y) and in (y, x) order, hull vertices all, are
/// inserted first (a few rounds of one to four points). Why: a hull vertex inserted late takes
/// over the fan its predecessor built, one flip an iteration; the ends of collinear runs (the ends
/// of two crossing lines, whose longer line's far points all fan from the shorter line's end) are
/// such vertices. Counted on the CPU backend at 1M: parallel_lines 212 -> 145 one-block flip
/// iterations, two_lines 451 -> 402, grid 73 -> 60, uniform 76 -> 68 (ulp_lattice 66 -> 75,
/// circle 280 -> 288); on an H200 the insertion of two_lines, parallel_lines and grid took 0.7 to
/// 1.7 ms less (bench/README.md, twentieth session).
///
/// Weighted, a few heavy vertices (IsHeavyVertex, at most kMaxHeavyFirst) are inserted first: the
/// points their disks hide are then hidden on relocation, instead of being inserted before them
/// and removed afterwards ring by ring (measured: one disk over a quarter of 1M points took 404 ms
/// on an H100 that way).
template <class System>
void InsertRemainingVertices(System& sys, DelaunayBuilder<System>* builder, FirstTriangle first, uint32_t m,
                             const Buffer<Point2, System>& vertex_points, const VertexWeights<System>& weights) {
  auto pol = sys.policy();
  const thrust::counting_iterator<int32_t> vfirst(0);
  const uint32_t num_pending = m - 3;
  Buffer<int32_t, System> pending(sys, num_pending);
  Buffer<int32_t, System> location(sys, num_pending);
  Buffer<uint8_t, System> inserted(sys, num_pending);
  thrust::copy_if(pol, vfirst, vfirst + m, pending.begin(), NotInitialVertex{first.a, first.b, first.c});
  thrust::fill(pol, location.begin(), location.end(), 0);
  thrust::fill(pol, inserted.begin(), inserted.end(), uint8_t{0});
  // The vertices inserted first (heavy ones, or the extremes), moved to the front of `pending`.
  uint32_t num_first = 0;
  const Point2* pts = vertex_points.data();
  if (weights.weighted()) {
    const BoundingBox box =
        thrust::transform_reduce(pol, pts, pts + m, PointToBox(), PointToBox()(sys.Read(pts)), MergeBoxes());
    const double spacing_sq = (box.max_x - box.min_x) * (box.max_y - box.min_y) / m;
    const double mean = thrust::reduce(pol, weights.weight.data(), weights.weight.data() + m, 0.0) / m;
    const auto heavy = IsHeavyVertex{weights.weight.data(), mean + 16.0 * spacing_sq};
    num_first = static_cast<uint32_t>(thrust::count_if(pol, pending.begin(), pending.end(), heavy));
    if (num_first > kMaxHeavyFirst) {
      num_first = 0;
    } else if (num_first > 0) {
      thrust::stable_partition(pol, pending.begin(), pending.end(), heavy);
    }
  } else {
    // One pass (and one wait) per order: its first and last vertex.
    const auto xy = thrust::minmax_element(pol, vfirst, vfirst + m, VertexLexLess{pts});
    const auto yx = thrust::minmax_element(pol, vfirst, vfirst + m, VertexLexLessYX{pts});
    const IsExtremeVertex extreme{{*xy.first, *xy.second, *yx.first, *yx.second}};
    num_first = static_cast<uint32_t>(thrust::count_if(pol, pending.begin(), pending.end(), extreme));
    if (num_first > 0) thrust::stable_partition(pol, pending.begin(), pending.end(), extreme);
  }
  if (num_first > 0) builder->InsertAll(pending.data(), location.data(), inserted.data(), num_first);
  builder->InsertAll(pending.data() + num_first, location.data() + num_first, inserted.data() + num_first,
                     num_pending - num_first);
}

/// The Delaunay mesh of the distinct points (Hilbert order): the first triangle, then every other
/// vertex by insertion rounds with Lawson flips. Held in an optional so that the mesh can be freed
/// as soon as the output holds its triangles.
template <class System>
void BuildMesh(System& sys, const Buffer<Point2, System>& vertex_points, DistinctPoints<System>& distinct,
               VertexWeights<System>& vertex_weights, std::optional<DelaunayBuilder<System>>* builder) {
  const FirstTriangle first = FindFirstTriangle(sys, vertex_points, distinct.m);
  const bool weighted = vertex_weights.weighted();
  builder->emplace(sys, vertex_points.data(), distinct.unique.data(),
                   weighted ? vertex_weights.sos_rank.data() : distinct.unique.data(),
                   weighted ? vertex_weights.weight.data() : nullptr, weighted ? vertex_weights.hidden.data() : nullptr,
                   distinct.m, first.a, first.b, first.c);
  (*builder)->Start(first.a, first.b, first.c);
  InsertRemainingVertices(sys, &**builder, first, distinct.m, vertex_points, vertex_weights);
}

/// Replaces `buffer` by its entries at the first `num_kept` positions of `kept`.
template <class T, class System>
void GatherKept(System& sys, Buffer<uint32_t, System>& kept, uint32_t num_kept, Buffer<T, System>* buffer) {
  Buffer<T, System> next(sys, num_kept);
  thrust::gather(sys.policy(), kept.begin(), kept.begin() + num_kept, buffer->begin(), next.begin());
  *buffer = std::move(next);
}

/// Weighted: records the vertices found hidden in the input's flags (`result->hidden`) and removes
/// them from the vertices (Hilbert order kept), for a build without them.
template <class System>
void DropHiddenVertices(System& sys, Buffer<Point2, System>* vertex_points, DistinctPoints<System>* distinct,
                        VertexWeights<System>* vertex_weights, SystemTriangulation<System>* result) {
  auto pol = sys.policy();
  const thrust::counting_iterator<uint32_t> first(0);
  const uint32_t m = distinct->m;
  const uint8_t* hidden = vertex_weights->hidden.data();
  thrust::for_each(pol, first, first + m, RecordHiddenVertex{distinct->unique.data(), hidden, result->hidden.data()});
  Buffer<uint32_t, System> kept(sys, m);
  const auto num_kept =
      static_cast<uint32_t>(thrust::copy_if(pol, first, first + m, hidden, kept.begin(), IsClear()) - kept.begin());
  GatherKept(sys, kept, num_kept, vertex_points);
  GatherKept(sys, kept, num_kept, &distinct->unique);
  GatherKept(sys, kept, num_kept, &vertex_weights->weight);
  GatherKept(sys, kept, num_kept, &vertex_weights->sos_rank);
  vertex_weights->hidden = Buffer<uint8_t, System>(sys, num_kept);
  thrust::fill(pol, vertex_weights->hidden.begin(), vertex_weights->hidden.end(), uint8_t{0});
  distinct->m = num_kept;
}

/// Output, first part: the finite triangles of the mesh by input index, and their neighbours.
template <class System>
void OutputTriangles(System& sys, const DelaunayBuilder<System>& builder, SystemTriangulation<System>* result) {
  auto pol = sys.policy();
  const MeshView mesh = builder.mesh();
  const int32_t num_tri = builder.num_triangles();
  const thrust::counting_iterator<int32_t> tfirst(0);
  Buffer<int32_t, System> finite_id(sys, num_tri);
  thrust::transform_exclusive_scan(pol, tfirst, tfirst + num_tri, finite_id.begin(), IsFiniteTriangle{mesh}, 0,
                                   thrust::plus<int32_t>());
  const int32_t num_finite = static_cast<int32_t>(thrust::count_if(pol, tfirst, tfirst + num_tri, IsFiniteTri{mesh}));
  result->tri = Buffer<Tri, System>(sys, num_finite);
  result->nbr = Buffer<TriNbr, System>(sys, num_finite);
  thrust::for_each(pol, tfirst, tfirst + num_tri,
                   WriteFiniteTriangle{mesh, finite_id.data(), result->tri.data(), result->nbr.data()});
  finite_id.Reset();
}

/// Output, second part: the edges by the ownership rule, from the output's triangles alone.
template <class System>
void OutputEdges(System& sys, SystemTriangulation<System>* result) {
  auto pol = sys.policy();
  const thrust::counting_iterator<int32_t> tfirst(0);
  const int32_t num_finite = static_cast<int32_t>(result->tri.size());
  result->edge_begin = Buffer<uint32_t, System>(sys, num_finite);
  const Tri* out_tri = result->tri.data();
  const TriNbr* out_nbr = result->nbr.data();
  thrust::transform_exclusive_scan(pol, tfirst, tfirst + num_finite, result->edge_begin.begin(),
                                   CountOwnedEdges{out_tri, out_nbr}, 0u, thrust::plus<uint32_t>());
  const uint32_t num_edges = sys.Read(result->edge_begin.data() + num_finite - 1) +
                             thrust::transform_reduce(pol, tfirst + num_finite - 1, tfirst + num_finite,
                                                      CountOwnedEdges{out_tri, out_nbr}, 0u, thrust::plus<uint32_t>());
  result->edges = Buffer<EdgePair, System>(sys, num_edges);
  thrust::for_each(pol, tfirst, tfirst + num_finite,
                   WriteOwnedEdges{out_tri, out_nbr, result->edge_begin.data(), result->edges.data()});
}

/// Triangulates `n` host points on `sys`; the result stays in the system's memory. With
/// `keep_points` the uploaded input is kept in the result (else it is freed as soon as possible).
/// One stage a call.
///
/// Weighted (`host_weights` set, one per point): the regular triangulation. Points found hidden
/// while inserting are left out as they are found; a point that turns out hidden only after its
/// insertion (MarkRedundant) is removed from the mesh in place (RemoveMarked), and the flips go on;
/// on the hull, it makes the mesh be built again without every point found hidden so far. Both end:
/// each pass removes at least one more. Stage "regular_check": the checks, removals and rebuilds.
template <class System>
SystemTriangulation<System> TriangulateOnSystem(System& sys, const Point2* host_points, const double* host_weights,
                                                uint32_t n, bool keep_points, StageTimer<System>& timer) {
  SystemTriangulation<System> result(sys);
  // The input as given; freed once the distinct points are gathered in Hilbert order.
  Buffer<Point2, System> input = UploadPoints(sys, host_points, n);
  Buffer<double, System> input_weights(sys, host_weights != nullptr ? n : 0);
  if (host_weights != nullptr) sys.FromHost(input_weights.data(), host_weights, n);
  const double* weights = host_weights != nullptr ? input_weights.data() : nullptr;
  timer.EndStage("upload");
  DistinctPoints<System> distinct = FindDistinctPoints(sys, input, weights, &result);
  timer.EndStage("dedupe");
  auto finish_on_a_line = [&] {
    if (weights != nullptr) {
      WriteWeightedCollinearChain(sys, input, weights, &distinct, &result);
    } else {
      WriteCollinearChain(sys, &distinct, &result);
    }
    if (keep_points) {
      result.points = std::move(input);
      result.weights = std::move(input_weights);
    }
    timer.EndStage("collinear_chain");
  };
  if (AllCollinear(sys, input, distinct)) {
    finish_on_a_line();
    return result;
  }
  VertexWeights<System> vertex_weights(sys);
  Buffer<Point2, System> vertex_points = HilbertOrder(sys, input, weights, &distinct, &vertex_weights);
  auto release_input = [&] {
    if (keep_points) {
      result.points = std::move(input);
    } else {
      input.Reset();
    }
  };
  if (weights == nullptr) release_input();  // weighted, a rebuild may need it (AllCollinear)
  timer.EndStage("hilbert_sort");
  std::optional<DelaunayBuilder<System>> builder;
  BuildMesh(sys, vertex_points, distinct, vertex_weights, &builder);
  timer.EndStage("insert_and_flip");
  builder->RepairHull();
  timer.EndStage("hull_repair");
  if (weights != nullptr) {
    for (;;) {
      // Points hidden by points inserted after them: removed in place; those on the hull (or with
      // too many neighbours) by building again without every point found hidden so far.
      if (builder->MarkRedundant() == 0) break;
      if (builder->RemoveMarked() == 0) continue;
      builder.reset();
      DropHiddenVertices(sys, &vertex_points, &distinct, &vertex_weights, &result);
      if (AllCollinear(sys, input, distinct)) {
        vertex_points.Reset();
        finish_on_a_line();
        return result;
      }
      BuildMesh(sys, vertex_points, distinct, vertex_weights, &builder);
      builder->RepairHull();
    }
    thrust::for_each(sys.policy(), thrust::counting_iterator<uint32_t>(0),
                     thrust::counting_iterator<uint32_t>(distinct.m),
                     RecordHiddenVertex{distinct.unique.data(), vertex_weights.hidden.data(), result.hidden.data()});
    timer.EndStage("regular_check");
  }
  if (weights != nullptr) release_input();
  if (keep_points) {
    result.weights = std::move(input_weights);
  } else {
    input_weights.Reset();
  }
  builder->ReleaseWorkspace();
  OutputTriangles(sys, *builder, &result);
  builder.reset();  // the mesh, as soon as the output holds its triangles
  vertex_points.Reset();
  distinct.unique.Reset();
  OutputEdges(sys, &result);
  timer.EndStage("output");
  return result;
}

/// The triangulation of `n` input points into `out`'s host vectors: its distinct count, triangles,
/// neighbours, edges and every input index's representative (not the hidden points).
template <class System>
void DownloadTriangulation(System& sys, const SystemTriangulation<System>& t, uint32_t n, DelaunayOutput* out) {
  out->num_unique = t.num_unique;
  out->triangles.resize(t.tri.size());
  out->neighbors.resize(t.nbr.size());
  out->tri_edge_begin.resize(t.edge_begin.size());
  out->edges.resize(t.edges.size());
  out->representative.resize(n);
  sys.Download({{out->triangles.data(), t.tri.data(), t.tri.size() * sizeof(Tri)},
                {out->neighbors.data(), t.nbr.data(), t.nbr.size() * sizeof(TriNbr)},
                {out->tri_edge_begin.data(), t.edge_begin.data(), t.edge_begin.size() * sizeof(uint32_t)},
                {out->edges.data(), t.edges.data(), t.edges.size() * sizeof(EdgePair)},
                {out->representative.data(), t.representative.data(), size_t{n} * sizeof(uint32_t)}});
}

/// Runs the whole triangulation of `n` host points on `sys` and downloads it into `out`.
template <class System>
void RunTriangulation(System& sys, const Point2* host_points, const double* host_weights, uint32_t n,
                      DelaunayOutput* out) {
  StageTimer<System> timer(sys, &out->stage_times);
  SystemTriangulation<System> t = TriangulateOnSystem(sys, host_points, host_weights, n, /*keep_points=*/false, timer);
  DownloadTriangulation(sys, t, n, out);
  if (host_weights != nullptr) {
    const std::vector<uint8_t> hidden = t.hidden.ToHostVector(n);
    for (uint32_t i = 0; i < n; ++i) {
      if (hidden[out->representative[i]] != 0) out->hidden.push_back(i);
    }
  }
  timer.EndStage("download");
  timer.Finish();
  out->peak_memory_bytes = sys.peak_bytes();
}

}  // namespace galpha::detail
