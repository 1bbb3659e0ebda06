// A family as the service holds it, in host memory (AlphaFamily) or resident where it was built
// (ResidentAlphaFamily: its rank tables in device memory after a CUDA build), read through one
// interface (server/family_reader.hpp; the report is the build summary a Describe returns), and
// the index orders Classify streams in and the triangles' area terms its summary adds (each computed
// on first use, once). No
// name: a BuildHeader.name is the label of one Build call, echoed in that call's answer only
// (proto: BuildHeader), so the family that any caller of the tenant may reach keeps none.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "core/family/alpha_family.hpp"
#include "core/io/coordinate_system.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gpu/alpha/resident_family.hpp"
#include "server/family_reader.hpp"

namespace galpha::server {

class CachedFamily {
 public:
  struct InputFrame;
  /// `frame`: where the points came from when the Build header named a CRS (may be null); its
  /// input points are charged to the family's bytes.
  explicit CachedFamily(AlphaFamily family, std::shared_ptr<const InputFrame> frame = nullptr);
  /// A resident family: `bytes()` charges its host arrays and tables held in host memory,
  /// `device_bytes()` its tables in device memory.
  explicit CachedFamily(ResidentAlphaFamily family, std::shared_ptr<const InputFrame> frame = nullptr);

  /// Either form, read the same way.
  const FamilyReader& reader() const { return *reader_; }
  /// The family when it is held in host memory; null when it is resident (reader().HostFamily()
  /// downloads one).
  const AlphaFamily* host_family() const { return host_.get(); }
  /// Whether the family is resident where it was built, and whether that is device memory.
  bool resident() const { return host_ == nullptr; }

  /// Where the family's points came from when a Build header named a CRS: the CRS, the points as
  /// sent (for a geographic CRS; empty when the family's points are the points as sent), and the
  /// local projection. Text geometry is written in these coordinates.
  struct InputFrame {
    CrsInfo crs;
    std::vector<Point2> input;
    std::string projection;
  };
  /// The frame attached to the family, if any (set once: by its first build with a CRS, which
  /// may be a cache hit on a family built from the same projected points without one; such a
  /// late frame is not charged to the cache).
  std::shared_ptr<const InputFrame> Frame() const;
  void AttachFrameIfNone(std::shared_ptr<const InputFrame> frame) const;
  /// Host bytes charged to the cache: the family (of a resident one, what it holds on the host,
  /// and its tables when the host is where they live), plus the index orders, ordered vertices and
  /// area terms once computed (charged up front so that the charge never changes while cached).
  size_t bytes() const { return bytes_; }
  /// Device bytes a resident family's tables hold (0 in host memory or on the CPU backend).
  size_t device_bytes() const { return device_bytes_; }

  /// Edge ids sorted by their (smaller, larger) vertex pair; triangle ids by sorted vertex triple.
  const std::vector<uint32_t>& EdgeOrder() const;
  const std::vector<uint32_t>& TriangleOrder() const;
  /// The vertices of the edges (pairs) and triangles (ascending triples) in those orders, flat: so
  /// that Classify copies index runs instead of gathering them one simplex at a time.
  const std::vector<uint32_t>& EdgeVerticesInOrder() const;
  const std::vector<uint32_t>& TriangleVerticesInOrder() const;
  /// Each triangle's term of the interior area (core/family/classification_summary.hpp), so that a
  /// Classify summary adds them in order instead of reading three points at random per triangle.
  const std::vector<double>& TriangleAreaTerms() const;

  /// reader().ClassifyAll(level, mode, rule), shared by the calls that ask for the same one while
  /// any of them still holds it: the parts of one Classify answer read over several calls at once
  /// (ClassifyRequest.part_count) classify the family once, not once a part. Computed by the first
  /// caller; the others wait for it. An error is not kept: the next caller tries again.
  absl::StatusOr<std::shared_ptr<const Classification>> SharedClassification(int64_t level, ClassifyMode mode,
                                                                             VertexRule rule) const;

 private:
  void ComputeOrders() const;

  /// One classification, computed once by whichever of its callers comes first.
  struct PendingClassification {
    std::once_flag once;
    absl::StatusOr<Classification> classes;
  };
  using ClassificationKey = std::tuple<int64_t, ClassifyMode, VertexRule>;

  std::shared_ptr<const AlphaFamily> host_;
  std::shared_ptr<const ResidentAlphaFamily> resident_;
  std::unique_ptr<FamilyReader> reader_;
  size_t bytes_ = 0;
  size_t device_bytes_ = 0;
  mutable absl::Mutex frame_mutex_;
  mutable std::shared_ptr<const InputFrame> frame_ ABSL_GUARDED_BY(frame_mutex_);
  mutable std::once_flag orders_once_;
  mutable std::vector<uint32_t> edge_order_, triangle_order_;
  mutable std::vector<uint32_t> edge_vertices_, triangle_vertices_;
  mutable std::once_flag area_terms_once_;
  mutable std::vector<double> triangle_area_terms_;
  mutable absl::Mutex shared_mutex_;
  // Expired entries are dropped on the next lookup: at most a few keys are ever in use at once.
  mutable std::map<ClassificationKey, std::weak_ptr<PendingClassification>> shared_classifications_
      ABSL_GUARDED_BY(shared_mutex_);
};

/// `family` as the cache shares it: its last owner (the cache, or a query still streaming from it
/// after a release, demotion or eviction) frees hundreds of megabytes, and asks for them to go back
/// to the system (server/heap_trim.hpp: soon, on the trimmer's thread).
std::shared_ptr<const CachedFamily> ShareCachedFamily(AlphaFamily family,
                                                      std::shared_ptr<const CachedFamily::InputFrame> frame);
std::shared_ptr<const CachedFamily> ShareCachedFamily(ResidentAlphaFamily family,
                                                      std::shared_ptr<const CachedFamily::InputFrame> frame);

/// Builds the family of `points` (`weighted`: with `weights`, one per point) in the form the
/// service caches: resident where it is built when `resident` (its tables stay in the build's
/// memory: GPU memory on CUDA, on its own stream, so `options.cuda_stream` is not used), else in
/// host memory. The engine's errors as they are.
absl::StatusOr<std::shared_ptr<const CachedFamily>> BuildCachedFamily(
    absl::Span<const Point2> points, absl::Span<const double> weights, bool weighted, BuildOptions options,
    bool resident, std::shared_ptr<const CachedFamily::InputFrame> frame);

}  // namespace galpha::server
