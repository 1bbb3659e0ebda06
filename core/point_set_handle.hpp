// Content-derived handles of point sets (DESIGN.md section 4): the SHA-256 of the points as a client
// sends them, so that equal inputs get equal handles on every replica and the client can compute a
// handle before uploading anything. The server caches a family under its handle; the client
// library asks for the handle first and skips the upload when the server already holds it.
//
// The digest covers a domain tag and the coordinates as little-endian IEEE doubles in input order
// (x0, y0, x1, y1, ...). Order and duplicates matter because answers name points by input index.
// Every option that changes a family would be part of the digest; today none does (both backends
// give the same family, which the identity test checks).
#pragma once

#include <memory>
#include <string>

#include "absl/types/span.h"
#include "core/point.hpp"

namespace galpha {

/// Incremental SHA-256 of a point stream, chunk by chunk.
class PointSetHasher {
 public:
  PointSetHasher();
  ~PointSetHasher();
  PointSetHasher(const PointSetHasher&) = delete;
  PointSetHasher& operator=(const PointSetHasher&) = delete;

  /// Adds coordinates x0, y0, x1, y1, ... (the split into chunks does not change the digest).
  void AddCoordinates(absl::Span<const double> coordinates);
  void AddPoints(absl::Span<const Point2> points);
  /// "sha256-" and 64 lowercase hex digits. The hasher cannot be used afterwards.
  std::string Finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The handle of a whole point set.
std::string PointSetHandle(absl::Span<const Point2> points);

/// Whether `handle` has the form PointSetHandle produces ("sha256-" + 64 lowercase hex digits).
bool IsWellFormedHandle(const std::string& handle);

}  // namespace galpha
