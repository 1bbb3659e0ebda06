// The GEOS wrapper of geos.hpp.
#include "tests/support/geos.hpp"

#include <geos_c.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace galpha::testing {

Geos::Geos() : ctx_(GEOS_init_r()) {}

Geos::~Geos() { GEOS_finish_r(ctx_); }

Geos::Geom Geos::ReadWkt(const std::string& wkt) const {
  GEOSWKTReader* reader = GEOSWKTReader_create_r(ctx_);
  GEOSGeometry* g = GEOSWKTReader_read_r(ctx_, reader, wkt.c_str());
  GEOSWKTReader_destroy_r(ctx_, reader);
  return Own(g);
}

Geos::Geom Geos::UnionOfTriangles(absl::Span<const Point2> points,
                                  const std::vector<std::array<uint32_t, 3>>& tris) const {
  std::vector<GEOSGeometry*> polygons;
  for (const std::array<uint32_t, 3>& t : tris) {
    GEOSCoordSequence* seq = GEOSCoordSeq_create_r(ctx_, 4, 2);
    for (unsigned k = 0; k < 4; ++k) {
      const Point2& p = points[t[k % 3]];
      GEOSCoordSeq_setXY_r(ctx_, seq, k, p.x, p.y);
    }
    polygons.push_back(GEOSGeom_createPolygon_r(ctx_, GEOSGeom_createLinearRing_r(ctx_, seq), nullptr, 0));
  }
  Geom collection = Own(GEOSGeom_createCollection_r(ctx_, GEOS_GEOMETRYCOLLECTION, polygons.data(),
                                                    static_cast<unsigned>(polygons.size())));
  return Own(GEOSUnaryUnion_r(ctx_, collection.get()));
}

std::string Geos::ValidReason(const GEOSGeometry* g) const {
  char* reason = GEOSisValidReason_r(ctx_, g);
  std::string out = reason ? reason : "(no reason)";
  GEOSFree_r(ctx_, reason);
  return out;
}

bool Geos::IsCcw(const GEOSGeometry* ring) const {
  char ccw = 0;
  GEOSCoordSeq_isCCW_r(ctx_, GEOSGeom_getCoordSeq_r(ctx_, ring), &ccw);
  return ccw == 1;
}

}  // namespace galpha::testing
