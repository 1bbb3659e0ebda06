// The alpha pipeline after the triangulation, written once over an execution system (CpuSystem or
// CudaSystem): edge topology, radii and attachment, the exact spectrum (sort by certified keys,
// exact repair of the runs whose keys may tie, merge of exact ties), ranks, intervals and the
// master list and the component curves (the report "Computing 2D Alpha Shapes Using GPU", chapters 3-4;
// docs/design.md, "Semantics" and "Exactness").
#pragma once

#include <thrust/binary_search.h>
#include <thrust/copy.h>
#include <thrust/count.h>
#include <thrust/fill.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/reduce.h>
#include <thrust/scan.h>
#include <thrust/scatter.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/family/alpha_ranks.hpp"
#include "gpu/alpha/alpha_backend.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/alpha/alpha_host_repair.hpp"
#include "gpu/alpha/area_curve.cuh"
#include "gpu/alpha/component_curve.cuh"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/alpha/resident_arrays.cuh"
#include "gpu/alpha/spectrum_refine.cuh"
#include "gpu/system/backend.hpp"
#include "gpu/system/engine_system.cuh"
#include "gpu/triangulation/delaunay_impl.cuh"

namespace galpha::detail {

// The pipeline reads the triangulation's arrays as the alpha functors' types, and the family's host
// arrays receive them as std::arrays: one layout throughout.
static_assert(sizeof(TriIdx) == sizeof(std::array<uint32_t, 3>), "layout of the host triangles");
static_assert(sizeof(TriNb) == sizeof(std::array<int32_t, 3>), "layout of the host neighbours");
static_assert(sizeof(EdgeIdx) == sizeof(std::array<uint32_t, 2>), "layout of the host edges");
static_assert(sizeof(EdgeTris) == sizeof(std::array<int32_t, 2>), "layout of the edge triangles");
static_assert(sizeof(TriIdx) == sizeof(Tri) && sizeof(TriNb) == sizeof(TriNbr) && sizeof(EdgeIdx) == sizeof(EdgePair),
              "the triangulation's layout is the pipeline's");

// ---- The state passed between the stages --------------------------------------------------------------

/// The triangulation as the stages read it: arrays in the system's memory, sizes on the host.
struct PipelineMesh {
  const Point2* points;
  const TriIdx* tri;
  const EdgeIdx* edges;
  const uint32_t* representative;  // per input point, its first occurrence
  const double* weights;           // per input point; nullptr for an unweighted family
  const uint8_t* hidden;           // weighted: per input point as given by the triangulation; else nullptr
  uint32_t n;                      // input points, duplicates included
  uint32_t num_unique;
  uint32_t num_vertices;  // distinct points that are vertices (weighted: not hidden)
  uint32_t num_tri;
  uint32_t num_edges;

  /// Spectrum entries are simplex ids: triangles first, then edges.
  uint32_t num_simplices() const { return num_tri + num_edges; }
  SimplexPoints simplex() const { return SimplexPoints{points, tri, edges, num_tri, weights}; }
};

template <class System>
PipelineMesh PipelineMeshOf(SystemTriangulation<System>& t) {
  PipelineMesh mesh;
  mesh.points = t.points.data();
  mesh.tri = reinterpret_cast<const TriIdx*>(t.tri.data());
  mesh.edges = reinterpret_cast<const EdgeIdx*>(t.edges.data());
  mesh.representative = t.representative.data();
  mesh.weights = t.weights.size() > 0 ? t.weights.data() : nullptr;
  mesh.hidden = t.weights.size() > 0 ? t.hidden.data() : nullptr;
  mesh.n = static_cast<uint32_t>(t.points.size());
  mesh.num_unique = t.num_unique;
  mesh.num_vertices = t.num_unique;  // weighted: less the hidden ones (HiddenVertices)
  mesh.num_tri = static_cast<uint32_t>(t.tri.size());
  mesh.num_edges = static_cast<uint32_t>(t.edges.size());
  return mesh;
}

/// A download running beside the pipeline (CudaSystem's waits when destroyed: declare it after the
/// buffers it reads).
template <class System>
using PendingDownloadOf = decltype(std::declval<System&>().DownloadAsync(std::vector<HostCopy>{}));

/// The mesh on its way to the host, where the family keeps it; the rare exact repairs on the host
/// read it there.
template <class System>
struct HostMesh {
  PendingDownloadOf<System> download;
  AlphaInput input;

  /// The mesh on the host, once it has arrived.
  const AlphaInput& Get() {
    download.Wait();
    return input;
  }
};

/// One certified radius key per simplex (kAttachedKey for attached edges), and the keys the
/// filter could not certify.
template <class System>
struct SimplexKeys {
  Buffer<uint64_t, System> key;
  Buffer<uint8_t, System> uncertified;
};

/// The spectrum's entries (triangles and unattached edges) sorted by certified key, and apart the
/// few whose keys are not certified.
template <class System>
struct SortedSpectrum {
  Buffer<uint32_t, System> ids;  // simplex ids, by key
  Buffer<uint32_t, System> odd_ids;
  Buffer<uint64_t, System> sorted_keys;  // the keys of `ids`, in order
  uint32_t num_entries;
  uint32_t num_odd;
};

/// The spectrum's entries in exact order, with the starts of the distinct exact values.
template <class System>
struct ExactSpectrum {
  Buffer<uint32_t, System> ids;
  Buffer<uint8_t, System> new_value;  // 1 where an exact value starts, 0 inside a tie
  uint32_t num_entries;
};

/// The sorted entries whose keys may tie with their neighbour's, grouped in runs.
template <class System>
struct TiedRuns {
  Buffer<uint8_t, System> link;        // link[i]: entries i and i + 1 may tie (num_entries - 1)
  Buffer<uint32_t, System> run_begin;  // each run's first entry, then num_entries (num_runs + 1)
  uint32_t num_runs;
  uint64_t num_links;
};

/// The rank of every simplex's value (1..K, in exact order) and the first simplex of every rank.
template <class System>
struct SpectrumRanks {
  Buffer<uint32_t, System> tri_rank;       // kNeverRank for collinear triangles
  Buffer<uint32_t, System> edge_rho_rank;  // 0 for attached edges
  Buffer<uint32_t, System> spectrum_simplex;
  uint32_t num_ranks;
};

/// The published spectrum values: the nearest doubles, except where the system could not round
/// (`needs_host`: rounded on the host after the download).
template <class System>
struct SpectrumValues {
  Buffer<double, System> spectrum;
  Buffer<uint8_t, System> needs_host;
  bool any_needs_host;
};

/// The intervals of edges and vertices (report Table 2.1), as ranks.
template <class System>
struct IntervalRanks {
  Buffer<uint32_t, System> edge_mu_low;
  Buffer<uint32_t, System> edge_mu_high;
  Buffer<uint32_t, System> vertex_mu_low;
  Buffer<uint32_t, System> vertex_mu_high;
  Buffer<uint32_t, System> vertex_tri_low;
};

/// The master list in CSR form: rank r's entries are entries[begin[r], begin[r + 1]).
template <class System>
struct MasterListCsr {
  Buffer<uint32_t, System> begin;
  Buffer<uint64_t, System> entries;  // packed MasterEntry values
  uint32_t num_master;
};

/// The component, hole and area curves: their values at every level 0..K.
template <class System>
struct ComponentCounts {
  Buffer<uint32_t, System> components;
  Buffer<uint32_t, System> solid_components;
  Buffer<uint32_t, System> holes;
  Buffer<uint32_t, System> regularized_components;
  Buffer<uint32_t, System> regularized_holes;
  Buffer<unsigned long long, System> area_units;
  AreaCurveScale area_scale;
};

// ---- The stages, in order ---------------------------------------------------------------------------------

/// The triangulation's arrays the family keeps go to the host beside the pipeline, from now on
/// (the host arrays are sized at once: sizing a HostVector touches no memory).
template <class System>
HostMesh<System> StartMeshDownload(System& sys, SystemTriangulation<System>& t, const PipelineMesh& mesh,
                                   const Point2* host_points, const double* host_weights, FamilyOutput* family) {
  family->triangles.resize(mesh.num_tri);
  family->edges.resize(mesh.num_edges);
  family->representative.resize(mesh.n);
  family->num_unique = t.num_unique;
  std::vector<HostCopy> copies = {
      {family->triangles.data(), t.tri.data(), size_t{mesh.num_tri} * sizeof(TriIdx)},
      {family->edges.data(), t.edges.data(), size_t{mesh.num_edges} * sizeof(EdgeIdx)},
      {family->representative.data(), t.representative.data(), size_t{mesh.n} * sizeof(uint32_t)}};
  if (mesh.hidden != nullptr) {  // weighted: the flags HiddenVertices put through the representatives
    family->hidden.resize(mesh.n);
    copies.push_back({family->hidden.data(), mesh.hidden, size_t{mesh.n}});
  }
  HostMesh<System> host{sys.DownloadAsync(std::move(copies)), AlphaInput{}};
  host.input.points = host_points;
  host.input.weights = host_weights;
  host.input.triangles = family->triangles.data();
  host.input.num_triangles = mesh.num_tri;
  host.input.edges = family->edges.data();
  return host;
}

/// Weighted: every input point's hidden flag through its representative (a duplicate of a hidden
/// point is hidden), in place in the triangulation's flags (only duplicates are written, and they
/// read representatives' flags, which nobody writes), and the number of distinct points that are
/// vertices. The flags then go to the family with the mesh (StartMeshDownload).
template <class System>
void HiddenVertices(System& sys, SystemTriangulation<System>& t, PipelineMesh& mesh) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  thrust::for_each_n(policy, zero, mesh.n, HiddenThroughRepresentative{mesh.representative, t.hidden.data()});
  mesh.num_vertices =
      mesh.num_unique - static_cast<uint32_t>(thrust::count_if(policy, zero, zero + mesh.n,
                                                               HiddenRepresentative{mesh.representative, mesh.hidden}));
}

