// GEOS through its reentrant C API, as the independent geometry oracle of the shape tests: one
// context per object, geometries owned by unique_ptr, WKT read back, the union of triangles built
// from their coordinates (not through our writers).
#pragma once

#include <geos_c.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"

namespace galpha::testing {

class Geos {
 public:
  struct Deleter {
    GEOSContextHandle_t ctx;
    void operator()(GEOSGeometry* g) const { GEOSGeom_destroy_r(ctx, g); }
  };
  using Geom = std::unique_ptr<GEOSGeometry, Deleter>;

  Geos();
  ~Geos();
  Geos(const Geos&) = delete;
  Geos& operator=(const Geos&) = delete;

  GEOSContextHandle_t ctx() const { return ctx_; }
  Geom Own(GEOSGeometry* g) const { return Geom(g, Deleter{ctx_}); }

  /// The geometry of `wkt`; null when GEOS cannot parse it.
  Geom ReadWkt(const std::string& wkt) const;

  /// GEOS's own union of the triangles, each built from its coordinates.
  Geom UnionOfTriangles(absl::Span<const Point2> points, const std::vector<std::array<uint32_t, 3>>& tris) const;

  /// Why GEOS finds `g` invalid ("Valid Geometry" when it is valid).
  std::string ValidReason(const GEOSGeometry* g) const;

  /// Whether the ring is counter-clockwise, by GEOS's own robust test.
  bool IsCcw(const GEOSGeometry* ring) const;

 private:
  GEOSContextHandle_t ctx_;
};

}  // namespace galpha::testing
