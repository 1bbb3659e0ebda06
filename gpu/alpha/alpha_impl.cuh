// The alpha pipeline after the triangulation, written once over an execution system (CpuSystem or
// CudaSystem): edge topology, radii and attachment, the exact spectrum (sort by certified keys,
// exact repair of the runs whose keys may tie, merge of exact ties), ranks, intervals and the
// master list and the component curves (the report "Computing 2D Alpha Shapes Using GPU", chapters 3-4;
// docs/design.md, "Semantics" and "Exactness").
#pragma once

#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/functional.h>
#include <thrust/for_each.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/reduce.h>
#include <thrust/scan.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>

#include <cstdint>
#include <vector>

#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/alpha/alpha_host_repair.hpp"
#include "gpu/alpha/component_curve.cuh"
#include "gpu/triangulation/delaunay_impl.cuh"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

/// Runs the alpha pipeline on the triangulation `t` (in `sys`'s memory, with its points kept) and
/// downloads the family into `out`: triangles, edges, duplicate map and rank tables. `host_points`
/// is the same input in host memory (the host's exact repairs read it).
template <class System>
void RunAlphaPipeline(System& sys, SystemTriangulation<System>& t, const Point2* host_points, StageTimer<System>& timer,
                      FamilyOutput* family) {
  static_assert(sizeof(TriIdx) == sizeof(std::array<uint32_t, 3>), "layout of the host triangles");
  static_assert(sizeof(TriNb) == sizeof(std::array<int32_t, 3>), "layout of the host neighbours");
  static_assert(sizeof(EdgeIdx) == sizeof(std::array<uint32_t, 2>), "layout of the host edges");
  static_assert(sizeof(EdgeTris) == sizeof(std::array<int32_t, 2>), "layout of the edge triangles");
  static_assert(sizeof(TriIdx) == sizeof(Tri) && sizeof(TriNb) == sizeof(TriNbr) && sizeof(EdgeIdx) == sizeof(EdgePair),
                "the triangulation's layout is the pipeline's");
  AlphaRanks* out = &family->ranks;
  auto policy = sys.policy();
  const uint32_t n = static_cast<uint32_t>(t.points.size());
  const uint32_t num_tri = static_cast<uint32_t>(t.tri.size()), num_edges = static_cast<uint32_t>(t.edges.size());
  const uint32_t num_simplices = num_tri + num_edges;
  thrust::counting_iterator<uint32_t> zero(0);

  Buffer<uint32_t, System>& representative = t.representative;
  auto& points = t.points;
  const TriIdx* tri_data = reinterpret_cast<const TriIdx*>(t.tri.data());
  const TriNb* nbr_data = reinterpret_cast<const TriNb*>(t.nbr.data());
  const EdgeIdx* edge_data = reinterpret_cast<const EdgeIdx*>(t.edges.data());

  // The triangulation's arrays the family keeps go to the host beside the pipeline, from now on
  // (the host arrays are sized at once: sizing a HostVector touches no memory).
  family->triangles.resize(num_tri);
  family->edges.resize(num_edges);
  family->representative.resize(n);
  family->num_unique = t.num_unique;
  auto mesh_download = sys.DownloadAsync(
      {{family->triangles.data(), t.tri.data(), size_t{num_tri} * sizeof(TriIdx)},
       {family->edges.data(), t.edges.data(), size_t{num_edges} * sizeof(EdgeIdx)},
       {family->representative.data(), representative.data(), size_t{n} * sizeof(uint32_t)}});
  AlphaInput host_input;
  host_input.points = host_points;
  host_input.triangles = family->triangles.data();
  host_input.num_triangles = num_tri;
  host_input.edges = family->edges.data();
  // The rare host repairs read the mesh on the host.
  auto host_mesh = [&]() -> const AlphaInput& {
    mesh_download.Wait();
    return host_input;
  };

  // Edge topology: the incident triangles of every edge (none for a collinear chain).
  Buffer<EdgeTris, System> edge_tris(sys, num_edges);
  thrust::fill_n(policy, edge_tris.data(), num_edges, EdgeTris{{-1, -1}});
  thrust::for_each_n(policy, zero, num_tri, WriteEdgeTriangles{tri_data, nbr_data, t.edge_begin.data(), edge_tris.data()});
  t.nbr.Reset();
  t.edge_begin.Reset();
  timer.EndStage("edge_topology");

  // Radii and attachment: one certified key per simplex.
  const SimplexPoints simplex{points.data(), tri_data, edge_data, num_tri};
  Buffer<uint64_t, System> keys(sys, num_simplices);
  Buffer<uint8_t, System> uncertified(sys, num_simplices);
  thrust::for_each_n(policy, zero, num_simplices,
                     ComputeRadiusKeys{simplex, edge_tris.data(), keys.data(), uncertified.data()});
  timer.EndStage("radii_attachment");

  // The spectrum's entries: triangles and unattached edges with certified keys, sorted by key;
  // the few uncertified ones are placed by the host with exact comparisons.
  Buffer<uint32_t, System> ids(sys, num_simplices);
  const uint32_t num_entries = static_cast<uint32_t>(
      thrust::copy_if(policy, zero, zero + num_simplices, ids.data(), IsSpectrumEntry{keys.data(), uncertified.data(), false}) -
      ids.data());
  Buffer<uint32_t, System> odd_ids(sys, num_simplices - num_entries);
  const uint32_t num_odd = static_cast<uint32_t>(
      thrust::copy_if(policy, zero, zero + num_simplices, odd_ids.data(), IsSpectrumEntry{keys.data(), uncertified.data(), true}) -
      odd_ids.data());
  uncertified.Reset();
  Buffer<uint64_t, System> sorted_keys(sys, num_entries);
  thrust::gather(policy, ids.data(), ids.data() + num_entries, keys.data(), sorted_keys.data());
  thrust::sort_by_key(policy, sorted_keys.data(), sorted_keys.data() + num_entries, ids.data());
  timer.EndStage("spectrum_sort");

  // Runs of entries whose keys may tie: sorted exactly; short runs in parallel on the system,
  // long or undecided runs on the host.
  Buffer<uint8_t, System> new_value(sys, num_entries);
  thrust::fill_n(policy, new_value.data(), num_entries, uint8_t{1});
  uint64_t num_links = 0;
  if (num_entries > 1) {
    Buffer<uint8_t, System> link(sys, num_entries - 1);
    thrust::transform(policy, zero, zero + (num_entries - 1), link.data(), MayTieWithNext{sorted_keys.data()});
    num_links = thrust::count(policy, link.data(), link.data() + (num_entries - 1), uint8_t{1});
    Buffer<uint32_t, System> run_begin(sys, num_entries + 1);
    const uint32_t num_runs = static_cast<uint32_t>(
        thrust::copy_if(policy, zero, zero + num_entries, run_begin.data(), IsRunStart{link.data()}) - run_begin.data());
    sys.FromHost(run_begin.data() + num_runs, &num_entries, 1);
    const uint32_t* run_end = run_begin.data() + 1;
    Buffer<uint8_t, System> needs_host(sys, num_runs);
    Buffer<uint32_t, System> run_comparisons(sys, num_runs);
    thrust::for_each_n(policy, zero, num_runs,
                       RepairRun{simplex, run_begin.data(), run_end, ids.data(), new_value.data(), needs_host.data(),
                                 run_comparisons.data()});
    out->comparisons.bounded_exact +=
        thrust::reduce(policy, run_comparisons.data(), run_comparisons.data() + num_runs, uint64_t{0});
    uint32_t host_runs = static_cast<uint32_t>(thrust::count(policy, needs_host.data(), needs_host.data() + num_runs, uint8_t{1}));
    if (host_runs > 0) {
      // Long runs whose values are all exactly one double (a grid's congruent simplices) are
      // settled here, in parallel: every entry checks itself against its run's first.
      Buffer<uint32_t, System> run_of(sys, num_entries);
      const auto starts = thrust::make_transform_iterator(zero, RunStartAsU32{link.data()});
      thrust::inclusive_scan(policy, starts, starts + num_entries, run_of.data());
      Buffer<uint8_t, System> settled(sys, num_runs);
      thrust::copy_n(policy, needs_host.data(), num_runs, settled.data());
      thrust::for_each_n(policy, zero, num_entries,
                         CheckRunOfOneDouble{simplex, ids.data(), run_of.data(), run_begin.data(), settled.data()});
      thrust::for_each_n(policy, zero, num_entries,
                         SettleRunOfOneDouble{run_of.data(), run_begin.data(), settled.data(), new_value.data()});
      out->comparisons.bounded_exact += thrust::transform_reduce(
          policy, zero, zero + num_runs, SettledComparisons{run_begin.data(), settled.data()}, uint64_t{0},
          thrust::plus<uint64_t>());
      thrust::transform(policy, zero, zero + num_runs, needs_host.data(), StillNeedsHost{needs_host.data(), settled.data()});
      host_runs = static_cast<uint32_t>(thrust::count(policy, needs_host.data(), needs_host.data() + num_runs, uint8_t{1}));
    }
    link.Reset();
    if (host_runs > 0) {
      // Bring the whole order to the host once (rare: long runs of near or exact ties, such as a
      // grid's congruent triangles) and repair there.
      std::vector<uint32_t> host_ids = ids.ToHostVector(num_entries);
      std::vector<uint8_t> host_new = new_value.ToHostVector(num_entries);
      std::vector<uint32_t> host_begin = run_begin.ToHostVector(num_runs + 1);
      std::vector<uint8_t> host_needs = needs_host.ToHostVector(num_runs);
      std::vector<std::array<uint32_t, 2>> runs;
      for (uint32_t r = 0; r < num_runs; ++r) {
        if (host_needs[r]) runs.push_back({host_begin[r], host_begin[r + 1]});
      }
      RepairRunsOnHost(host_mesh(), runs, host_ids.data(), host_new.data(), &out->comparisons);
      sys.FromHost(ids.data(), host_ids.data(), num_entries);
      sys.FromHost(new_value.data(), host_new.data(), num_entries);
    }
  }
  out->comparisons.filter += num_entries > 0 ? (num_entries - 1) - num_links : 0;
  sorted_keys.Reset();

  // Entries whose keys are not certified (extreme exponent ranges inside one simplex): merged
  // into the exact order on the host.
  uint32_t total_entries = num_entries;
  if (num_odd > 0) {
    std::vector<uint32_t> host_ids = ids.ToHostVector(num_entries);
    std::vector<uint8_t> host_new = new_value.ToHostVector(num_entries);
    std::vector<uint32_t> odd = odd_ids.ToHostVector(num_odd);
    MergeUncertifiedOnHost(host_mesh(), odd, &host_ids, &host_new, &out->comparisons);
    total_entries = static_cast<uint32_t>(host_ids.size());
    ids = Buffer<uint32_t, System>(sys, total_entries);
    new_value = Buffer<uint8_t, System>(sys, total_entries);
    sys.FromHost(ids.data(), host_ids.data(), total_entries);
    sys.FromHost(new_value.data(), host_new.data(), total_entries);
  }
  odd_ids.Reset();
  timer.EndStage("spectrum_repair");

  // Ranks: an inclusive scan of the value starts numbers the distinct exact values 1..K.
  Buffer<uint32_t, System> rank(sys, total_entries);
  // (Scanned as uint32: Thrust may accumulate in the input's type, and uint8 would wrap.)
  const auto as_u32 = thrust::make_transform_iterator(new_value.data(), ToU32{});
  thrust::inclusive_scan(policy, as_u32, as_u32 + total_entries, rank.data());
  const uint32_t num_ranks = total_entries > 0 ? sys.Read(rank.data() + (total_entries - 1)) : 0;
  Buffer<uint32_t, System> tri_rank(sys, num_tri);
  Buffer<uint32_t, System> edge_rho_rank(sys, num_edges);
  thrust::fill_n(policy, tri_rank.data(), num_tri, kNeverRank);  // collinear triangles: never born
  thrust::fill_n(policy, edge_rho_rank.data(), num_edges, uint32_t{0});
  Buffer<uint32_t, System> spectrum_simplex(sys, num_ranks);
  thrust::for_each_n(policy, zero, total_entries,
                     ScatterRanks{ids.data(), rank.data(), new_value.data(), num_tri, tri_rank.data(),
                                  edge_rho_rank.data(), spectrum_simplex.data()});
  rank.Reset();
  ids.Reset();
  new_value.Reset();
  timer.EndStage("ranks");

  // Published spectrum values: the nearest doubles. (Downloaded with the rest at the end, so that
  // this stage's time is the computation's; the rare values the device cannot round are rounded
  // on the host after the download.)
  Buffer<double, System> spectrum(sys, num_ranks);
  Buffer<uint8_t, System> needs_host(sys, num_ranks);
  thrust::for_each_n(policy, zero, num_ranks,
                     NearestSpectrumValue{simplex, spectrum_simplex.data(), spectrum.data(), needs_host.data()});
  const bool any_needs_host = thrust::count(policy, needs_host.data(), needs_host.data() + num_ranks, uint8_t{1}) > 0;
  timer.EndStage("spectrum_values");

  // Intervals (report Table 2.1) for edges and vertices.
  Buffer<uint32_t, System> edge_mu_low(sys, num_edges), edge_mu_high(sys, num_edges);
  Buffer<uint32_t, System> vertex_mu_low(sys, n), vertex_mu_high(sys, n), vertex_tri_low(sys, n);
  thrust::fill_n(policy, vertex_mu_low.data(), n, kNeverRank);
  thrust::fill_n(policy, vertex_mu_high.data(), n, uint32_t{0});
  thrust::fill_n(policy, vertex_tri_low.data(), n, kNeverRank);
  thrust::for_each_n(policy, zero, num_edges,
                     EdgeIntervals{edge_data, edge_tris.data(), tri_rank.data(), edge_rho_rank.data(),
                                   edge_mu_low.data(), edge_mu_high.data(), keys.data(), num_tri,
                                   vertex_mu_low.data(), vertex_mu_high.data(), vertex_tri_low.data()});
  // Representatives first (their own values), then duplicates copy them.
  thrust::for_each_n(policy, zero, n,
                     FinishVertexIntervals{representative.data(), vertex_mu_low.data(), vertex_mu_high.data(),
                                           vertex_tri_low.data()});
  keys.Reset();
  timer.EndStage("intervals");

  // The spectrum, the ranks and the intervals are final: they go to the host beside the master
  // list and the component curves (which only read them).
  out->spectrum.resize(num_ranks);
  out->spectrum_simplex.resize(num_ranks);
  out->tri_rank.resize(num_tri);
  out->edge_rho_rank.resize(num_edges);
  out->edge_mu_low.resize(num_edges);
  out->edge_mu_high.resize(num_edges);
  out->edge_triangles.resize(num_edges);
  out->vertex_mu_low.resize(n);
  out->vertex_mu_high.resize(n);
  out->vertex_tri_low.resize(n);
  auto tables_download = sys.DownloadAsync(
      {{out->spectrum.data(), spectrum.data(), size_t{num_ranks} * sizeof(double)},
       {out->spectrum_simplex.data(), spectrum_simplex.data(), size_t{num_ranks} * sizeof(uint32_t)},
       {out->tri_rank.data(), tri_rank.data(), size_t{num_tri} * sizeof(uint32_t)},
       {out->edge_rho_rank.data(), edge_rho_rank.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_mu_low.data(), edge_mu_low.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_mu_high.data(), edge_mu_high.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_triangles.data(), edge_tris.data(), size_t{num_edges} * sizeof(EdgeTris)},
       {out->vertex_mu_low.data(), vertex_mu_low.data(), size_t{n} * sizeof(uint32_t)},
       {out->vertex_mu_high.data(), vertex_mu_high.data(), size_t{n} * sizeof(uint32_t)},
       {out->vertex_tri_low.data(), vertex_tri_low.data(), size_t{n} * sizeof(uint32_t)}});

  // Master list in CSR form: count the end points per rank, scan, place each entry in its rank's
  // segment, then sort every segment (O(entries): no global sort).
  const MasterEndpoints endpoints{representative.data(), vertex_mu_low.data(), vertex_mu_high.data(),
                                  edge_rho_rank.data(), edge_mu_low.data(), edge_mu_high.data(),
                                  tri_rank.data(), n, num_edges};
  const uint32_t num_items = n + num_edges + num_tri;
  Buffer<uint32_t, System> master_begin(sys, static_cast<size_t>(num_ranks) + 2);
  thrust::fill_n(policy, master_begin.data(), num_ranks + 2, uint32_t{0});
  thrust::for_each_n(policy, zero, num_items, CountMasterEntries{endpoints, master_begin.data()});
  thrust::exclusive_scan(policy, master_begin.data(), master_begin.data() + (num_ranks + 2), master_begin.data());
  const uint32_t num_master = sys.Read(master_begin.data() + (num_ranks + 1));
  Buffer<uint64_t, System> master_entries(sys, num_master);
  {
    Buffer<uint32_t, System> cursor(sys, static_cast<size_t>(num_ranks) + 2);
    thrust::copy_n(policy, master_begin.data(), num_ranks + 2, cursor.data());
    thrust::for_each_n(policy, zero, num_items, FillMasterEntries{endpoints, cursor.data(), master_entries.data()});
  }
  {
    Buffer<uint8_t, System> long_segment(sys, static_cast<size_t>(num_ranks) + 1);
    thrust::for_each_n(policy, zero, num_ranks + 1,
                       SortMasterSegment{master_begin.data(), master_entries.data(), long_segment.data()});
    if (thrust::count(policy, long_segment.data(), long_segment.data() + (num_ranks + 1), uint8_t{1}) > 0) {
      const std::vector<uint8_t> host_long = long_segment.ToHostVector(num_ranks + 1);
      const std::vector<uint32_t> host_begin = master_begin.ToHostVector(num_ranks + 2);
      if constexpr (System::kHostMemory) {
        // One pass over the simplices in order writes the long segments already sorted (items
        // come by kind, then id, each with its end points in order): no sort of exact ties.
        std::vector<uint32_t> cursor(host_begin.begin(), host_begin.end() - 1);
        uint64_t* entries = master_entries.data();
        auto place = [&](uint32_t rank, uint64_t packed) {
          if (host_long[rank]) entries[cursor[rank]++] = packed;
        };
        for (uint32_t item = 0; item < num_items; ++item) endpoints.Visit(item, place);
      } else {
        for (uint32_t r = 0; r <= num_ranks; ++r) {
          if (host_long[r]) {
            thrust::sort(policy, master_entries.data() + host_begin[r], master_entries.data() + host_begin[r + 1]);
          }
        }
      }
    }
  }
  timer.EndStage("master_list");

  // Component curves over all levels (Borůvka spanning forests, component_curve.cuh).
  Buffer<uint32_t, System> components(sys, static_cast<size_t>(num_ranks) + 1);
  Buffer<uint32_t, System> solid_components(sys, static_cast<size_t>(num_ranks) + 1);
  ComponentCurves(sys, n, t.num_unique, num_tri, num_edges, num_ranks, edge_data, edge_tris.data(), tri_rank.data(),
                  edge_rho_rank.data(), edge_mu_low.data(), edge_mu_high.data(), components.data(),
                  solid_components.data());
  timer.EndStage("components");

  // The rest of the family, then the downloads started earlier (the host arrays are not zeroed
  // first: the copies are their first touch, on every core; core/base/host_vector.hpp).
  out->components.resize(static_cast<size_t>(num_ranks) + 1);
  out->solid_components.resize(static_cast<size_t>(num_ranks) + 1);
  out->master_begin.resize(static_cast<size_t>(num_ranks) + 2);
  static_assert(sizeof(MasterEntry) == sizeof(uint64_t), "the packed entries are the list");
  out->master.resize(num_master);
  sys.Download({{out->components.data(), components.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
                {out->solid_components.data(), solid_components.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
                {out->master_begin.data(), master_begin.data(), (size_t{num_ranks} + 2) * sizeof(uint32_t)},
                {out->master.data(), master_entries.data(), size_t{num_master} * sizeof(uint64_t)}});
  tables_download.Wait();
  mesh_download.Wait();
  if (any_needs_host) NearestValuesOnHost(host_input, needs_host.ToHostVector(num_ranks), out);
  timer.EndStage("download");
}

/// The whole build on one system: triangulation, then the alpha pipeline on the triangulation
/// where it lies; the family comes back to the host once (partly beside the last stages).
template <class System>
void RunFamilyBuild(System& sys, const Point2* host_points, uint32_t n, const BuildHooks& hooks, FamilyOutput* out) {
  StageTimer<System> timer(sys, &out->stage_times);
  SystemTriangulation<System> t = TriangulateOnSystem(sys, host_points, n, /*keep_points=*/true, timer);
  if (hooks.after_triangulation) hooks.after_triangulation();
  RunAlphaPipeline(sys, t, host_points, timer, out);
  timer.Finish();
  out->peak_memory_bytes = sys.peak_bytes();
}

}  // namespace galpha::detail