/// Edge topology: the incident triangles of every edge (none for a collinear chain). The
/// triangulation's neighbours and edge offsets are not needed after it.
template <class System>
Buffer<EdgeTris, System> EdgeTriangles(System& sys, const PipelineMesh& mesh, SystemTriangulation<System>* t) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const TriNb* nbr_data = reinterpret_cast<const TriNb*>(t->nbr.data());
  Buffer<EdgeTris, System> edge_tris(sys, mesh.num_edges);
  thrust::fill_n(policy, edge_tris.data(), mesh.num_edges, EdgeTris{{-1, -1}});
  thrust::for_each_n(policy, zero, mesh.num_tri,
                     WriteEdgeTriangles{mesh.tri, nbr_data, t->edge_begin.data(), edge_tris.data()});
  t->nbr.Reset();
  t->edge_begin.Reset();
  return edge_tris;
}

/// Weighted edges whose attachment bounded arithmetic left undecided (rare: weights far more
/// precise than the edge is long): decided on the host by GMP, their keys and flags put right.
template <class System>
void ResolveUndecidedAttachment(System& sys, const PipelineMesh& mesh, const Buffer<EdgeTris, System>& edge_tris,
                                HostMesh<System>& host_mesh, SimplexKeys<System>* keys) {
  const uint32_t num_tri = mesh.num_tri;
  const std::vector<uint8_t> flags = keys->uncertified.ToHostVector(mesh.num_simplices());
  std::vector<uint32_t> edge_ids;
  for (uint32_t e = 0; e < mesh.num_edges; ++e) {
    if ((flags[num_tri + e] & kAttachmentUndecided) != 0) edge_ids.push_back(e);
  }
  std::vector<EdgeTris> host_edge_tris = edge_tris.ToHostVector(mesh.num_edges);
  std::vector<std::array<int32_t, 2>> triangles_of(mesh.num_edges);
  for (uint32_t e = 0; e < mesh.num_edges; ++e) triangles_of[e] = {host_edge_tris[e].t[0], host_edge_tris[e].t[1]};
  std::vector<uint8_t> attached;
  ResolveAttachmentOnHost(host_mesh.Get(), triangles_of.data(), edge_ids, &attached);
  for (size_t i = 0; i < edge_ids.size(); ++i) {
    const uint32_t id = num_tri + edge_ids[i];
    const uint8_t flag = static_cast<uint8_t>(attached[i] ? 0 : (flags[id] & 1));
    sys.FromHost(keys->uncertified.data() + id, &flag, 1);
    if (attached[i]) sys.FromHost(keys->key.data() + id, &kAttachedKey, 1);
  }
}

/// Radii and attachment: one certified key per simplex.
template <class System>
SimplexKeys<System> KeySimplices(System& sys, const PipelineMesh& mesh, const Buffer<EdgeTris, System>& edge_tris,
                                 HostMesh<System>& host_mesh) {
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_simplices = mesh.num_simplices();
  SimplexKeys<System> keys{Buffer<uint64_t, System>(sys, num_simplices), Buffer<uint8_t, System>(sys, num_simplices)};
  thrust::for_each_n(sys.policy(), zero, num_simplices,
                     ComputeRadiusKeys{mesh.simplex(), edge_tris.data(), keys.key.data(), keys.uncertified.data()});
  if (mesh.weights != nullptr &&
      thrust::count_if(sys.policy(), keys.uncertified.data(), keys.uncertified.data() + num_simplices,
                       HasFlag{kAttachmentUndecided}) > 0) {
    ResolveUndecidedAttachment(sys, mesh, edge_tris, host_mesh, &keys);
  }
  return keys;
}

/// The spectrum's entries: triangles and unattached edges with certified keys, sorted by key;
/// the few uncertified ones are placed by the host with exact comparisons (RepairSpectrum).
template <class System>
SortedSpectrum<System> SortSpectrum(System& sys, const PipelineMesh& mesh, SimplexKeys<System>* keys) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_simplices = mesh.num_simplices();
  Buffer<uint32_t, System> ids(sys, num_simplices);
  const uint32_t num_entries =
      static_cast<uint32_t>(thrust::copy_if(policy, zero, zero + num_simplices, ids.data(),
                                            IsSpectrumEntry{keys->key.data(), keys->uncertified.data(), false}) -
                            ids.data());
  Buffer<uint32_t, System> odd_ids(sys, num_simplices - num_entries);
  const uint32_t num_odd =
      static_cast<uint32_t>(thrust::copy_if(policy, zero, zero + num_simplices, odd_ids.data(),
                                            IsSpectrumEntry{keys->key.data(), keys->uncertified.data(), true}) -
                            odd_ids.data());
  keys->uncertified.Reset();
  Buffer<uint64_t, System> sorted_keys(sys, num_entries);
  thrust::gather(policy, ids.data(), ids.data() + num_entries, keys->key.data(), sorted_keys.data());
  thrust::sort_by_key(policy, sorted_keys.data(), sorted_keys.data() + num_entries, ids.data());
  return {std::move(ids), std::move(odd_ids), std::move(sorted_keys), num_entries, num_odd};
}

