// The families of many point sets in one packed build (issue 20: one hull per feature): the packed
// triangulation (gpu/triangulation/delaunay_batch.cuh), then the alpha pipeline's stages
// (alpha_impl.cuh) run once over all the sets' simplices, then each set's family cut out on the
// host (gpu/alpha/packed_families.cpp). Written once over an execution system.
//
// Why each set's family is the one a build of the set alone gives, bit for bit:
// - Its triangulation is (delaunay_batch.cuh), with its triangles and edges one run each, in their
//   order alone; the radius keys, attachment and intervals of a simplex read only its own points
//   and neighbours, so they are the same.
// - The spectrum is sorted and repaired exactly over all the sets together: the runs of possible
//   ties may then mix sets, but the result is the exact order of all the values, each value's
//   entries together. The entries are then sorted stably by set, and a value starts in a set
//   where the entry before it is of another set or of a smaller value (SeparateSetsInSpectrum):
//   each set's entries are in exact order and its values start where its own build's start, so
//   its ranks are its own, numbered on from the sets' before it (R + 1..R + K). Which simplex
//   names a rank is the smallest id of that value (ScatterRanks), which keeps its place among the
//   set's simplices.
// - Every level's counts are additive over the sets (components and holes by forests and the Euler
//   characteristic, component_curve.cuh; areas), and at packed level R + l the sets before s are
//   at their last level, set s at its level l and the sets after it at level 0: set s's curve is
//   the difference curve[R + l] - curve[R] plus its own level 0 (its distinct points for the
//   components, zero for the rest). The areas are measured in each set's own scale
//   (PackedAreaCurves).
// - The master list is by rank, and each rank's entries are one set's, in the order of kind, then
//   id: the set's ids keep their order.
// What is not a set's own: the counts of exact comparisons (of the sets together) and a set whose
// mesh held a flat triangle (its part is not its family: the caller builds it alone).
#pragma once

#include <thrust/binary_search.h>
#include <thrust/copy.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_impl.cuh"
#include "gpu/triangulation/delaunay_batch.cuh"

namespace galpha::detail {

/// The set of a simplex id of a packed build (triangles first, then edges): its first vertex's.
struct SimplexSetOf {
  const TriIdx* tri;
  const EdgeIdx* edges;
  uint32_t num_tri;
  const uint32_t* input_set;
  GALPHA_HD uint32_t operator()(uint32_t id) const {
    return input_set[id < num_tri ? tri[id].v[0] : edges[id - num_tri].v[0]];
  }
};

/// Entry i of the spectrum sorted by set starts a value of its set: the first of its set, or of a
/// larger exact value than the entry before it (`value`: each entry's rank among all the sets).
struct ValueStartInSet {
  const uint32_t* set;
  const uint32_t* value;
  GALPHA_HD uint8_t operator()(uint32_t i) const {
    return i == 0 || set[i] != set[i - 1] || value[i] != value[i - 1] ? 1 : 0;
  }
};

/// Each set's edges are one run (its mesh's, in triangle order, or its chain): edge e records
/// where its set's run begins or ends.
struct MarkSetEdgeRun {
  const EdgeIdx* edges;
  const uint32_t* input_set;
  uint32_t num_edges;
  uint32_t* first;
  uint32_t* last;
  GALPHA_HD void operator()(uint32_t e) const {
    const uint32_t set = input_set[edges[e].v[0]];
    if (e == 0 || input_set[edges[e - 1].v[0]] != set) first[set] = e;
    if (e + 1 == num_edges || input_set[edges[e + 1].v[0]] != set) last[set] = e + 1;
  }
};

/// The chains of the sets on one line join the mesh edges, after them: every edge of the build in
/// one array, as the pipeline reads it (a chain's edges have no triangles).
template <class System>
void AppendChains(System& sys, PackedTriangulation<System>* packed) {
  const size_t num_chain = packed->chain.size();
  if (num_chain == 0) return;
  SystemTriangulation<System>& t = packed->mesh;
  const size_t num_mesh = t.edges.size();
  Buffer<EdgePair, System> edges(sys, num_mesh + num_chain);
  if (num_mesh > 0) thrust::copy_n(sys.policy(), t.edges.data(), num_mesh, edges.data());
  thrust::copy_n(sys.policy(), packed->chain.data(), num_chain, edges.data() + num_mesh);
  t.edges = std::move(edges);
  packed->chain.Reset();
}

/// Where each set's edges lie (an empty run at 0 for a set without edges).
template <class System>
void FindSetEdgeRuns(System& sys, const PipelineMesh& mesh, const uint32_t* input_set, uint32_t num_sets,
                     PackedFamilyOutput* out) {
  auto policy = sys.policy();
  Buffer<uint32_t, System> first(sys, num_sets);
  Buffer<uint32_t, System> last(sys, num_sets);
  thrust::fill_n(policy, first.data(), num_sets, 0u);
  thrust::fill_n(policy, last.data(), num_sets, 0u);
  thrust::for_each_n(policy, thrust::counting_iterator<uint32_t>(0), mesh.num_edges,
                     MarkSetEdgeRun{mesh.edges, input_set, mesh.num_edges, first.data(), last.data()});
  out->set_edge_begin = first.ToHostVector(num_sets);
  out->set_edge_end = last.ToHostVector(num_sets);
}

/// The exact spectrum of all the sets (every value's entries together) sorted stably by set, and
/// each set's value starts marked (see the file's comment).
template <class System>
void SeparateSetsInSpectrum(System& sys, const PipelineMesh& mesh, const uint32_t* input_set,
                            ExactSpectrum<System>* spectrum) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num = spectrum->num_entries;
  if (num == 0) return;
  Buffer<uint32_t, System> value(sys, num);
  const auto as_u32 = thrust::make_transform_iterator(spectrum->new_value.data(), ToU32{});
  thrust::inclusive_scan(policy, as_u32, as_u32 + num, value.data());
  Buffer<uint32_t, System> set(sys, num);
  thrust::transform(policy, spectrum->ids.data(), spectrum->ids.data() + num, set.data(),
                    SimplexSetOf{mesh.tri, mesh.edges, mesh.num_tri, input_set});
  Buffer<uint32_t, System> order(sys, num);
  thrust::sequence(policy, order.data(), order.data() + num);
  thrust::stable_sort_by_key(policy, set.data(), set.data() + num, order.data());
  Buffer<uint32_t, System> ids(sys, num);
  Buffer<uint32_t, System> set_value(sys, num);
  thrust::gather(policy, order.data(), order.data() + num, spectrum->ids.data(), ids.data());
  thrust::gather(policy, order.data(), order.data() + num, value.data(), set_value.data());
  thrust::transform(policy, zero, zero + num, spectrum->new_value.data(),
                    ValueStartInSet{set.data(), set_value.data()});
  spectrum->ids = std::move(ids);
}

