// What the service's answers read of a cached family, in either of its forms: in host memory
// (AlphaFamily) or resident where it was built (ResidentAlphaFamily, gpu/alpha/resident_family.hpp:
// the rank tables in device memory after a CUDA build, in the OpenMP build's own buffers on the
// CPU). The answers (query_answers.cpp) are written once against this interface; a resident
// family computes them where its tables live and only the answers come back.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "core/family/persistence_pair.hpp"
#include "core/family/threshold.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/resident_family.hpp"

namespace galpha::server {

class FamilyReader {
 public:
  virtual ~FamilyReader() = default;

  // The host arrays, which both forms hold.
  virtual const HostVector<Point2>& points() const = 0;
  virtual const HostVector<double>& weights() const = 0;
  virtual const HostVector<uint32_t>& representative() const = 0;
  virtual uint32_t num_unique() const = 0;
  virtual const HostVector<std::array<uint32_t, 3>>& triangles() const = 0;
  virtual const HostVector<std::array<uint32_t, 2>>& edges() const = 0;
  /// Per input index, 1 for a hidden point (empty when unweighted).
  virtual const HostVector<uint8_t>& hidden_flags() const = 0;
  virtual bool weighted() const = 0;
  virtual const BuildReport& report() const = 0;
  virtual int64_t max_level() const = 0;

  // The rank tables' answers (AlphaFamily's, by the same names).
  virtual absl::StatusOr<ResolvedThreshold> Resolve(const Threshold& threshold) const = 0;
  virtual absl::StatusOr<int64_t> RankLowerBound(double alpha_sq) const = 0;
  virtual absl::StatusOr<Classification> ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const = 0;
  /// AssembleShape(AlphaFamily::ComplexAt(level, mode)); a resident family's found where its
  /// tables live, the same ShapeGeometry (ResidentAlphaFamily::ShapeAt).
  virtual absl::StatusOr<ShapeGeometry> ShapeAt(int64_t level, ClassifyMode mode) const = 0;
  virtual absl::StatusOr<std::vector<TopologyAtLevel>> TopologyBetween(int64_t first, int64_t last) const = 0;
  virtual absl::StatusOr<double> HullAreaApprox() const = 0;
  virtual absl::StatusOr<double> PublishedAlphaSq(int64_t level) const = 0;
  virtual absl::StatusOr<std::optional<int64_t>> OptimalLevelRegularized(uint32_t n,
                                                                         std::optional<uint32_t> max_holes) const = 0;
  virtual absl::StatusOr<std::optional<int64_t>> OptimalLevelGeneral(uint32_t n,
                                                                     std::optional<uint32_t> max_holes) const = 0;
  /// spectrum[first_index, first_index + count), clipped to 0..K-1.
  virtual absl::StatusOr<std::vector<double>> Spectrum(int64_t first_index, int64_t count) const = 0;
  /// master_begin[first_rank, first_rank + count) and master[position, position + count).
  virtual absl::StatusOr<std::vector<uint32_t>> MasterBegins(int64_t first_rank, int64_t count) const = 0;
  virtual absl::StatusOr<std::vector<MasterEntry>> MasterEntries(uint64_t position, uint64_t count) const = 0;

  /// The persistence diagram: PersistenceDiagramOf (gpu/alpha/persistence_engine.hpp; the
  /// canonical orders the cache keeps, when given) for a family in host memory, computed where the
  /// tables live for a resident one (ResidentAlphaFamily::Persistence). The same diagram.
  virtual absl::StatusOr<PersistenceDiagram> Persistence(absl::Span<const uint32_t> edge_order,
                                                         absl::Span<const uint32_t> triangle_order) const = 0;

  /// The family in host memory, for answers a resident family does not compute where it lives:
  /// the family itself, or for a resident one its tables downloaded for this call (freed with the
  /// returned pointer).
  virtual absl::StatusOr<std::shared_ptr<const AlphaFamily>> HostFamily() const = 0;
};

/// The host arrays both forms hold, by the same names: read from the family of type `Family`.
template <class Family>
class FamilyReaderOf : public FamilyReader {
 public:
  explicit FamilyReaderOf(std::shared_ptr<const Family> family) : family_(std::move(family)) {}

  const HostVector<Point2>& points() const override { return family_->points(); }
  const HostVector<double>& weights() const override { return family_->weights(); }
  const HostVector<uint32_t>& representative() const override { return family_->representative(); }
  uint32_t num_unique() const override { return family_->num_unique(); }
  const HostVector<std::array<uint32_t, 3>>& triangles() const override { return family_->triangles(); }
  const HostVector<std::array<uint32_t, 2>>& edges() const override { return family_->edges(); }
  const HostVector<uint8_t>& hidden_flags() const override { return family_->hidden_flags(); }
  bool weighted() const override { return family_->weighted(); }
  const BuildReport& report() const override { return family_->report(); }
  int64_t max_level() const override { return family_->max_level(); }