/// The start of every run of linked entries, then num_entries, into `run_begin` (num_entries + 1
/// long); returns the number of runs.
template <class System>
uint32_t ListRunStarts(System& sys, const Buffer<uint8_t, System>& link, uint32_t num_entries,
                       Buffer<uint32_t, System>* run_begin) {
  thrust::counting_iterator<uint32_t> zero(0);
  const auto num_runs = static_cast<uint32_t>(
      thrust::copy_if(sys.policy(), zero, zero + num_entries, run_begin->data(), IsRunStart{link.data()}) -
      run_begin->data());
  sys.FromHost(run_begin->data() + num_runs, &num_entries, 1);
  return num_runs;
}

/// The runs of sorted entries linked by keys that may tie (num_entries > 1).
template <class System>
TiedRuns<System> FindTiedRuns(System& sys, const Buffer<uint64_t, System>& sorted_keys, uint32_t num_entries) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint8_t, System> link(sys, num_entries - 1);
  thrust::transform(policy, zero, zero + (num_entries - 1), link.data(), MayTieWithNext{sorted_keys.data()});
  const uint64_t num_links = thrust::count(policy, link.data(), link.data() + (num_entries - 1), uint8_t{1});
  Buffer<uint32_t, System> run_begin(sys, num_entries + 1);
  const uint32_t num_runs = ListRunStarts(sys, link, num_entries, &run_begin);
  return {std::move(link), std::move(run_begin), num_runs, num_links};
}

/// Long runs whose values are all exactly one double (a grid's congruent simplices) are settled
/// here, in parallel: every entry checks itself against its run's first. Clears their
/// `needs_host`; returns the number of runs still left for the host.
template <class System>
uint32_t SettleRunsOfOneDouble(System& sys, const PipelineMesh& mesh, const TiedRuns<System>& runs,
                               ExactSpectrum<System>* spectrum, Buffer<uint8_t, System>* needs_host,
                               ComparisonCounts* counts) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_entries = spectrum->num_entries;
  const uint32_t num_runs = runs.num_runs;
  Buffer<uint32_t, System> run_of(sys, num_entries);
  const auto starts = thrust::make_transform_iterator(zero, RunStartAsU32{runs.link.data()});
  thrust::inclusive_scan(policy, starts, starts + num_entries, run_of.data());
  Buffer<uint8_t, System> settled(sys, num_runs);
  thrust::copy_n(policy, needs_host->data(), num_runs, settled.data());
  thrust::for_each_n(
      policy, zero, num_entries,
      CheckRunOfOneDouble{mesh.simplex(), spectrum->ids.data(), run_of.data(), runs.run_begin.data(), settled.data()});
  thrust::for_each_n(
      policy, zero, num_entries,
      SettleRunOfOneDouble{run_of.data(), runs.run_begin.data(), settled.data(), spectrum->new_value.data()});
  counts->bounded_exact +=
      thrust::transform_reduce(policy, zero, zero + num_runs, SettledComparisons{runs.run_begin.data(), settled.data()},
                               uint64_t{0}, thrust::plus<uint64_t>());
  thrust::transform(policy, zero, zero + num_runs, needs_host->data(),
                    StillNeedsHost{needs_host->data(), settled.data()});
  return static_cast<uint32_t>(thrust::count(policy, needs_host->data(), needs_host->data() + num_runs, uint8_t{1}));
}

/// Stops the build: its exact comparisons passed `limit`.
[[noreturn]] inline void ThrowExactComparisonLimit(const ComparisonCounts& counts, uint64_t limit) {
  const uint64_t used = counts.bounded_exact + counts.cpu_fallback;
  throw EngineError(EngineError::Kind::kWorkLimit,
                    "the spectrum needed more than its limit of " + std::to_string(limit) +
                        " exact radius comparisons (stopped after " + std::to_string(used) + ")");
}

/// Throws EngineError kWorkLimit once the build's exact comparisons passed `limit` (0: none).
inline void CheckExactComparisons(const ComparisonCounts& counts, uint64_t limit) {
  if (limit != 0 && counts.bounded_exact + counts.cpu_fallback > limit) ThrowExactComparisonLimit(counts, limit);
}

/// What is left of a limit of exact comparisons for the host's repairs (which stop there).
inline uint64_t ExactComparisonsLeft(const ComparisonCounts& counts, uint64_t limit) {
  if (limit == 0) return kNoComparisonLimit;
  const uint64_t used = counts.bounded_exact + counts.cpu_fallback;
  return used < limit ? limit - used : 0;
}

/// Brings the whole order to the host once (rare: long runs of near or exact ties, such as a
/// grid's congruent triangles) and repairs there the runs marked in `needs_host`.
template <class System>
void RepairRunsOnHostOnce(System& sys, HostMesh<System>& host_mesh, const TiedRuns<System>& runs,
                          const Buffer<uint8_t, System>& needs_host, ExactSpectrum<System>* spectrum,
                          uint64_t max_exact_comparisons, ComparisonCounts* counts) {
  const uint32_t num_entries = spectrum->num_entries;
  const uint32_t num_runs = runs.num_runs;
  std::vector<uint32_t> host_ids = spectrum->ids.ToHostVector(num_entries);
  std::vector<uint8_t> host_new = spectrum->new_value.ToHostVector(num_entries);
  std::vector<uint32_t> host_begin = runs.run_begin.ToHostVector(num_runs + 1);
  std::vector<uint8_t> host_needs = needs_host.ToHostVector(num_runs);
  std::vector<std::array<uint32_t, 2>> host_runs;
  for (uint32_t r = 0; r < num_runs; ++r) {
    if (host_needs[r]) host_runs.push_back({host_begin[r], host_begin[r + 1]});
  }
  if (!RepairRunsOnHost(host_mesh.Get(), host_runs, ExactComparisonsLeft(*counts, max_exact_comparisons),
                        host_ids.data(), host_new.data(), counts)) {
    ThrowExactComparisonLimit(*counts, max_exact_comparisons);
  }
  CheckExactComparisons(*counts, max_exact_comparisons);  // runs of exact doubles count after the fact
  sys.FromHost(spectrum->ids.data(), host_ids.data(), num_entries);
  sys.FromHost(spectrum->new_value.data(), host_new.data(), num_entries);
}

