// Content-derived handles of point sets (docs/design.md, "Formats"): a SHA-256 tree over the points as a
// client sends them, so that equal inputs get equal handles on every replica and the client can
// compute a handle before uploading anything (to skip the upload when the server holds the family,
// and to route the stream to the replica that would hold it).
//
// The digest: the coordinates as little-endian IEEE doubles in input order (x0, y0, x1, y1, ...)
// are cut into leaves of kHandleLeafBytes (the last one shorter; none for no points). Leaf i's
// digest is SHA-256 of a zero byte and the leaf's bytes; the handle is "sha256-" and the hex of
// SHA-256 of the tag "galpha.v2.points" (with its NUL), the number of bytes as a little-endian
// uint64, and the leaf digests in order. The leaves are hashed in parallel: one SHA-256 over 16 MB
// (1M points) takes ~10 ms on one core, and both the client and the server hash every build.
// Order and duplicates matter because answers name points by input index. Every option that
// changes a family would be part of the digest; today none does (both backends give the same
// family, which the identity test checks).
#pragma once

#include <cstddef>
#include <string>

#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha {

/// Bytes of coordinates per leaf of the handle's hash tree.
inline constexpr size_t kHandleLeafBytes = size_t{1} << 20;

/// The handle of a whole point set: "sha256-" and 64 lowercase hex digits.
std::string PointSetHandle(absl::Span<const Point2> points);

/// The handle of a weighted point set (a weighted family, issue 18): the same tree over the
/// triples (x0, y0, w0, x1, y1, w1, ...) under the tag "galpha.v2.weighted-points", so that it
/// covers the weights and never equals an unweighted handle. `weights` holds one per point.
std::string WeightedPointSetHandle(absl::Span<const Point2> points, absl::Span<const double> weights);

/// Whether `handle` has the form PointSetHandle produces ("sha256-" + 64 lowercase hex digits).
bool IsWellFormedHandle(const std::string& handle);

}  // namespace galpha