/// Where each set's ranks begin: the ranks are numbered set after set, and each names a simplex of
/// its set.
template <class System>
std::vector<uint32_t> SetRankBegin(System& sys, const PipelineMesh& mesh, const uint32_t* input_set,
                                   const SpectrumRanks<System>& ranks, uint32_t num_sets) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> rank_set(sys, ranks.num_ranks);
  thrust::transform(policy, ranks.spectrum_simplex.data(), ranks.spectrum_simplex.data() + ranks.num_ranks,
                    rank_set.data(), SimplexSetOf{mesh.tri, mesh.edges, mesh.num_tri, input_set});
  Buffer<uint32_t, System> begin(sys, size_t{num_sets} + 1);
  thrust::lower_bound(policy, rank_set.data(), rank_set.data() + ranks.num_ranks, zero, zero + (num_sets + 1),
                      begin.data());
  return begin.ToHostVector(size_t{num_sets} + 1);
}

/// The packed build's additions to the pipeline (alpha_impl.cuh's RunAlphaPipeline): where each
/// set's edges lie, the exact order separated by set, where each set's ranks lie, each set's
/// area scale.
template <class System>
struct SetPacking {
  const uint32_t* input_set;
  uint32_t num_sets;
  PackedFamilyOutput* out;
  PackedAreaSets area;

  void AfterMesh(System& sys, const PipelineMesh& mesh) { FindSetEdgeRuns(sys, mesh, input_set, num_sets, out); }
  void AfterExactOrder(System& sys, const PipelineMesh& mesh, ExactSpectrum<System>* exact, StageTimer<System>& timer) {
    SeparateSetsInSpectrum(sys, mesh, input_set, exact);
    timer.EndStage("spectrum_sets");
  }
  void AfterRanks(System& sys, const PipelineMesh& mesh, const SpectrumRanks<System>& ranks) {
    out->set_rank_begin = SetRankBegin(sys, mesh, input_set, ranks, num_sets);
  }
  const PackedAreaSets* area_sets() const { return &area; }
};

/// The packed build of the families of `num_sets` sets of `n` host points (set s: [set_begin[s],
/// set_begin[s + 1])) on `sys`, downloaded into `out` (see PackedFamilyOutput). One stage a call.
template <class System>
void RunPackedFamilyBuild(System& sys, const Point2* host_points, const uint32_t* host_set_begin, uint32_t num_sets,
                          uint32_t n, const BuildHooks& hooks, PackedFamilyOutput* out) {
  StageTimer<System> timer(sys, &out->all.stage_times);
  PackedTriangulation<System> packed =
      TriangulateSetsOnSystem(sys, host_points, host_set_begin, num_sets, n, /*keep_points=*/true, timer);
  if (hooks.after_triangulation) hooks.after_triangulation();
  AppendChains(sys, &packed);
  out->set_triangle_begin = std::move(packed.set_triangle_begin);
  if (out->set_triangle_begin.empty()) out->set_triangle_begin.assign(size_t{num_sets} + 1, 0);
  out->build_alone = std::move(packed.build_alone);
  const uint32_t* input_set = packed.input_set.data();
  const SetPacking<System> packing{input_set, num_sets, out, PackedAreaSets{input_set, num_sets, &out->set_area_scale}};
  RunAlphaPipeline<System, SetPacking<System>>(sys, packed.mesh, host_points, /*host_weights=*/nullptr, timer,
                                               hooks.max_exact_comparisons,
                                               /*persistence=*/false, /*resident=*/nullptr, &out->all, packing);
  timer.Finish();
  out->all.peak_memory_bytes = sys.peak_bytes();
}

}  // namespace galpha::detail