/// Runs of entries whose keys may tie: sorted exactly; short runs in parallel on the system,
/// long or undecided runs on the host. Returns the number of links (neighbours whose keys alone
/// did not order them). Ends the stages "spectrum_refine" (long runs by refined keys) and
/// "spectrum_repair" (the runs left, on the system); the host's part follows in the caller's.
template <class System>
uint64_t RepairTiedRuns(System& sys, const PipelineMesh& mesh, HostMesh<System>& host_mesh,
                        const Buffer<uint64_t, System>& sorted_keys, ExactSpectrum<System>* spectrum,
                        StageTimer<System>& timer, uint64_t max_exact_comparisons, ComparisonCounts* counts) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  TiedRuns<System> runs = FindTiedRuns(sys, sorted_keys, spectrum->num_entries);
  // Runs too long for one thread are ordered by refined keys first (spectrum_refine.cuh); what
  // they settle is cut out of the runs, and what is left is repaired below like any run.
  if (RefineLongRuns(sys, mesh.simplex(), runs.link.data(), runs.run_begin.data(), runs.num_runs, spectrum->ids.data(),
                     spectrum->new_value.data(), spectrum->num_entries, counts) > 0) {
    runs.num_runs = ListRunStarts(sys, runs.link, spectrum->num_entries, &runs.run_begin);
  }
  timer.EndStage("spectrum_refine");
  CheckExactComparisons(*counts, max_exact_comparisons);
  const uint32_t num_runs = runs.num_runs;
  const uint32_t* run_end = runs.run_begin.data() + 1;
  Buffer<uint8_t, System> needs_host(sys, num_runs);
  Buffer<uint32_t, System> run_comparisons(sys, num_runs);
  thrust::fill_n(policy, needs_host.data(), num_runs, uint8_t{0});
  thrust::fill_n(policy, run_comparisons.data(), num_runs, uint32_t{0});
  // One thread a run, but only for runs of two or more entries, longest first: most runs are
  // single settled values, and a thread for each left warps with two busy lanes of 32 (centimetre
  // LiDAR at 1M: 29 ms of divergent waiting on the H100).
  Buffer<uint32_t, System> tied(sys, num_runs);
  const auto num_tied = static_cast<uint32_t>(
      thrust::copy_if(policy, zero, zero + num_runs, tied.data(), IsTiedRun{runs.run_begin.data()}) - tied.data());
  if (num_tied > 0) {
    Buffer<uint32_t, System> length(sys, num_tied);
    thrust::transform(policy, tied.data(), tied.data() + num_tied, length.data(),
                      NegatedRunLength{runs.run_begin.data()});
    thrust::sort_by_key(policy, length.data(), length.data() + num_tied, tied.data());
    // Every pair of neighbours in the short runs compared at once (pair index major: see
    // OrderRunNeighbours), then each run checked, and sorted only if out of order.
    const uint32_t longest = std::min(~sys.Read(length.data()), kMaxDeviceRun);
    const uint64_t num_pair_threads = uint64_t{num_tied} * (longest - 1);
    if (num_pair_threads > 0xFFFFFFFFull) {
      throw EngineError(EngineError::Kind::kInternal, "too many tied runs for one launch of neighbour comparisons");
    }
    Buffer<uint8_t, System> verdict(sys, spectrum->num_entries);
    thrust::for_each_n(policy, zero, static_cast<uint32_t>(num_pair_threads),
                       OrderRunNeighbours{mesh.simplex(), tied.data(), num_tied, runs.run_begin.data(),
                                          spectrum->ids.data(), verdict.data()});
    thrust::for_each_n(policy, tied.data(), num_tied,
                       RepairRun{mesh.simplex(), runs.run_begin.data(), run_end, verdict.data(), spectrum->ids.data(),
                                 spectrum->new_value.data(), needs_host.data(), run_comparisons.data()});
  }
  tied.Reset();
  counts->bounded_exact +=
      thrust::reduce(policy, run_comparisons.data(), run_comparisons.data() + num_runs, uint64_t{0});
  uint32_t host_runs =
      static_cast<uint32_t>(thrust::count(policy, needs_host.data(), needs_host.data() + num_runs, uint8_t{1}));
  if (host_runs > 0) host_runs = SettleRunsOfOneDouble(sys, mesh, runs, spectrum, &needs_host, counts);
  runs.link.Reset();
  timer.EndStage("spectrum_repair");
  CheckExactComparisons(*counts, max_exact_comparisons);
  if (host_runs > 0) RepairRunsOnHostOnce(sys, host_mesh, runs, needs_host, spectrum, max_exact_comparisons, counts);
  return runs.num_links;
}

/// Entries whose keys are not certified (extreme exponent ranges inside one simplex): merged into
/// the exact order on the host.
template <class System>
void MergeUncertified(System& sys, HostMesh<System>& host_mesh, const Buffer<uint32_t, System>& odd_ids,
                      uint32_t num_odd, ExactSpectrum<System>* spectrum, uint64_t max_exact_comparisons,
                      ComparisonCounts* counts) {
  std::vector<uint32_t> host_ids = spectrum->ids.ToHostVector(spectrum->num_entries);
  std::vector<uint8_t> host_new = spectrum->new_value.ToHostVector(spectrum->num_entries);
  std::vector<uint32_t> odd = odd_ids.ToHostVector(num_odd);
  if (!MergeUncertifiedOnHost(host_mesh.Get(), odd, ExactComparisonsLeft(*counts, max_exact_comparisons), &host_ids,
                              &host_new, counts)) {
    ThrowExactComparisonLimit(*counts, max_exact_comparisons);
  }
  CheckExactComparisons(*counts, max_exact_comparisons);  // the comparator's last, unreported batch
  const uint32_t total_entries = static_cast<uint32_t>(host_ids.size());
  spectrum->ids = Buffer<uint32_t, System>(sys, total_entries);
  spectrum->new_value = Buffer<uint8_t, System>(sys, total_entries);
  sys.FromHost(spectrum->ids.data(), host_ids.data(), total_entries);
  sys.FromHost(spectrum->new_value.data(), host_new.data(), total_entries);
  spectrum->num_entries = total_entries;
}

/// The exact spectrum from the key order: the runs of entries whose keys may tie are sorted
/// exactly, then the uncertified entries are merged in. Ends the stages "spectrum_refine",
/// "spectrum_repair" and "spectrum_host_repair" (every build lists all three, zero where idle).
template <class System>
ExactSpectrum<System> RepairSpectrum(System& sys, const PipelineMesh& mesh, HostMesh<System>& host_mesh,
                                     SortedSpectrum<System>* sorted, StageTimer<System>& timer,
                                     uint64_t max_exact_comparisons, ComparisonCounts* counts) {
  const uint32_t num_entries = sorted->num_entries;
  ExactSpectrum<System> spectrum{std::move(sorted->ids), Buffer<uint8_t, System>(sys, num_entries), num_entries};
  thrust::fill_n(sys.policy(), spectrum.new_value.data(), num_entries, uint8_t{1});
  uint64_t num_links = 0;
  if (num_entries > 1) {
    num_links =
        RepairTiedRuns(sys, mesh, host_mesh, sorted->sorted_keys, &spectrum, timer, max_exact_comparisons, counts);
  } else {
    timer.EndStage("spectrum_refine");
    timer.EndStage("spectrum_repair");
  }
  counts->filter += num_entries > 0 ? (num_entries - 1) - num_links : 0;
  sorted->sorted_keys.Reset();
  if (sorted->num_odd > 0) {
    MergeUncertified(sys, host_mesh, sorted->odd_ids, sorted->num_odd, &spectrum, max_exact_comparisons, counts);
  }
  sorted->odd_ids.Reset();
  timer.EndStage("spectrum_host_repair");
  return spectrum;
}

