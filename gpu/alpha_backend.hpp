// The seam between BuildAlphaFamily() and the two backends that run the one templated alpha
// pipeline (alpha_impl.cuh) after the triangulation. Plain C++ and std types only.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/alpha_ranks.hpp"
#include "core/point.hpp"
#include "core/stage_time.hpp"

namespace galpha::detail {

/// A triangulation as the alpha pipeline reads it (host memory, borrowed).
struct AlphaInput {
  const Point2* points = nullptr;
  uint32_t num_points = 0;
  uint32_t num_unique = 0;                         // distinct points
  const uint32_t* representative = nullptr;       // num_points
  const std::array<uint32_t, 3>* triangles = nullptr;
  const std::array<int32_t, 3>* neighbors = nullptr;
  const uint32_t* tri_edge_begin = nullptr;
  uint32_t num_triangles = 0;
  const std::array<uint32_t, 2>* edges = nullptr;
  uint32_t num_edges = 0;
};

/// Runs the alpha pipeline on the OpenMP backend; fills everything in `out` but the triangulation.
void BuildAlphaOnCpu(const AlphaInput& in, AlphaRanks* out, std::vector<StageTime>* stage_times,
                     size_t* peak_bytes);

/// The same on the CUDA backend, on `stream` (a cudaStream_t, or nullptr for one of its own).
void BuildAlphaOnCuda(const AlphaInput& in, void* stream, AlphaRanks* out,
                      std::vector<StageTime>* stage_times, size_t* peak_bytes);

}  // namespace galpha::detail
