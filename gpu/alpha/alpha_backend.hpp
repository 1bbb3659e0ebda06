// The seam between BuildAlphaFamily() and the two backends that run the one templated build
// (triangulation, delaunay_impl.cuh, then the alpha pipeline, alpha_impl.cuh, on the triangulation
// where it lies). Plain C++ and std types only.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/base/host_vector.hpp"
#include "core/base/point.hpp"
#include "core/base/stage_time.hpp"
#include "core/family/alpha_ranks.hpp"
#include "core/family/persistence_pair.hpp"
#include "gpu/alpha/resident_backend.hpp"

namespace galpha::detail {

/// A triangulation in host memory, borrowed: what the host's exact repairs read.
struct AlphaInput {
  const Point2* points = nullptr;
  const std::array<uint32_t, 3>* triangles = nullptr;
  uint32_t num_triangles = 0;  // simplex ids below this are triangles, the rest edges
  const std::array<uint32_t, 2>* edges = nullptr;
  /// Weighted families: the weight of every input point; nullptr when unweighted.
  const double* weights = nullptr;
};

/// What a backend's build hands back; BuildAlphaFamily() moves it into an AlphaFamily.
struct FamilyOutput {
  HostVector<uint32_t> representative;
  uint32_t num_unique = 0;
  HostVector<std::array<uint32_t, 3>> triangles;
  HostVector<std::array<uint32_t, 2>> edges;
  /// Weighted: 1 for every input index whose point is hidden; empty when unweighted.
  HostVector<uint8_t> hidden;
  AlphaRanks ranks;
  std::vector<StageTime> stage_times;
  size_t peak_memory_bytes = 0;
  /// The persistence diagram, when BuildHooks::persistence asked for it.
  bool has_persistence = false;
  PersistenceDiagram persistence;
  /// When BuildHooks::resident asked for it: the rank tables where the build computed them (then
  /// `ranks` holds only the comparison counts and the area scale); the mesh arrays above are on
  /// the host either way.
  std::unique_ptr<ResidentTables> resident;
};

/// Called between the build's phases: after the triangulation, `after_triangulation` runs (it
/// reports progress and may throw EngineError kCancelled to stop the build). A build whose exact
/// radius comparisons pass `max_exact_comparisons` (0: no limit) throws EngineError kWorkLimit.
struct BuildHooks {
  std::function<void()> after_triangulation;
  uint64_t max_exact_comparisons = 0;
  /// Compute the persistence diagram after the component curves.
  bool persistence = false;
  /// Keep the rank tables where they were computed (FamilyOutput::resident) instead of
  /// downloading them; on CUDA the build then runs on a stream the tables own (the `stream`
  /// argument must be null).
  bool resident = false;
};

/// What a packed build of many sets' families hands back (gpu/alpha/packed_family.cuh): one family
/// of all the sets' simplices, named by indices of the whole input (each set's triangles one run,
/// set after set; each set's edges one run; each set's ranks one run, set after set, numbered on
/// from the sets' before it), and where each set's runs lie.
struct PackedFamilyOutput {
  /// The packed family: `ranks.area_units` in each set's own scale (`set_area_scale`), the
  /// comparison counts those of all the sets together.
  FamilyOutput all;
  std::vector<uint32_t> set_triangle_begin;  // num_sets + 1 (all zero when no set has a mesh)
  std::vector<uint32_t> set_edge_begin;      // per set, its edges' run [begin, end)
  std::vector<uint32_t> set_edge_end;
  std::vector<uint32_t> set_rank_begin;  // num_sets + 1: set s's ranks are R + 1..R + K, R = [s]
  std::vector<AreaCurveScale> set_area_scale;
  /// Per set: 1 where its mesh held a flat triangle (DelaunaySetsOutput::build_alone): its part of
  /// `all` is not its family, and the caller builds it alone.
  std::vector<uint8_t> build_alone;
};

/// Builds the families of the `num_sets` sets of the `n` finite points (set s: [set_begin[s],
/// set_begin[s + 1]); n > 0) in one packed build on the OpenMP backend, or on the CUDA backend on
/// `stream`. Unweighted; `hooks.persistence` and `hooks.resident` are not taken. Throws as
/// BuildFamilyOnCpu.
void BuildFamiliesOnCpu(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n,
                        const BuildHooks& hooks, PackedFamilyOutput* out);
void BuildFamiliesOnCuda(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n, void* stream,
                         const BuildHooks& hooks, PackedFamilyOutput* out);

/// Builds the family of `n` finite points (with `weights`, one per point, or nullptr for the
/// unweighted family) on the OpenMP backend. Throws EngineError (or a Thrust/std exception) on
/// failure.
void BuildFamilyOnCpu(const Point2* points, const double* weights, uint32_t n, const BuildHooks& hooks,
                      FamilyOutput* out);

/// The same on the CUDA backend, on `stream` (a cudaStream_t, or nullptr for one of its own).
void BuildFamilyOnCuda(const Point2* points, const double* weights, uint32_t n, void* stream, const BuildHooks& hooks,
                       FamilyOutput* out);

}  // namespace galpha::detail