/// Ranks: an inclusive scan of the value starts numbers the distinct exact values 1..K. The exact
/// order is not needed after it.
template <class System>
SpectrumRanks<System> RankSpectrum(System& sys, const PipelineMesh& mesh, ExactSpectrum<System>* spectrum) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t total_entries = spectrum->num_entries;
  Buffer<uint32_t, System> rank(sys, total_entries);
  // (Scanned as uint32: Thrust may accumulate in the input's type, and uint8 would wrap.)
  const auto as_u32 = thrust::make_transform_iterator(spectrum->new_value.data(), ToU32{});
  thrust::inclusive_scan(policy, as_u32, as_u32 + total_entries, rank.data());
  const uint32_t num_ranks = total_entries > 0 ? sys.Read(rank.data() + (total_entries - 1)) : 0;
  Buffer<uint32_t, System> tri_rank(sys, mesh.num_tri);
  Buffer<uint32_t, System> edge_rho_rank(sys, mesh.num_edges);
  thrust::fill_n(policy, tri_rank.data(), mesh.num_tri, kNeverRank);  // collinear triangles: never born
  thrust::fill_n(policy, edge_rho_rank.data(), mesh.num_edges, uint32_t{0});
  Buffer<uint32_t, System> spectrum_simplex(sys, num_ranks);
  thrust::fill_n(policy, spectrum_simplex.data(), num_ranks, ~0u);
  thrust::for_each_n(policy, zero, total_entries,
                     ScatterRanks{spectrum->ids.data(), rank.data(), mesh.num_tri, tri_rank.data(),
                                  edge_rho_rank.data(), spectrum_simplex.data()});
  rank.Reset();
  spectrum->ids.Reset();
  spectrum->new_value.Reset();
  return {std::move(tri_rank), std::move(edge_rho_rank), std::move(spectrum_simplex), num_ranks};
}

/// Published spectrum values: the nearest doubles. (Downloaded with the rest at the end, so that
/// this stage's time is the computation's; the rare values the device cannot round are rounded
/// on the host after the download.)
template <class System>
SpectrumValues<System> RoundSpectrumValues(System& sys, const PipelineMesh& mesh, const SpectrumRanks<System>& ranks) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_ranks = ranks.num_ranks;
  SpectrumValues<System> values{Buffer<double, System>(sys, num_ranks), Buffer<uint8_t, System>(sys, num_ranks), false};
  thrust::for_each_n(policy, zero, num_ranks,
                     NearestSpectrumValue{mesh.simplex(), ranks.spectrum_simplex.data(), values.spectrum.data(),
                                          values.needs_host.data()});
  values.any_needs_host =
      thrust::count(policy, values.needs_host.data(), values.needs_host.data() + num_ranks, uint8_t{1}) > 0;
  return values;
}

/// Intervals (report Table 2.1) for edges and vertices; attached edges get edge_rho_rank 0. The
/// keys are not needed after them.
template <class System>
IntervalRanks<System> ComputeIntervals(System& sys, const PipelineMesh& mesh, const Buffer<EdgeTris, System>& edge_tris,
                                       SpectrumRanks<System>* ranks, SimplexKeys<System>* keys) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t n = mesh.n;
  IntervalRanks<System> iv{Buffer<uint32_t, System>(sys, mesh.num_edges), Buffer<uint32_t, System>(sys, mesh.num_edges),
                           Buffer<uint32_t, System>(sys, n), Buffer<uint32_t, System>(sys, n),
                           Buffer<uint32_t, System>(sys, n)};
  thrust::fill_n(policy, iv.vertex_mu_low.data(), n, kNeverRank);
  thrust::fill_n(policy, iv.vertex_mu_high.data(), n, uint32_t{0});
  thrust::fill_n(policy, iv.vertex_tri_low.data(), n, kNeverRank);
  thrust::for_each_n(policy, zero, mesh.num_edges,
                     EdgeIntervals{mesh.edges, edge_tris.data(), ranks->tri_rank.data(), ranks->edge_rho_rank.data(),
                                   iv.edge_mu_low.data(), iv.edge_mu_high.data(), keys->key.data(), mesh.num_tri,
                                   iv.vertex_mu_low.data(), iv.vertex_mu_high.data(), iv.vertex_tri_low.data()});
  // Representatives first (their own values), then duplicates copy them.
  thrust::for_each_n(policy, zero, n,
                     FinishVertexIntervals{mesh.representative, iv.vertex_mu_low.data(), iv.vertex_mu_high.data(),
                                           iv.vertex_tri_low.data()});
  keys->key.Reset();
  return iv;
}

/// The spectrum, the ranks and the intervals are final: they go to the host beside the master
/// list and the component curves (which only read them).
template <class System>
PendingDownloadOf<System> StartTablesDownload(System& sys, const PipelineMesh& mesh,
                                              const Buffer<EdgeTris, System>& edge_tris,
                                              const SpectrumRanks<System>& ranks, const SpectrumValues<System>& values,
                                              const IntervalRanks<System>& iv, AlphaRanks* out) {
  const uint32_t n = mesh.n, num_tri = mesh.num_tri, num_edges = mesh.num_edges, num_ranks = ranks.num_ranks;
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
  return sys.DownloadAsync(
      {{out->spectrum.data(), values.spectrum.data(), size_t{num_ranks} * sizeof(double)},
       {out->spectrum_simplex.data(), ranks.spectrum_simplex.data(), size_t{num_ranks} * sizeof(uint32_t)},
       {out->tri_rank.data(), ranks.tri_rank.data(), size_t{num_tri} * sizeof(uint32_t)},
       {out->edge_rho_rank.data(), ranks.edge_rho_rank.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_mu_low.data(), iv.edge_mu_low.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_mu_high.data(), iv.edge_mu_high.data(), size_t{num_edges} * sizeof(uint32_t)},
       {out->edge_triangles.data(), edge_tris.data(), size_t{num_edges} * sizeof(EdgeTris)},
       {out->vertex_mu_low.data(), iv.vertex_mu_low.data(), size_t{n} * sizeof(uint32_t)},
       {out->vertex_mu_high.data(), iv.vertex_mu_high.data(), size_t{n} * sizeof(uint32_t)},
       {out->vertex_tri_low.data(), iv.vertex_tri_low.data(), size_t{n} * sizeof(uint32_t)}});
}

/// Sorts every rank segment of the master list: short ones by one thread each, long ones (exact
/// ties: a grid's congruent simplices) afterwards.
/// Up to this many long master-list segments are sorted one by one on the device; more are sorted
/// together (SortMasterSegments).
constexpr size_t kMaxSeparateSegmentSorts = 32;

