// Two families of one point set compared table by table: every array of AlphaFamily, its rank
// tables and curves, the area scale and the solid level (header only; the resident family's and
// the packed families' tests, whose families must equal BuildAlphaFamily's bit for bit).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/base/host_vector.hpp"
#include "core/family/alpha_family.hpp"

namespace galpha::testing {

template <typename T>
std::vector<T> AsVector(const HostVector<T>& v) {
  return std::vector<T>(v.begin(), v.end());
}

/// Master-list entries as their packed words (MasterEntry has no equality of its own).
inline std::vector<uint64_t> PackedEntries(const HostVector<MasterEntry>& entries) {
  std::vector<uint64_t> out;
  out.reserve(entries.size());
  for (const MasterEntry& e : entries) out.push_back(e.packed());
  return out;
}

/// Every table of `a` equals `b`'s.
inline void ExpectSameFamilyTables(const AlphaFamily& a, const AlphaFamily& b) {
  EXPECT_EQ(AsVector(a.points()), AsVector(b.points()));
  EXPECT_EQ(AsVector(a.representative()), AsVector(b.representative()));
  EXPECT_EQ(a.num_unique(), b.num_unique());
  EXPECT_EQ(AsVector(a.triangles()), AsVector(b.triangles()));
  EXPECT_EQ(AsVector(a.edges()), AsVector(b.edges()));
  EXPECT_EQ(AsVector(a.weights()), AsVector(b.weights()));
  EXPECT_EQ(AsVector(a.hidden_flags()), AsVector(b.hidden_flags()));
  const AlphaRanks& r = a.ranks();
  const AlphaRanks& s = b.ranks();
  EXPECT_EQ(AsVector(r.spectrum), AsVector(s.spectrum));
  EXPECT_EQ(AsVector(r.spectrum_simplex), AsVector(s.spectrum_simplex));
  EXPECT_EQ(AsVector(r.tri_rank), AsVector(s.tri_rank));
  EXPECT_EQ(AsVector(r.edge_rho_rank), AsVector(s.edge_rho_rank));
  EXPECT_EQ(AsVector(r.edge_mu_low), AsVector(s.edge_mu_low));
  EXPECT_EQ(AsVector(r.edge_mu_high), AsVector(s.edge_mu_high));
  EXPECT_EQ(AsVector(r.edge_triangles), AsVector(s.edge_triangles));
  EXPECT_EQ(AsVector(r.vertex_mu_low), AsVector(s.vertex_mu_low));
  EXPECT_EQ(AsVector(r.vertex_mu_high), AsVector(s.vertex_mu_high));
  EXPECT_EQ(AsVector(r.vertex_tri_low), AsVector(s.vertex_tri_low));
  EXPECT_EQ(AsVector(r.master_begin), AsVector(s.master_begin));
  EXPECT_EQ(PackedEntries(r.master), PackedEntries(s.master));
  EXPECT_EQ(AsVector(r.components), AsVector(s.components));
  EXPECT_EQ(AsVector(r.solid_components), AsVector(s.solid_components));
  EXPECT_EQ(AsVector(r.holes), AsVector(s.holes));
  EXPECT_EQ(AsVector(r.regularized_components), AsVector(s.regularized_components));
  EXPECT_EQ(AsVector(r.regularized_holes), AsVector(s.regularized_holes));
  EXPECT_EQ(AsVector(r.area_units), AsVector(s.area_units));
  EXPECT_EQ(r.area_scale.unit_log2, s.area_scale.unit_log2);
  EXPECT_EQ(r.area_scale.error_units, s.area_scale.error_units);
  EXPECT_EQ(a.SolidLevel(), b.SolidLevel());
}

}  // namespace galpha::testing
