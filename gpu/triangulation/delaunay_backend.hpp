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

/// Runs the triangulation on the OpenMP backend. `points` holds `n` finite points; `weights`, when
/// not null, `n` weights (a regular triangulation). Throws EngineError (or a Thrust/std exception)
/// on failure.
void TriangulateOnCpu(const Point2* points, const double* weights, uint32_t n, DelaunayOutput* out);

/// Runs the triangulation on the CUDA backend on `stream` (a cudaStream_t, or nullptr for a stream
/// of the engine's own). Only defined in CUDA builds.
void TriangulateOnCuda(const Point2* points, const double* weights, uint32_t n, void* stream, DelaunayOutput* out);

}  // namespace galpha::detail