template <class System>
void SortMasterSegments(System& sys, const MasterEndpoints& endpoints, uint32_t num_items, uint32_t num_ranks,
                        uint32_t num_master, const Buffer<uint32_t, System>& master_begin,
                        Buffer<uint64_t, System>* master_entries) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint8_t, System> long_segment(sys, static_cast<size_t>(num_ranks) + 1);
  thrust::for_each_n(policy, zero, num_ranks + 1,
                     SortMasterSegment{master_begin.data(), master_entries->data(), long_segment.data()});
  const auto num_long = static_cast<size_t>(
      thrust::count(policy, long_segment.data(), long_segment.data() + (num_ranks + 1), uint8_t{1}));
  if (num_long == 0) return;
  if constexpr (System::kHostMemory) {
    // One pass over the simplices in order writes the long segments already sorted (items
    // come by kind, then id, each with its end points in order): no sort of exact ties.
    const uint8_t* host_long = long_segment.data();
    std::vector<uint32_t> cursor(master_begin.data(), master_begin.data() + (num_ranks + 1));
    uint64_t* entries = master_entries->data();
    auto place = [&](uint32_t rank, uint64_t packed) {
      if (host_long[rank]) entries[cursor[rank]++] = packed;
    };
    for (uint32_t item = 0; item < num_items; ++item) endpoints.Visit(item, place);
  } else if (num_long <= kMaxSeparateSegmentSorts) {
    const std::vector<uint8_t> host_long = long_segment.ToHostVector(num_ranks + 1);
    const std::vector<uint32_t> host_begin = master_begin.ToHostVector(num_ranks + 2);
    for (uint32_t r = 0; r <= num_ranks; ++r) {
      if (host_long[r]) {
        thrust::sort(policy, master_entries->data() + host_begin[r], master_entries->data() + host_begin[r + 1]);
      }
    }
  } else {
    // Many long segments (lattices: thousands of ranks of exact ties; centimetre LiDAR: 4,786
    // holding a quarter of the list at 1M): one sort per segment would cost a launch and a wait
    // each. The entries of the long segments are gathered (their positions ascend, a segment's
    // contiguous), sorted by (rank, entry), and put back at the same positions: every long segment
    // gets its own entries sorted, the order one sort per segment gives, and the short segments'
    // entries (most of the list) are not sorted again. Below 2^28 ranks (rank, entry) is one
    // 64-bit key, sorted once (entries are unique: a plain sort); beyond, two stable radix sorts,
    // by entry and then by rank (parallel lines at 1M: 3,168 ranks hold the whole list).
    Buffer<uint32_t, System> rank_of(sys, num_master);
    thrust::upper_bound(policy, master_begin.data() + 1, master_begin.data() + (num_ranks + 2), zero, zero + num_master,
                        rank_of.data());
    Buffer<uint32_t, System> position(sys, num_master);
    const auto num_gathered =
        static_cast<uint32_t>(thrust::copy_if(policy, zero, zero + num_master, position.data(),
                                              InLongSegment{rank_of.data(), long_segment.data()}) -
                              position.data());
    if (num_ranks < (uint32_t{1} << (64 - kMasterEntryBits))) {
      Buffer<uint64_t, System> key(sys, num_gathered);
      thrust::transform(policy, position.data(), position.data() + num_gathered, key.data(),
                        RankedMasterKey{rank_of.data(), master_entries->data()});
      rank_of.Reset();
      thrust::sort(policy, key.data(), key.data() + num_gathered);
      const auto sorted_entries = thrust::make_transform_iterator(key.data(), EntryOfRankedKey{});
      thrust::scatter(policy, sorted_entries, sorted_entries + num_gathered, position.data(), master_entries->data());
      return;
    }
    Buffer<uint64_t, System> entry(sys, num_gathered);
    Buffer<uint32_t, System> rank(sys, num_gathered);
    thrust::gather(policy, position.data(), position.data() + num_gathered, master_entries->data(), entry.data());
    thrust::gather(policy, position.data(), position.data() + num_gathered, rank_of.data(), rank.data());
    rank_of.Reset();
    thrust::stable_sort_by_key(policy, entry.data(), entry.data() + num_gathered, rank.data());
    thrust::stable_sort_by_key(policy, rank.data(), rank.data() + num_gathered, entry.data());
    thrust::scatter(policy, entry.data(), entry.data() + num_gathered, position.data(), master_entries->data());
  }
}

/// On the device, with at least this many simplices a rank on average, the master list is built by
/// one sort of (rank, entry) keys (BuildSortedMasterList) instead of per-rank counters and cursors.
/// Measured at 1M on an H200 (bench/README.md, twenty-second session): two crossing lines (3
/// simplices a rank) took 1.0 ms sorted against 2.0-2.5 with the counters, centimetre LiDAR (4.8)
/// 1.1-1.4 against 2.1-2.2, a lattice nudged by ulps (475: sorted at either threshold) 1.1; uniform points (1.5)
/// took 1.2-1.3 ms either way, and keep the counters, which need 36 B a point less at the engine's
/// peak.
constexpr uint32_t kMinItemsPerRankToSortMaster = 2;

/// The master list in CSR form by one sort: every item writes its (rank, entry) keys at its own
/// offset, the keys are sorted, each rank's segment begins at the lower bound of its first key,
/// and the ranks are masked off. The order is the per-rank path's (entries ascending in each
/// segment). Where millions of entries share a few ranks (lattices, quantized coordinates) the
/// per-rank counters' atomics contend: at 1M ulp-nudged lattice points their two passes took
/// 1.4 ms of the H200's 2.8 ms master list, and the long segments' sort another 0.75 ms.
template <class System>
MasterListCsr<System> BuildSortedMasterList(System& sys, const MasterEndpoints& endpoints, uint32_t num_items,
                                            uint32_t num_ranks) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  Buffer<uint32_t, System> offset(sys, static_cast<size_t>(num_items) + 1);
  const auto counts = thrust::make_transform_iterator(zero, MasterEntriesOfItem{endpoints, num_items});
  thrust::exclusive_scan(policy, counts, counts + (num_items + 1), offset.data());
  const uint32_t num_master = sys.Read(offset.data() + num_items);
  Buffer<uint64_t, System> keys(sys, num_master);
  thrust::for_each_n(policy, zero, num_items, WriteRankedMasterKeys{endpoints, offset.data(), keys.data()});
  offset.Reset();
  thrust::sort(policy, keys.data(), keys.data() + num_master);
  Buffer<uint32_t, System> master_begin(sys, static_cast<size_t>(num_ranks) + 2);
  const auto first_keys = thrust::make_transform_iterator(zero, FirstRankedMasterKey{});
  thrust::lower_bound(policy, keys.data(), keys.data() + num_master, first_keys, first_keys + (num_ranks + 2),
                      master_begin.data());
  thrust::transform(policy, keys.data(), keys.data() + num_master, keys.data(), EntryOfRankedKey{});
  return {std::move(master_begin), std::move(keys), num_master};
}

/// Master list in CSR form: count the end points per rank, scan, place each entry in its rank's
/// segment, then sort every segment (O(entries): no global sort). On the device, where ranks are
/// few for the simplices, one sort instead (BuildSortedMasterList).
template <class System>
MasterListCsr<System> BuildMasterList(System& sys, const PipelineMesh& mesh, const SpectrumRanks<System>& ranks,
                                      const IntervalRanks<System>& iv) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_ranks = ranks.num_ranks;
  const MasterEndpoints endpoints{
      mesh.representative,   iv.vertex_mu_low.data(), iv.vertex_mu_high.data(), ranks.edge_rho_rank.data(),
      iv.edge_mu_low.data(), iv.edge_mu_high.data(),  ranks.tri_rank.data(),    mesh.n,
      mesh.num_edges};
  const uint32_t num_items = mesh.n + mesh.num_edges + mesh.num_tri;
  if constexpr (!System::kHostMemory) {
    // Keys hold ranks up to num_ranks + 1 (the end of the last segment's lower bound).
    const bool ranks_fit_key = uint64_t{num_ranks} + 1 < (uint64_t{1} << (64 - kMasterEntryBits));
    if (ranks_fit_key && uint64_t{num_items} >= uint64_t{kMinItemsPerRankToSortMaster} * num_ranks) {
      return BuildSortedMasterList(sys, endpoints, num_items, num_ranks);
    }
  }
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
  SortMasterSegments(sys, endpoints, num_items, num_ranks, num_master, master_begin, &master_entries);
  return {std::move(master_begin), std::move(master_entries), num_master};
}

