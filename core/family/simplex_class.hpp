// The classes of simplices at a level and the rules that give them, written once for the host
// (AlphaFamily) and the engine's backends (a resident family classifies where its arrays live,
// gpu/alpha/resident_arrays.cuh). Semantics: docs/design.md, "Semantics".
#pragma once

#include <cstdint>

#include "core/base/hd.hpp"
#include "core/family/alpha_ranks.hpp"

namespace galpha {

enum class SimplexClass : uint8_t { kExterior = 0, kSingular = 1, kRegular = 2, kInterior = 3 };
/// "EXTERIOR", "SINGULAR", "REGULAR", "INTERIOR".
const char* SimplexClassName(SimplexClass c);

/// GENERAL keeps singular simplices; REGULARIZED keeps only what bounds or fills triangles.
enum class ClassifyMode { kGeneral, kRegularized };
/// Vertex classes from incident edges (the rule of the report "Computing 2D Alpha Shapes Using GPU") or
/// from incident triangles (CGAL's).
enum class VertexRule { kReport, kCgal };

/// Whether an interval end `rank` (kNeverRank: never) is reached at `level`.
GALPHA_HD inline bool ReachedAt(uint32_t rank, int64_t level) {
  return rank != kNeverRank && level >= static_cast<int64_t>(rank);
}

/// A triangle is INTERIOR from its birth on, EXTERIOR before.
GALPHA_HD inline SimplexClass TriangleClassAt(uint32_t tri_rank, int64_t level) {
  return ReachedAt(tri_rank, level) ? SimplexClass::kInterior : SimplexClass::kExterior;
}

/// An edge from its ranks (rho when unattached, else 0; mu-low; mu-high): EXTERIOR before its birth,
/// SINGULAR (REGULARIZED: EXTERIOR) until its first triangle, REGULAR until both are in.
GALPHA_HD inline SimplexClass EdgeClassAt(uint32_t rho_rank, uint32_t mu_low, uint32_t mu_high, int64_t level,
                                          ClassifyMode mode) {
  if (!ReachedAt(EdgeBirthRank(rho_rank, mu_low), level)) return SimplexClass::kExterior;
  if (!ReachedAt(mu_low, level))
    return mode == ClassifyMode::kGeneral ? SimplexClass::kSingular : SimplexClass::kExterior;
  return ReachedAt(mu_high, level) ? SimplexClass::kInterior : SimplexClass::kRegular;
}

/// A vertex (an input index; a duplicate has its first occurrence's ranks) from its ranks: mu-low
/// (first incident edge in), mu-high (every incident edge interior) and tri-low (first incident
/// triangle in). A hidden point (weighted) is EXTERIOR at every level.
GALPHA_HD inline SimplexClass VertexClassAt(bool hidden, uint32_t mu_low, uint32_t mu_high, uint32_t tri_low,
                                            int64_t level, ClassifyMode mode, VertexRule rule) {
  if (level < 0 || hidden) return SimplexClass::kExterior;
  const bool has_triangle = ReachedAt(tri_low, level);
  if (mode == ClassifyMode::kRegularized && !has_triangle) return SimplexClass::kExterior;
  if (rule == VertexRule::kReport) {
    if (!ReachedAt(mu_low, level)) return SimplexClass::kSingular;
  } else if (!has_triangle) {
    return SimplexClass::kSingular;
  }
  return ReachedAt(mu_high, level) ? SimplexClass::kInterior : SimplexClass::kRegular;
}

}  // namespace galpha
