// Public, CUDA-free interface of the Delaunay triangulation engine.
//
// The algorithm is gDel2D's (Qi, Cao, Tan): points sorted along a Hilbert curve are inserted in
// rounds (each triangle takes the uninserted point nearest its circumcentre), the Delaunay property
// is restored with parallel Lawson flips whose conflicts are resolved by voting, and uninserted
// points are relocated by a visibility walk. The convex hull is handled symbolically with a vertex
// at infinity; all predicates are exact with Simulation of Simplicity on input indices. The same
// source runs on the CUDA backend (one stream) and on the OpenMP backend.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/base/stage_time.hpp"
#include "gpu/system/backend.hpp"

namespace galpha {

struct TriangulateOptions {
  Backend backend = Backend::kAuto;
  /// CUDA stream (a cudaStream_t) to run on; nullptr uses a stream the engine creates. Ignored on
  /// the CPU backend.
  void* cuda_stream = nullptr;
};

/// The Delaunay triangulation of a point set, named by input indices.
///
/// Vertices are input indices; an input point that duplicates an earlier one is represented by the
/// first occurrence (see `representative`). Triangles are counter-clockwise. The edge list follows
/// the ownership rule of the report "Computing 2D Alpha Shapes Using GPU" (section 3.1): triangle t
/// owns its local edge k (from vertex k to vertex k+1) when the vertex indices increase along it or
/// when it is a hull edge; edges are laid out triangle by triangle in the order of an exclusive scan
/// of the owned counts.
struct Triangulation {
  /// Input points exactly as given (duplicates included).
  std::vector<Point2> points;
  /// For every input index, the input index of its first occurrence (itself when not a duplicate).
  std::vector<uint32_t> representative;
  /// Number of distinct points (weighted: distinct in position and weight).
  uint32_t num_unique = 0;
  /// Weighted (TriangulateWeighted): the input indices, ascending, of the points that are not
  /// vertices of the regular triangulation (their lifted point lies above the lower hull of the
  /// lifts, or on it where the tie rule hides it; at one position only the heaviest point can be
  /// a vertex). Empty for Triangulate.
  std::vector<uint32_t> hidden;

  /// Finite triangles: three input indices, counter-clockwise.
  std::vector<std::array<uint32_t, 3>> triangles;
  /// neighbors[t][k]: the triangle across the edge opposite vertex k, or kNoNeighbor on the hull.
  std::vector<std::array<int32_t, 3>> neighbors;
  /// First owned edge of each triangle in `edges` (exclusive scan of owned counts).
  std::vector<uint32_t> tri_edge_begin;
  /// Edges as (smaller input index, larger input index).
  std::vector<std::array<uint32_t, 2>> edges;

  /// Backend that ran, and the stage times (transfers are their own stages).
  Backend backend = Backend::kCpu;
  std::vector<StageTime> stage_times;
  /// Peak working memory of the build on its backend (device memory on CUDA, host memory on the
  /// CPU backend), in bytes: the engine's buffers and its algorithms' temporaries, input included,
  /// the returned host vectors excluded.
  size_t peak_memory_bytes = 0;

  static constexpr int32_t kNoNeighbor = -1;
};

/// Triangulates `points`.
///
/// Errors: InvalidArgument naming the first index holding NaN or infinity; ResourceExhausted when
/// there are more points than a 32-bit index allows; Unavailable when the CUDA backend is asked for
/// and there is none; Internal when a device call fails. 0, 1 or 2 distinct points and collinear
/// input are valid: no triangles, and the edges join the points in sorted order along their line.
absl::StatusOr<Triangulation> Triangulate(absl::Span<const Point2> points, const TriangulateOptions& options = {});

/// The regular (weighted Delaunay) triangulation of the points with `weights` (one per point: the
/// squared radius of a disk centred at it; negative values are valid, as in CGAL): the projection
/// of the lower convex hull of the lifted points (x, y, x^2 + y^2 - w). Same algorithm and output as
/// Triangulate, with the power test in place of the in-circle test, the points it hides listed in
/// `hidden`, and exact ties broken as CGAL's Regular_triangulation_2 breaks them where its first
/// perturbation term decides (core/exact/power.hpp). Points at one position with one weight are
/// duplicates (represented by the first); with different weights only the heaviest (the first of
/// them) can be a vertex. Collinear input gives the chain of the points that are not hidden.
///
/// Errors: Triangulate's, and InvalidArgument for weights outside the input domain
/// (ValidateWeights in core/io/input_validation.hpp, naming the first bad index).
absl::StatusOr<Triangulation> TriangulateWeighted(absl::Span<const Point2> points, absl::Span<const double> weights,
                                                  const TriangulateOptions& options = {});

/// The most sets one TriangulateSets call takes (its Hilbert keys keep a set's id above 42 bits).
inline constexpr uint32_t kMaxTriangulatedSets = 1u << 22;

/// Many point sets triangulated together (TriangulateSets).
struct TriangulatedSets {
  /// One triangulation a set, in the sets' order, each equal to Triangulate's of the set alone on
  /// the same backend (its indices are the set's own, from 0); their stage times are empty and their
  /// peak memory 0: the build's are below.
  std::vector<Triangulation> sets;
  Backend backend = Backend::kCpu;
  std::vector<StageTime> stage_times;
  size_t peak_memory_bytes = 0;
  /// Sets built alone after the packed build, with their own launches (a mesh with a flat
  /// triangle after insertion; none measured).
  uint32_t built_alone = 0;
};

/// Triangulates many point sets in one build: set s is points[set_begin[s], set_begin[s + 1]), with
/// set_begin running from 0 to points.size() (set_begin.size() - 1 sets, empty ones allowed). The
/// sets are packed into one mesh's arrays and built by the same launches (not one build a set):
/// thousands of small sets take about what one build of all their points takes.
///
/// Errors: Triangulate's for each set, its message prefixed by the set ("set 2: point 2 is not
/// finite..."; the point's index is the set's own); ResourceExhausted for more than 2^30 points in
/// all (one build's limit); InvalidArgument for offsets that do not run from 0 to points.size()
/// without decreasing, or more than kMaxTriangulatedSets sets.
absl::StatusOr<TriangulatedSets> TriangulateSets(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin,
                                                 const TriangulateOptions& options = {});

/// TriangulateSets' checks of its input (its errors, above), for the other builds of many sets
/// (BuildAlphaFamilies).
absl::Status ValidatePointSets(absl::Span<const Point2> points, absl::Span<const uint32_t> set_begin);

}  // namespace galpha