/// A packed build's sets, for its area curves (PackedAreaCurves): every input index's set, and
/// where each set's scale and error go.
struct PackedAreaSets {
  const uint32_t* input_set;
  uint32_t num_sets;
  std::vector<AreaCurveScale>* set_scales;
};

/// Component and hole curves over all levels (Borůvka spanning forests, component_curve.cuh) and
/// the area curve (area_curve.cuh; a packed build's in each set's scale, `packed`). Given the
/// canonical edge positions, the general forest is also the persistence diagram's primal forest,
/// marked by position in `primal_forest_mark`.
template <class System>
ComponentCounts<System> CountComponents(System& sys, const PipelineMesh& mesh,
                                        const Buffer<EdgeTris, System>& edge_tris, const SpectrumRanks<System>& ranks,
                                        const IntervalRanks<System>& iv, const uint32_t* edge_position = nullptr,
                                        uint8_t* primal_forest_mark = nullptr, const PackedAreaSets* packed = nullptr) {
  const size_t levels = static_cast<size_t>(ranks.num_ranks) + 1;
  ComponentCounts<System> counts{Buffer<uint32_t, System>(sys, levels),
                                 Buffer<uint32_t, System>(sys, levels),
                                 Buffer<uint32_t, System>(sys, levels),
                                 Buffer<uint32_t, System>(sys, levels),
                                 Buffer<uint32_t, System>(sys, levels),
                                 Buffer<unsigned long long, System>(sys, levels),
                                 AreaCurveScale{}};
  TopologyCurves(
      sys,
      TopologyCurvesIn{mesh.n, mesh.num_vertices, mesh.num_tri, mesh.num_edges, ranks.num_ranks, mesh.edges,
                       edge_tris.data(), mesh.representative, ranks.tri_rank.data(), ranks.edge_rho_rank.data(),
                       iv.edge_mu_low.data(), iv.edge_mu_high.data(), iv.vertex_tri_low.data(), edge_position},
      TopologyCurvesOut{counts.components.data(), counts.solid_components.data(), counts.holes.data(),
                        counts.regularized_components.data(), counts.regularized_holes.data(), primal_forest_mark});
  const AreaCurveIn area_in{mesh.points, mesh.tri, ranks.tri_rank.data(), mesh.n, mesh.num_tri, ranks.num_ranks};
  if (packed != nullptr) {
    PackedAreaCurves(sys, area_in, packed->input_set, packed->num_sets, counts.area_units.data(), packed->set_scales);
  } else {
    counts.area_scale = AreaCurve(sys, area_in, counts.area_units.data());
  }
  return counts;
}

