// The seam between the public Triangulate() and the two backends that run the one templated
// implementation (delaunay_impl.cuh). Plain C++ and std types only: no CUDA, no Abseil, so that the
// CUDA translation unit never parses Abseil headers.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/point.hpp"
#include "core/base/stage_time.hpp"
#include "gpu/system/backend.hpp"

namespace galpha::detail {

/// What a backend hands back; Triangulate() moves it into a galpha::Triangulation.
struct DelaunayOutput {
  std::vector<uint32_t> representative;
  uint32_t num_unique = 0;
  std::vector<uint32_t> hidden;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<std::array<int32_t, 3>> neighbors;
  std::vector<uint32_t> tri_edge_begin;
  std::vector<std::array<uint32_t, 2>> edges;
  std::vector<StageTime> stage_times;
  size_t peak_memory_bytes = 0;
};

/// What a packed build of many sets hands back (delaunay_batch.cuh), named by indices of the whole
/// input: a one-set build's output for all the sets with a mesh together (each set's triangles one
/// run, set after set, in the order of a build of that set alone, neighbours by position in the
/// whole list, edges laid out from the triangles; representatives for every input index), and the
/// chains of the sets on one line.
struct DelaunaySetsOutput {
  DelaunayOutput meshes;
  /// Where each set's run of triangles starts in `meshes.triangles` (num_sets + 1 entries; empty
  /// when no set has a mesh).
  std::vector<uint32_t> set_triangle_begin;
  /// The chains of the sets on one line, set after set, each in a one-set build's order.
  std::vector<std::array<uint32_t, 2>> chain_edges;
  /// Per set: 1 where its mesh held a flat triangle; its part of `meshes` is then not its
  /// triangulation, and the caller builds it alone.
  std::vector<uint8_t> build_alone;
};

/// Runs the triangulation on the OpenMP backend. `points` holds `n` finite points; `weights`, when
/// not null, `n` weights (a regular triangulation). Throws EngineError (or a Thrust/std exception)
/// on failure.
void TriangulateOnCpu(const Point2* points, const double* weights, uint32_t n, DelaunayOutput* out);

/// Runs the triangulation on the CUDA backend on `stream` (a cudaStream_t, or nullptr for a stream
/// of the engine's own). Only defined in CUDA builds.
void TriangulateOnCuda(const Point2* points, const double* weights, uint32_t n, void* stream, DelaunayOutput* out);

/// Runs the packed build of `num_sets` sets of the `n` points (set s: [set_begin[s],
/// set_begin[s + 1]); n > 0) on the OpenMP backend, or on the CUDA backend on `stream` (only
/// defined in CUDA builds). Unweighted.
void TriangulateSetsOnCpu(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n,
                          DelaunaySetsOutput* out);
void TriangulateSetsOnCuda(const Point2* points, const uint32_t* set_begin, uint32_t num_sets, uint32_t n, void* stream,
                           DelaunaySetsOutput* out);

}  // namespace galpha::detail