 protected:
  std::shared_ptr<const Family> family_;
};

/// A family in host memory.
class HostFamilyReader final : public FamilyReaderOf<AlphaFamily> {
 public:
  using FamilyReaderOf::FamilyReaderOf;

  absl::StatusOr<ResolvedThreshold> Resolve(const Threshold& threshold) const override;
  absl::StatusOr<int64_t> RankLowerBound(double alpha_sq) const override;
  absl::StatusOr<Classification> ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const override;
  absl::StatusOr<ShapeGeometry> ShapeAt(int64_t level, ClassifyMode mode) const override {
    return AssembleShape(family_->ComplexAt(level, mode));
  }
  absl::StatusOr<std::vector<TopologyAtLevel>> TopologyBetween(int64_t first, int64_t last) const override;
  absl::StatusOr<double> HullAreaApprox() const override;
  absl::StatusOr<double> PublishedAlphaSq(int64_t level) const override;
  absl::StatusOr<std::optional<int64_t>> OptimalLevelRegularized(uint32_t n,
                                                                 std::optional<uint32_t> max_holes) const override;
  absl::StatusOr<std::optional<int64_t>> OptimalLevelGeneral(uint32_t n,
                                                             std::optional<uint32_t> max_holes) const override;
  absl::StatusOr<std::vector<double>> Spectrum(int64_t first_index, int64_t count) const override;
  absl::StatusOr<std::vector<uint32_t>> MasterBegins(int64_t first_rank, int64_t count) const override;
  absl::StatusOr<std::vector<MasterEntry>> MasterEntries(uint64_t position, uint64_t count) const override;
  absl::StatusOr<PersistenceDiagram> Persistence(absl::Span<const uint32_t> edge_order,
                                                 absl::Span<const uint32_t> triangle_order) const override;
  absl::StatusOr<std::shared_ptr<const AlphaFamily>> HostFamily() const override { return family_; }
};

/// A resident family.
class ResidentFamilyReader final : public FamilyReaderOf<ResidentAlphaFamily> {
 public:
  using FamilyReaderOf::FamilyReaderOf;

  absl::StatusOr<ResolvedThreshold> Resolve(const Threshold& threshold) const override;
  absl::StatusOr<int64_t> RankLowerBound(double alpha_sq) const override { return family_->RankLowerBound(alpha_sq); }
  absl::StatusOr<Classification> ClassifyAll(int64_t level, ClassifyMode mode, VertexRule rule) const override {
    return family_->ClassifyAll(level, mode, rule);
  }
  absl::StatusOr<ShapeGeometry> ShapeAt(int64_t level, ClassifyMode mode) const override {
    return family_->ShapeAt(level, mode);
  }
  absl::StatusOr<std::vector<TopologyAtLevel>> TopologyBetween(int64_t first, int64_t last) const override {
    return family_->TopologyBetween(first, last);
  }
  absl::StatusOr<double> HullAreaApprox() const override {
    return family_->RegularizedAreaApprox(family_->max_level());
  }
  absl::StatusOr<double> PublishedAlphaSq(int64_t level) const override { return family_->PublishedAlphaSq(level); }
  absl::StatusOr<std::optional<int64_t>> OptimalLevelRegularized(uint32_t n,
                                                                 std::optional<uint32_t> max_holes) const override {
    return family_->OptimalLevelRegularized(n, max_holes);
  }
  absl::StatusOr<std::optional<int64_t>> OptimalLevelGeneral(uint32_t n,
                                                             std::optional<uint32_t> max_holes) const override {
    return family_->OptimalLevelGeneral(n, max_holes);
  }
  absl::StatusOr<std::vector<double>> Spectrum(int64_t first_index, int64_t count) const override {
    return family_->Spectrum(first_index, count);
  }
  absl::StatusOr<std::vector<uint32_t>> MasterBegins(int64_t first_rank, int64_t count) const override {
    return family_->MasterBegins(first_rank, count);
  }
  absl::StatusOr<std::vector<MasterEntry>> MasterEntries(uint64_t position, uint64_t count) const override {
    return family_->MasterEntries(position, count);
  }
  absl::StatusOr<PersistenceDiagram> Persistence(absl::Span<const uint32_t> edge_order,
                                                 absl::Span<const uint32_t> triangle_order) const override;
  absl::StatusOr<std::shared_ptr<const AlphaFamily>> HostFamily() const override;
};

}  // namespace galpha::server