/// The rest of the family, then the downloads started earlier (the host arrays are not zeroed
/// first: the copies are their first touch, on every core; core/base/host_vector.hpp), then the
/// values the system could not round.
template <class System>
void FinishDownload(System& sys, const SpectrumRanks<System>& ranks, const SpectrumValues<System>& values,
                    const MasterListCsr<System>& master, const ComponentCounts<System>& counts,
                    PendingDownloadOf<System>* tables_download, HostMesh<System>* host_mesh, AlphaRanks* out) {
  const uint32_t num_ranks = ranks.num_ranks;
  out->components.resize(static_cast<size_t>(num_ranks) + 1);
  out->solid_components.resize(static_cast<size_t>(num_ranks) + 1);
  out->holes.resize(static_cast<size_t>(num_ranks) + 1);
  out->regularized_components.resize(static_cast<size_t>(num_ranks) + 1);
  out->regularized_holes.resize(static_cast<size_t>(num_ranks) + 1);
  out->area_units.resize(static_cast<size_t>(num_ranks) + 1);
  out->area_scale = counts.area_scale;
  out->master_begin.resize(static_cast<size_t>(num_ranks) + 2);
  static_assert(sizeof(MasterEntry) == sizeof(uint64_t), "the packed entries are the list");
  out->master.resize(master.num_master);
  sys.Download(
      {{out->components.data(), counts.components.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
       {out->solid_components.data(), counts.solid_components.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
       {out->holes.data(), counts.holes.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
       {out->regularized_components.data(), counts.regularized_components.data(),
        (size_t{num_ranks} + 1) * sizeof(uint32_t)},
       {out->regularized_holes.data(), counts.regularized_holes.data(), (size_t{num_ranks} + 1) * sizeof(uint32_t)},
       {out->area_units.data(), counts.area_units.data(), (size_t{num_ranks} + 1) * sizeof(uint64_t)},
       {out->master_begin.data(), master.begin.data(), (size_t{num_ranks} + 2) * sizeof(uint32_t)},
       {out->master.data(), master.entries.data(), size_t{master.num_master} * sizeof(uint64_t)}});
  tables_download->Wait();
  const AlphaInput& host_input = host_mesh->Get();
  if (values.any_needs_host) NearestValuesOnHost(host_input, values.needs_host.ToHostVector(num_ranks), out);
}

/// The resident path's end instead of the download (BuildHooks::resident): the final tables move
/// into `resident` where they lie, with the few values the system could not round put right from
/// the host, and the solid level computed there; the mesh's download (which the family keeps on
/// the host) is waited for.
template <class System>
void KeepResidentTables(System& sys, const PipelineMesh& mesh, SystemTriangulation<System>& t,
                        Buffer<EdgeTris, System>& edge_tris, SpectrumRanks<System>& ranks,
                        SpectrumValues<System>& values, IntervalRanks<System>& iv, MasterListCsr<System>& master,
                        ComponentCounts<System>& counts, HostMesh<System>* host_mesh,
                        ResidentTablesOn<System>* resident, AlphaRanks* out) {
  auto policy = sys.policy();
  thrust::counting_iterator<uint32_t> zero(0);
  const uint32_t num_ranks = ranks.num_ranks;
  const AlphaInput& host_input = host_mesh->Get();
  if (values.any_needs_host) {
    AlphaRanks rounded;
    rounded.spectrum.resize(num_ranks);
    rounded.spectrum_simplex.resize(num_ranks);
    sys.Download(
        {{rounded.spectrum.data(), values.spectrum.data(), size_t{num_ranks} * sizeof(double)},
         {rounded.spectrum_simplex.data(), ranks.spectrum_simplex.data(), size_t{num_ranks} * sizeof(uint32_t)}});
    NearestValuesOnHost(host_input, values.needs_host.ToHostVector(num_ranks), &rounded);
    sys.Upload({{rounded.spectrum.data(), values.spectrum.data(), size_t{num_ranks} * sizeof(double)}});
  }
  // AlphaFamily's rule: the largest first-triangle rank over the distinct points that are vertices.
  ResidentSizes sizes{mesh.n, mesh.num_tri, mesh.num_edges, num_ranks, master.num_master, std::nullopt};
  if (mesh.num_tri > 0) {
    const uint32_t worst = thrust::transform_reduce(
        policy, zero, zero + mesh.n, DistinctVertexTriLow{mesh.representative, mesh.hidden, iv.vertex_tri_low.data()},
        0u, thrust::maximum<uint32_t>());
    if (worst != kNeverRank) sizes.solid_level = worst;
  }
  ResidentTableBuffers<System>& kept = resident->tables();
  kept.spectrum = std::move(values.spectrum);
  kept.spectrum_simplex = std::move(ranks.spectrum_simplex);
  kept.tri_rank = std::move(ranks.tri_rank);
  kept.edge_rho_rank = std::move(ranks.edge_rho_rank);
  kept.edge_mu_low = std::move(iv.edge_mu_low);
  kept.edge_mu_high = std::move(iv.edge_mu_high);
  kept.edge_triangles = std::move(edge_tris);
  kept.vertex_mu_low = std::move(iv.vertex_mu_low);
  kept.vertex_mu_high = std::move(iv.vertex_mu_high);
  kept.vertex_tri_low = std::move(iv.vertex_tri_low);
  if (mesh.hidden != nullptr) kept.hidden = std::move(t.hidden);
  kept.master_begin = std::move(master.begin);
  kept.master = std::move(master.entries);
  kept.components = std::move(counts.components);
  kept.solid_components = std::move(counts.solid_components);
  kept.holes = std::move(counts.holes);
  kept.regularized_components = std::move(counts.regularized_components);
  kept.regularized_holes = std::move(counts.regularized_holes);
  kept.area_units = std::move(counts.area_units);
  resident->set_sizes(sizes);
  out->area_scale = counts.area_scale;
  sys.Synchronize();
}

// ---- The pipeline -------------------------------------------------------------------------------------------

/// What the pipeline of one set adds for many: nothing. A packed build of many sets passes its own
/// (packed_family.cuh's SetPacking): the sets' edge runs, the exact order separated by set, the
/// sets' rank runs and their area scales.
struct NoPacking {
  template <class System>
  void AfterMesh(System&, const PipelineMesh&) {}
  template <class System>
  void AfterExactOrder(System&, const PipelineMesh&, ExactSpectrum<System>*, StageTimer<System>&) {}
  template <class System>
  void AfterRanks(System&, const PipelineMesh&, const SpectrumRanks<System>&) {}
  const PackedAreaSets* area_sets() const { return nullptr; }
};

/// Runs the alpha pipeline on the triangulation `t` (in `sys`'s memory, with its points kept) and
/// downloads the family into `out`: triangles, edges, duplicate map and rank tables (or, with
/// `resident`, downloads the mesh and keeps the rank tables there). `host_points` is the same input
/// in host memory (the host's exact repairs read it). One stage a call; the buffers a stage no
/// longer needs are freed by the stage that reads them last. `packing`: a packed build's additions
/// (then without persistence or resident tables).
template <class System, class Packing = NoPacking>
void RunAlphaPipeline(System& sys, SystemTriangulation<System>& t, const Point2* host_points,
                      const double* host_weights, StageTimer<System>& timer, uint64_t max_exact_comparisons,
                      bool persistence, ResidentTablesOn<System>* resident, FamilyOutput* family,
                      Packing packing = {}) {
  AlphaRanks* out = &family->ranks;
  PipelineMesh mesh = PipelineMeshOf(t);
  if (mesh.weights != nullptr) HiddenVertices(sys, t, mesh);
  HostMesh<System> host_mesh = StartMeshDownload(sys, t, mesh, host_points, host_weights, family);
  packing.AfterMesh(sys, mesh);
  Buffer<EdgeTris, System> edge_tris = EdgeTriangles(sys, mesh, &t);
  timer.EndStage("edge_topology");
  SimplexKeys<System> keys = KeySimplices(sys, mesh, edge_tris, host_mesh);
  timer.EndStage("radii_attachment");
  SortedSpectrum<System> sorted = SortSpectrum(sys, mesh, &keys);
  timer.EndStage("spectrum_sort");
  ExactSpectrum<System> exact =
      RepairSpectrum(sys, mesh, host_mesh, &sorted, timer, max_exact_comparisons, &out->comparisons);
  packing.AfterExactOrder(sys, mesh, &exact, timer);
  SpectrumRanks<System> ranks = RankSpectrum(sys, mesh, &exact);
  packing.AfterRanks(sys, mesh, ranks);
  timer.EndStage("ranks");
  SpectrumValues<System> values = RoundSpectrumValues(sys, mesh, ranks);
  timer.EndStage("spectrum_values");
  IntervalRanks<System> intervals = ComputeIntervals(sys, mesh, edge_tris, &ranks, &keys);
  timer.EndStage("intervals");
  // Declared after the buffers it reads: on an early exit it waits for its copies before they go.
  std::optional<PendingDownloadOf<System>> tables_download;
  if (resident == nullptr)
    tables_download.emplace(StartTablesDownload(sys, mesh, edge_tris, ranks, values, intervals, out));
  // The persistence diagram reads the family's arrays where they lie, while the tables download.
  // Its canonical orders come first: with them the curves' general forest is its primal forest.
  const PersistenceIn persistence_in{mesh.n,
                                     mesh.num_edges,
                                     mesh.num_tri,
                                     mesh.edges,
                                     edge_tris.data(),
                                     mesh.tri,
                                     ranks.edge_rho_rank.data(),
                                     intervals.edge_mu_low.data(),
                                     ranks.tri_rank.data(),
                                     mesh.representative,
                                     mesh.hidden};
  std::optional<CanonicalOrders<System>> orders;
  Buffer<uint8_t, System> primal_forest(sys, persistence ? mesh.num_edges : 0);
  if (persistence) {
    orders.emplace(CanonicalOrdersOf(sys, persistence_in));
    timer.EndStage("persistence_orders");
  }
  // The curves before the master list: their forests' working space is the build's largest, and
  // the master list is not yet held beside it.
  ComponentCounts<System> components =
      CountComponents(sys, mesh, edge_tris, ranks, intervals, persistence ? orders->edge_position.data() : nullptr,
                      persistence ? primal_forest.data() : nullptr, packing.area_sets());
  timer.EndStage("components");
  MasterListCsr<System> master = BuildMasterList(sys, mesh, ranks, intervals);
  timer.EndStage("master_list");
  if (persistence) {
    PersistenceOut diagram;
    PersistenceDiagramOnSystem(sys, persistence_in, *orders, primal_forest.data(), /*host_finish=*/true, timer,
                               &diagram);
    family->persistence.pairs = std::move(diagram.pairs);
    family->persistence.dimension_begin[1] = diagram.num_h0;
    family->persistence.dimension_begin[2] = family->persistence.pairs.size();
    family->has_persistence = true;
    orders.reset();
    primal_forest.Reset();
  }
  if (resident != nullptr) {
    KeepResidentTables(sys, mesh, t, edge_tris, ranks, values, intervals, master, components, &host_mesh, resident,
                       out);
    timer.EndStage("keep_resident");
    return;
  }
  FinishDownload(sys, ranks, values, master, components, &*tables_download, &host_mesh, out);
  timer.EndStage("download");
}

/// The whole build on one system: triangulation, then the alpha pipeline on the triangulation
/// where it lies; the family comes back to the host once (partly beside the last stages), or, with
/// `resident` (which owns `sys`), its rank tables stay there.
template <class System>
void RunFamilyBuild(System& sys, const Point2* host_points, const double* host_weights, uint32_t n,
                    const BuildHooks& hooks, FamilyOutput* out, ResidentTablesOn<System>* resident = nullptr) {
  StageTimer<System> timer(sys, &out->stage_times);
  SystemTriangulation<System> t = TriangulateOnSystem(sys, host_points, host_weights, n, /*keep_points=*/true, timer);
  if (hooks.after_triangulation) hooks.after_triangulation();
  RunAlphaPipeline(sys, t, host_points, host_weights, timer, hooks.max_exact_comparisons, hooks.persistence, resident,
                   out);
  timer.Finish();
  out->peak_memory_bytes = sys.peak_bytes();
}

}  // namespace galpha::detail
