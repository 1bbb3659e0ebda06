// The alpha family against its definitions, without CGAL (the brute-force comparison on small sets
// is alpha_bruteforce_test.cpp):
// - GUDHI's seven-point example (tests/data/gudhi_alpha_seven_points.txt): the simplices, every
//   birth and the spectrum, exactly;
// - on 2000-point inputs of every hard kind: the rank tables against exact radii and attachment,
//   the intervals' invariants, the master list entry by entry, the exact order of the spectrum, the
//   component curve;
// - the shapes of the family (GEOS): valid, with the interior triangles' area, one polygon per
//   solid component, the singular edges and isolated points the classes name;
// - bad and degenerate input: NaN and infinity name their index; 0, 1, 2 points and collinear sets
//   give families with edges only.
#include "core/family/alpha_family.hpp"

#include <geos_c.h>
#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/io/point_formats.hpp"
#include "core/exact/radius_rational.hpp"
#include "core/geometry/shape.hpp"
#include "gpu/alpha/alpha_engine.hpp"
#include "gtest/gtest.h"
#include "tests/support/data_files.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha {
namespace {

using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

class BackendTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::kCuda && !CudaBackendAvailable()) GTEST_SKIP() << "no GPU";
  }
  absl::StatusOr<AlphaFamily> Build(const std::vector<Point2>& points) const {
    BuildOptions options;
    options.backend = GetParam();
    return BuildAlphaFamily(points, options);
  }
};

std::string BackendParamName(const ::testing::TestParamInfo<Backend>& info) { return BackendName(info.param); }

// Exact rho^2 of a triangle or an edge of the family.
mpq_class TriangleRhoSq(const AlphaFamily& f, uint32_t t) {
  const Point2 p[3] = {f.points()[f.triangles()[t][0]], f.points()[f.triangles()[t][1]],
                       f.points()[f.triangles()[t][2]]};
  return *RadiusSqRational(p, 3);
}
mpq_class EdgeRhoSq(const AlphaFamily& f, uint32_t e) {
  const Point2 p[2] = {f.points()[f.edges()[e][0]], f.points()[f.edges()[e][1]]};
  return *RadiusSqRational(p, 2);
}

// The exact threshold of rank r (1..K), recomputed from the simplex the family names for it.
mpq_class ExactThreshold(const AlphaFamily& f, int64_t rank) {
  const uint32_t id = f.ranks().spectrum_simplex[static_cast<size_t>(rank - 1)];
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  return id < num_tri ? TriangleRhoSq(f, id) : EdgeRhoSq(f, id - num_tri);
}

Tri SortedTri(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

// =================================================================================================
// 1. GUDHI's seven points: exact golden births.

struct Golden {
  std::vector<Point2> points;
  std::map<Edge, mpq_class> edges;
  std::map<Tri, mpq_class> triangles;
  int vertices = 0;
};

Golden ReadGolden(const std::string& path) {
  Golden g;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# Points", 0) == 0) {
      // "# Points (0-based input index: x y): 0: 1 1, 1: 7 0, ..."
      std::string list = line.substr(line.find("):") + 2);
      std::replace(list.begin(), list.end(), ',', ' ');
      std::istringstream items(list);
      std::string index;
      double x, y;
      while (items >> index >> x >> y) {
        EXPECT_EQ(index, std::to_string(g.points.size()) + ":");
        g.points.push_back({x, y});
      }
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string kind, value;
    fields >> kind;
    if (kind == "v") {
      uint32_t i;
      fields >> i >> value;
      EXPECT_EQ(value, "0");
      ++g.vertices;
    } else if (kind == "e") {
      Edge e;
      fields >> e[0] >> e[1] >> value;
      g.edges[e] = mpq_class(value);
    } else if (kind == "t") {
      Tri t;
      fields >> t[0] >> t[1] >> t[2] >> value;
      g.triangles[t] = mpq_class(value);
    } else {
      ADD_FAILURE() << "bad line: " << line;
    }
  }
  return g;
}

using GudhiTest = BackendTest;

TEST_P(GudhiTest, SevenPointsExactBirths) {
  const Golden g = ReadGolden(std::string(GALPHA_TESTS_DATA_DIR) + "/gudhi_alpha_seven_points.txt");
  ASSERT_EQ(g.points.size(), 7u);
  ASSERT_EQ(g.vertices, 7);
  ASSERT_EQ(g.edges.size(), 12u);
  ASSERT_EQ(g.triangles.size(), 6u);
  absl::StatusOr<AlphaFamily> built = Build(g.points);
  ASSERT_TRUE(built.ok()) << built.status();
  const AlphaFamily& f = *built;
  const AlphaRanks& r = f.ranks();

  // The spectrum: the sorted distinct positive births, exactly and as nearest doubles.
  std::vector<mpq_class> spectrum;
  for (const auto& [e, birth] : g.edges) spectrum.push_back(birth);
  for (const auto& [t, birth] : g.triangles) spectrum.push_back(birth);
  std::sort(spectrum.begin(), spectrum.end());
  spectrum.erase(std::unique(spectrum.begin(), spectrum.end()), spectrum.end());
  ASSERT_EQ(f.max_level(), static_cast<int64_t>(spectrum.size()));
  for (int64_t rank = 1; rank <= f.max_level(); ++rank) {
    const mpq_class value = ExactThreshold(f, rank);
    EXPECT_EQ(value, spectrum[static_cast<size_t>(rank - 1)]) << "rank " << rank;
    EXPECT_EQ(f.spectrum()[static_cast<size_t>(rank - 1)], NearestDouble(value)) << "rank " << rank;
  }
  auto value_of = [&](uint32_t rank) -> mpq_class {
    if (rank == 0 || rank == kNeverRank || rank > spectrum.size()) return mpq_class(-1);
    return spectrum[rank - 1];
  };

  // The same simplices, each born at its golden value.
  std::set<Edge> edges;
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const Edge& ed = f.edges()[e];
    edges.insert(ed);
    const auto it = g.edges.find(ed);
    ASSERT_NE(it, g.edges.end()) << "edge " << ed[0] << " " << ed[1] << " is not in the golden file";
    EXPECT_EQ(value_of(EdgeBirthRank(r, e)), it->second) << "edge " << ed[0] << " " << ed[1];
    // Attached exactly when the birth is not the edge's own rho^2 (then it is an incident
    // triangle's, which is larger).
    const bool attached = it->second != EdgeRhoSq(f, e);
    EXPECT_EQ(r.edge_rho_rank[e] == 0, attached) << "edge " << ed[0] << " " << ed[1];
  }
  EXPECT_EQ(edges.size(), g.edges.size());
  std::set<Tri> triangles;
  for (uint32_t t = 0; t < f.triangles().size(); ++t) {
    const Tri tri = SortedTri(f.triangles()[t]);
    triangles.insert(tri);
    const auto it = g.triangles.find(tri);
    ASSERT_NE(it, g.triangles.end()) << "triangle " << tri[0] << " " << tri[1] << " " << tri[2];
    EXPECT_EQ(value_of(r.tri_rank[t]), it->second) << "triangle " << tri[0] << " " << tri[1] << " " << tri[2];
  }
  EXPECT_EQ(triangles.size(), g.triangles.size());
  // The file names these two attached; everything is in at the last rank, nothing singular.
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    const bool named = f.edges()[e] == Edge{0, 4} || f.edges()[e] == Edge{4, 6};
    EXPECT_EQ(r.edge_rho_rank[e] == 0, named) << f.edges()[e][0] << " " << f.edges()[e][1];
  }
  EXPECT_EQ(f.Components(f.max_level()), 1u);
  EXPECT_EQ(f.SolidComponents(f.max_level()), 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, GudhiTest, ::testing::Values(Backend::kCpu, Backend::kCuda), BackendParamName);

// =================================================================================================
// 3. Rank tables, intervals and the master list on bigger inputs.

struct Case {
  std::string name;
  std::vector<Point2> points;
};

std::vector<Case> InvariantCases() {
  using namespace gen;
  return {
      {"uniform", Uniform(2000, 31)},
      {"grid", Grid(2000, 32)},
      {"circle", Circle(2000, 33)},
      {"two_lines", TwoLines(2000, 34)},
      {"duplicates", WithDuplicates(2000, 35)},
      {"tiny", Tiny(2000, 36)},
  };
}

uint32_t MinOf(uint32_t a, uint32_t b) { return std::min(a, b); }

void CheckInvariants(const AlphaFamily& f) {
  const AlphaRanks& r = f.ranks();
  const int64_t k = f.max_level();
  const uint32_t n = static_cast<uint32_t>(f.points().size());
  const uint32_t num_tri = static_cast<uint32_t>(f.triangles().size());
  const uint32_t num_edges = static_cast<uint32_t>(f.edges().size());
  ASSERT_GT(k, 0);
  ASSERT_EQ(r.spectrum.size(), static_cast<size_t>(k));
  ASSERT_EQ(r.spectrum_simplex.size(), static_cast<size_t>(k));
  ASSERT_EQ(r.tri_rank.size(), num_tri);
  ASSERT_EQ(r.edge_rho_rank.size(), num_edges);
  ASSERT_EQ(r.edge_mu_low.size(), num_edges);
  ASSERT_EQ(r.edge_mu_high.size(), num_edges);
  ASSERT_EQ(r.edge_triangles.size(), num_edges);
  ASSERT_EQ(r.vertex_mu_low.size(), n);
  ASSERT_EQ(r.vertex_mu_high.size(), n);
  ASSERT_EQ(r.vertex_tri_low.size(), n);
  auto in_range = [k](uint32_t rank) { return rank >= 1 && static_cast<int64_t>(rank) <= k; };

  // The spectrum: strictly increasing exact values, their nearest doubles non-decreasing.
  std::vector<mpq_class> exact(static_cast<size_t>(k));
  for (int64_t rank = 1; rank <= k; ++rank) {
    exact[static_cast<size_t>(rank - 1)] = ExactThreshold(f, rank);
    ASSERT_EQ(r.spectrum[static_cast<size_t>(rank - 1)], NearestDouble(exact[static_cast<size_t>(rank - 1)]))
        << "rank " << rank;
    if (rank > 1) {
      ASSERT_LT(exact[static_cast<size_t>(rank - 2)], exact[static_cast<size_t>(rank - 1)]) << "rank " << rank;
      ASSERT_LE(r.spectrum[static_cast<size_t>(rank - 2)], r.spectrum[static_cast<size_t>(rank - 1)])
          << "rank " << rank;
    }
  }
  ASSERT_GT(exact[0], 0);

  // Triangles: the rank names their exact rho^2.
  for (uint32_t t = 0; t < num_tri; ++t) {
    ASSERT_TRUE(in_range(r.tri_rank[t])) << "triangle " << t;
    ASSERT_EQ(exact[r.tri_rank[t] - 1], TriangleRhoSq(f, t)) << "triangle " << t;
  }
  // Edges: incident triangles, attachment (exact), rho, mu-low, mu-high.
  std::map<Edge, std::vector<uint32_t>> tris_of_edge;
  for (uint32_t t = 0; t < num_tri; ++t) {
    const Tri& tr = f.triangles()[t];
    for (int k3 = 0; k3 < 3; ++k3) {
      const uint32_t a = tr[k3], b = tr[(k3 + 1) % 3];
      tris_of_edge[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  }
  ASSERT_EQ(tris_of_edge.size(), num_tri == 0 ? 0 : num_edges);
  std::vector<uint32_t> min_birth(n, kNeverRank), max_high(n, 0), min_tri(n, kNeverRank);
  std::vector<bool> has_edge(n, false);
  for (uint32_t e = 0; e < num_edges; ++e) {
    SCOPED_TRACE(testing::Message() << "edge " << e << " (" << f.edges()[e][0] << ", " << f.edges()[e][1] << ")");
    const Edge& ed = f.edges()[e];
    std::vector<uint32_t> tris;
    for (int32_t t : r.edge_triangles[e]) {
      if (t >= 0) tris.push_back(static_cast<uint32_t>(t));
    }
    std::sort(tris.begin(), tris.end());
    if (num_tri > 0) {
      ASSERT_EQ(tris, tris_of_edge[ed]);
    }
    bool attached = false;
    const mpq_class ax(f.points()[ed[0]].x), ay(f.points()[ed[0]].y);
    const mpq_class bx(f.points()[ed[1]].x), by(f.points()[ed[1]].y);
    for (uint32_t t : tris) {
      for (uint32_t v : f.triangles()[t]) {
        if (v == ed[0] || v == ed[1]) continue;
        const mpq_class cx(f.points()[v].x), cy(f.points()[v].y);
        attached |= sgn((ax - cx) * (bx - cx) + (ay - cy) * (by - cy)) < 0;
      }
    }
    if (attached) {
      ASSERT_EQ(r.edge_rho_rank[e], 0u);
    } else {
      ASSERT_TRUE(in_range(r.edge_rho_rank[e]));
      ASSERT_EQ(exact[r.edge_rho_rank[e] - 1], EdgeRhoSq(f, e));
      ASSERT_LE(r.edge_rho_rank[e], r.edge_mu_low[e]) << "unattached: rho <= mu-low";
    }
    uint32_t low = kNeverRank, high = kNeverRank;
    if (tris.size() == 1) low = r.tri_rank[tris[0]];  // a hull edge: never interior
    if (tris.size() == 2) {
      low = std::min(r.tri_rank[tris[0]], r.tri_rank[tris[1]]);
      high = std::max(r.tri_rank[tris[0]], r.tri_rank[tris[1]]);
    }
    ASSERT_EQ(r.edge_mu_low[e], low);
    ASSERT_EQ(r.edge_mu_high[e], high);
    ASSERT_LE(r.edge_mu_low[e], r.edge_mu_high[e]);
    const uint32_t birth = EdgeBirthRank(r, e);
    ASSERT_TRUE(in_range(birth));
    for (uint32_t v : ed) {
      has_edge[v] = true;
      min_birth[v] = MinOf(min_birth[v], birth);
      max_high[v] = std::max(max_high[v], r.edge_mu_high[e]);  // kNeverRank on the hull wins
    }
  }
  for (uint32_t t = 0; t < num_tri; ++t) {
    for (uint32_t v : f.triangles()[t]) min_tri[v] = MinOf(min_tri[v], r.tri_rank[t]);
  }
  // Vertices: from their incident edges and triangles; duplicates repeat their representative's.
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t w = f.representative()[v];
    ASSERT_LE(w, v);
    ASSERT_EQ(f.representative()[w], w);
    ASSERT_EQ(r.vertex_mu_low[v], min_birth[w]) << "vertex " << v;
    ASSERT_EQ(r.vertex_mu_high[v], has_edge[w] ? max_high[w] : kNeverRank) << "vertex " << v;
    ASSERT_EQ(r.vertex_tri_low[v], min_tri[w]) << "vertex " << v;
    ASSERT_EQ(has_edge[v], w == v) << "vertex " << v << ": every distinct point and no duplicate is in an edge";
  }

  // The master list: for every rank exactly the interval end points of that rank, in the order
  // vertex < edge < triangle, then id, then end point (rho, mu-low, mu-high).
  std::vector<std::vector<MasterEntry>> want(static_cast<size_t>(k) + 1);
  auto add = [&](uint32_t rank, uint32_t id, SimplexKind kind, Endpoint end) {
    if (rank == 0 || rank == kNeverRank) return;
    want[rank].push_back({id, kind, end});
  };
  for (uint32_t v = 0; v < n; ++v) {
    if (f.representative()[v] != v) continue;
    add(r.vertex_mu_low[v], v, SimplexKind::kVertex, Endpoint::kMuLow);
    add(r.vertex_mu_high[v], v, SimplexKind::kVertex, Endpoint::kMuHigh);
  }
  for (uint32_t e = 0; e < num_edges; ++e) {
    add(r.edge_rho_rank[e], e, SimplexKind::kEdge, Endpoint::kRho);
    add(r.edge_mu_low[e], e, SimplexKind::kEdge, Endpoint::kMuLow);
    add(r.edge_mu_high[e], e, SimplexKind::kEdge, Endpoint::kMuHigh);
  }
  for (uint32_t t = 0; t < num_tri; ++t) add(r.tri_rank[t], t, SimplexKind::kTriangle, Endpoint::kRho);
  ASSERT_EQ(r.master_begin.size(), static_cast<size_t>(k) + 2);
  ASSERT_EQ(r.master_begin[0], 0u);
  ASSERT_EQ(r.master_begin[1], 0u);
  size_t total = 0;
  for (int64_t rank = 1; rank <= k; ++rank) {
    const std::vector<MasterEntry>& expected = want[static_cast<size_t>(rank)];
    ASSERT_EQ(r.master_begin[static_cast<size_t>(rank)], total) << "rank " << rank;
    total += expected.size();
    ASSERT_GE(expected.size(), 1u) << "rank " << rank << " is nobody's end point";
    const absl::Span<const MasterEntry> got = f.MasterList(rank);
    ASSERT_EQ(got.size(), expected.size()) << "rank " << rank;
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].kind(), expected[i].kind()) << "rank " << rank << " entry " << i;
      ASSERT_EQ(got[i].id(), expected[i].id()) << "rank " << rank << " entry " << i;
      ASSERT_EQ(got[i].endpoint(), expected[i].endpoint()) << "rank " << rank << " entry " << i;
    }
  }
  ASSERT_EQ(r.master_begin.back(), total);
  ASSERT_EQ(r.master.size(), total);
  EXPECT_TRUE(f.MasterList(0).empty());
  EXPECT_TRUE(f.MasterList(k + 1).empty());

  // Components: one per distinct point at level 0, never increasing, one at the end.
  EXPECT_EQ(f.Components(-1), 0u);
  EXPECT_EQ(f.Components(0), f.num_unique());
  for (int64_t level = 1; level <= k; ++level) {
    ASSERT_LE(f.Components(level), f.Components(level - 1)) << "level " << level;
  }
  EXPECT_EQ(f.Components(k), 1u);
  EXPECT_EQ(f.SolidComponents(0), 0u);
  EXPECT_EQ(f.SolidComponents(k), num_tri > 0 ? 1u : 0u);
  EXPECT_EQ(f.report().comparisons.cpu_fallback, 0u);
}

using InvariantsTest = BackendTest;

TEST_P(InvariantsTest, MasterListAndIntervals) {
  for (const Case& c : InvariantCases()) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_TRUE(built.ok()) << built.status();
    CheckInvariants(*built);
    if (HasFatalFailure()) return;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, InvariantsTest, ::testing::Values(Backend::kCpu, Backend::kCuda), BackendParamName);

// =================================================================================================
// 4. The shapes of the family, checked by GEOS.

class Geos {
 public:
  struct Deleter {
    GEOSContextHandle_t ctx;
    void operator()(GEOSGeometry* g) const { GEOSGeom_destroy_r(ctx, g); }
  };
  using Geom = std::unique_ptr<GEOSGeometry, Deleter>;

  Geos() : ctx_(GEOS_init_r()) {}
  ~Geos() { GEOS_finish_r(ctx_); }
  Geos(const Geos&) = delete;
  Geos& operator=(const Geos&) = delete;

  GEOSContextHandle_t ctx() const { return ctx_; }

  Geom ReadWkt(const std::string& wkt) const {
    GEOSWKTReader* reader = GEOSWKTReader_create_r(ctx_);
    GEOSGeometry* g = GEOSWKTReader_read_r(ctx_, reader, wkt.c_str());
    GEOSWKTReader_destroy_r(ctx_, reader);
    return Geom(g, Deleter{ctx_});
  }

  // GEOS's own union of the triangles, built from their coordinates.
  Geom UnionOfTriangles(absl::Span<const Point2> points, const std::vector<Tri>& tris) const {
    std::vector<GEOSGeometry*> polygons;
    for (const Tri& t : tris) {
      GEOSCoordSequence* seq = GEOSCoordSeq_create_r(ctx_, 4, 2);
      for (unsigned k = 0; k < 4; ++k) {
        const Point2& p = points[t[k % 3]];
        GEOSCoordSeq_setXY_r(ctx_, seq, k, p.x, p.y);
      }
      polygons.push_back(GEOSGeom_createPolygon_r(ctx_, GEOSGeom_createLinearRing_r(ctx_, seq), nullptr, 0));
    }
    Geom collection(GEOSGeom_createCollection_r(ctx_, GEOS_GEOMETRYCOLLECTION, polygons.data(),
                                                static_cast<unsigned>(polygons.size())),
                    Deleter{ctx_});
    return Geom(GEOSUnaryUnion_r(ctx_, collection.get()), Deleter{ctx_});
  }

  std::string ValidReason(const GEOSGeometry* g) const {
    char* reason = GEOSisValidReason_r(ctx_, g);
    std::string out = reason ? reason : "(no reason)";
    GEOSFree_r(ctx_, reason);
    return out;
  }

 private:
  GEOSContextHandle_t ctx_;
};

// Edge-connected pieces of a set of triangles (union-find over shared edges).
size_t EdgeConnectedPieces(const std::vector<Tri>& tris) {
  std::vector<uint32_t> parent(tris.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<Edge, uint32_t> first;
  size_t pieces = tris.size();
  for (uint32_t t = 0; t < tris.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
      const auto [it, inserted] = first.emplace(Edge{std::min(a, b), std::max(a, b)}, t);
      if (inserted) continue;
      const uint32_t x = find(it->second), y = find(t);
      if (x != y) {
        parent[x] = y;
        --pieces;
      }
    }
  }
  return pieces;
}

void CheckShapeAt(const Geos& geos, const AlphaFamily& f, int64_t level) {
  SCOPED_TRACE(testing::Message() << "level " << level << " of " << f.max_level());
  const absl::Span<const Point2> points = f.points();
  // What the classes say is in, independently of ComplexAt.
  const Classification classes = f.ClassifyAll(level, ClassifyMode::kGeneral, VertexRule::kReport);
  std::vector<Tri> interior;
  double area = 0.0;
  for (uint32_t t = 0; t < f.triangles().size(); ++t) {
    if (classes.triangles[t] != SimplexClass::kInterior) continue;
    const Tri& tr = f.triangles()[t];
    interior.push_back(tr);
    const Point2 a = points[tr[0]], b = points[tr[1]], c = points[tr[2]];
    area += 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  std::vector<Edge> singular;
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    if (classes.edges[e] == SimplexClass::kSingular) singular.push_back(f.edges()[e]);
  }
  std::vector<uint32_t> isolated;
  for (uint32_t v = 0; v < points.size(); ++v) {
    if (f.representative()[v] == v && classes.vertices[v] == SimplexClass::kSingular) isolated.push_back(v);
  }
  const size_t pieces = EdgeConnectedPieces(interior);
  ASSERT_EQ(f.SolidComponents(level), pieces);

  std::string general_wkt;
  for (ClassifyMode mode : {ClassifyMode::kGeneral, ClassifyMode::kRegularized}) {
    const bool general = mode == ClassifyMode::kGeneral;
    SCOPED_TRACE(general ? "GENERAL" : "REGULARIZED");
    const ShapeComplex complex = f.ComplexAt(level, mode);
    std::vector<Tri> got_tris = complex.triangles, want_tris = interior;
    std::sort(got_tris.begin(), got_tris.end());
    std::sort(want_tris.begin(), want_tris.end());
    ASSERT_EQ(got_tris, want_tris);
    const absl::StatusOr<ShapeGeometry> shape = AssembleShape(complex);
    ASSERT_TRUE(shape.ok()) << shape.status();
    ASSERT_EQ(shape->polygons.size(), pieces);
    EXPECT_NEAR(shape->area, area, 1e-9 * std::abs(area));
    std::vector<Edge> want_singular = general ? singular : std::vector<Edge>{};
    std::sort(want_singular.begin(), want_singular.end());
    ASSERT_EQ(shape->singular_edges, want_singular);
    ASSERT_EQ(shape->isolated_points, general ? isolated : std::vector<uint32_t>{});
    if (!general) continue;

    const std::string wkt = ShapeToWkt(*shape, points);
    const Geos::Geom collection = geos.ReadWkt(wkt);
    ASSERT_NE(collection, nullptr);
    int part = 0;
    if (!shape->polygons.empty()) {
      const GEOSGeometry* multi = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), multi), GEOS_MULTIPOLYGON);
      EXPECT_EQ(GEOSisValid_r(geos.ctx(), multi), 1) << geos.ValidReason(multi);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multi), static_cast<int>(pieces));
      double geos_area = 0.0;
      GEOSArea_r(geos.ctx(), multi, &geos_area);
      EXPECT_NEAR(geos_area, area, 1e-9 * std::abs(area));
      const Geos::Geom merged = geos.UnionOfTriangles(points, interior);
      ASSERT_NE(merged, nullptr);
      EXPECT_EQ(GEOSEquals_r(geos.ctx(), multi, merged.get()), 1);
    } else {
      EXPECT_EQ(pieces, 0u);
    }
    if (!shape->singular_edges.empty()) {
      const GEOSGeometry* lines = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), lines), GEOS_MULTILINESTRING);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), lines), static_cast<int>(singular.size()));
    }
    if (!shape->isolated_points.empty()) {
      const GEOSGeometry* multipoint = GEOSGetGeometryN_r(geos.ctx(), collection.get(), part++);
      ASSERT_EQ(GEOSGeomTypeId_r(geos.ctx(), multipoint), GEOS_MULTIPOINT);
      EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), multipoint), static_cast<int>(isolated.size()));
    }
    EXPECT_EQ(GEOSGetNumGeometries_r(geos.ctx(), collection.get()), part);
  }
}

void CheckShapes(const AlphaFamily& f) {
  const Geos geos;
  const int64_t k = f.max_level();
  constexpr int64_t kLevels = 8;
  std::set<int64_t> levels = {0, k};
  for (int64_t i = 1; i < kLevels; ++i) levels.insert(k * i / kLevels);
  // Where the shape is richest: just before every point is covered, and the optimal levels.
  if (f.SolidLevel()) levels.insert(std::max<int64_t>(0, *f.SolidLevel() - 1));
  if (f.OptimalLevelGeneral(1)) levels.insert(*f.OptimalLevelGeneral(1));
  for (int64_t level : levels) {
    CheckShapeAt(geos, f, level);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

using ShapesTest = BackendTest;

TEST_P(ShapesTest, GeneratedInputs) {
  const std::vector<Case> cases = {
      {"uniform", gen::Uniform(2000, 41)}, {"grid", gen::Grid(1600, 42)}, {"clustered", gen::Clustered(2000, 43)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    absl::StatusOr<AlphaFamily> built = Build(c.points);
    ASSERT_TRUE(built.ok()) << built.status();
    CheckShapes(*built);
    if (HasFatalFailure()) return;
  }
}

TEST_P(ShapesTest, RealDataSet) {
  const std::vector<std::string> files = testdata::PointFiles();
  ASSERT_FALSE(files.empty());
  // The GPS tracks: thin traces far apart, in degrees (the smallest real set).
  std::string file = files.front();
  for (const std::string& candidate : files) {
    if (candidate.find("gps_tracks") != std::string::npos) file = candidate;
  }
  SCOPED_TRACE(file);
  absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(file);
  ASSERT_TRUE(points.ok()) << points.status();
  absl::StatusOr<AlphaFamily> built = Build(*points);
  ASSERT_TRUE(built.ok()) << built.status();
  CheckShapes(*built);
}

INSTANTIATE_TEST_SUITE_P(Backends, ShapesTest, ::testing::Values(Backend::kCpu, Backend::kCuda), BackendParamName);

// =================================================================================================
// 5. Bad and degenerate input.

using InputTest = BackendTest;

TEST_P(InputTest, NonFiniteCoordinatesNameTheirIndex) {
  const double nan = std::nan(""), inf = INFINITY;
  const std::vector<std::pair<std::vector<Point2>, size_t>> cases = {
      {{{nan, 0}}, 0},
      {{{0, 0}, {1, 0}, {0, 1}, {2, nan}, {5, 5}}, 3},
      {{{0, 0}, {1, 0}, {nan, nan}, {inf, 1}}, 2},
      {{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {-inf, 1}}, 4},
      {{{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {3, -inf}}, 11},
  };
  for (const auto& [points, bad] : cases) {
    const absl::StatusOr<AlphaFamily> built = Build(points);
    ASSERT_FALSE(built.ok()) << "bad index " << bad;
    EXPECT_EQ(built.status().code(), absl::StatusCode::kInvalidArgument) << built.status();
    const std::string message(built.status().message());
    EXPECT_NE(message.find("point " + std::to_string(bad) + " "), std::string::npos) << message;
  }
}

// A family with no triangles: the edges of a chain, the spectrum of their squared half lengths.
void CheckChainFamily(const AlphaFamily& f, const std::vector<Point2>& points) {
  // The chain: the distinct points in their order along the line (lexicographic on a line).
  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < points.size(); ++i) {
    bool first = true;
    for (uint32_t j = 0; j < i && first; ++j) first = !(points[j] == points[i]);
    if (first) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return LexLess(points[a], points[b]); });
  std::set<Edge> want_edges;
  std::vector<mpq_class> spectrum;
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    want_edges.insert({std::min(order[i], order[i + 1]), std::max(order[i], order[i + 1])});
    const mpq_class dx = mpq_class(points[order[i + 1]].x) - points[order[i]].x;
    const mpq_class dy = mpq_class(points[order[i + 1]].y) - points[order[i]].y;
    spectrum.push_back((dx * dx + dy * dy) / 4);
  }
  std::sort(spectrum.begin(), spectrum.end());
  spectrum.erase(std::unique(spectrum.begin(), spectrum.end()), spectrum.end());

  EXPECT_EQ(f.num_unique(), order.size());
  EXPECT_TRUE(f.triangles().empty());
  EXPECT_EQ(std::set<Edge>(f.edges().begin(), f.edges().end()), want_edges);
  EXPECT_EQ(f.edges().size(), want_edges.size());
  ASSERT_EQ(f.max_level(), static_cast<int64_t>(spectrum.size()));
  for (int64_t rank = 1; rank <= f.max_level(); ++rank) {
    EXPECT_EQ(ExactThreshold(f, rank), spectrum[static_cast<size_t>(rank - 1)]) << "rank " << rank;
    EXPECT_EQ(f.spectrum()[static_cast<size_t>(rank - 1)], NearestDouble(spectrum[static_cast<size_t>(rank - 1)]));
  }
  for (uint32_t e = 0; e < f.edges().size(); ++e) {
    EXPECT_NE(f.ranks().edge_rho_rank[e], 0u) << "an edge without triangles is unattached";
    EXPECT_EQ(f.ranks().edge_mu_low[e], kNeverRank);
    EXPECT_EQ(f.ranks().edge_mu_high[e], kNeverRank);
  }
  EXPECT_EQ(f.SolidLevel(), std::nullopt);
  EXPECT_EQ(f.OptimalLevelRegularized(1), std::nullopt);
  EXPECT_EQ(f.Components(0), order.size());
  EXPECT_EQ(f.Components(f.max_level()), order.empty() ? 0u : 1u);
  EXPECT_EQ(f.OptimalLevelGeneral(1),
            order.empty() ? std::optional<int64_t>(0) : std::optional<int64_t>(order.size() <= 1 ? 0 : f.max_level()));
  // Everything is singular at the end (no triangle ever), and nothing is in REGULARIZED mode.
  const Classification general = f.ClassifyAll(f.max_level(), ClassifyMode::kGeneral, VertexRule::kReport);
  for (SimplexClass c : general.edges) EXPECT_EQ(c, SimplexClass::kSingular);
  for (uint32_t v = 0; v < points.size(); ++v) {
    EXPECT_EQ(general.vertices[v], order.size() == 1 ? SimplexClass::kSingular : SimplexClass::kRegular) << v;
  }
  const Classification regularized = f.ClassifyAll(f.max_level(), ClassifyMode::kRegularized, VertexRule::kCgal);
  for (SimplexClass c : regularized.edges) EXPECT_EQ(c, SimplexClass::kExterior);
  for (SimplexClass c : regularized.vertices) EXPECT_EQ(c, SimplexClass::kExterior);
  const absl::StatusOr<ShapeGeometry> shape = AssembleShape(f.ComplexAt(f.max_level(), ClassifyMode::kGeneral));
  ASSERT_TRUE(shape.ok()) << shape.status();
  EXPECT_TRUE(shape->polygons.empty());
  EXPECT_EQ(shape->singular_edges.size(), want_edges.size());
}

TEST_P(InputTest, FewPointsAndCollinearSetsAreValid) {
  auto tiny = [](int m) { return std::ldexp(static_cast<double>(m), -1000); };  // m * 2^-1000, exact
  const std::vector<std::vector<Point2>> cases = {
      {},
      {{2, 3}},
      {{2, 3}, {2, 3}},
      {{2, 3}, {5, -1}},
      {{5, -1}, {2, 3}, {5, -1}},
      // Collinear chains: repeated gaps (exact ties), unsorted input, duplicates, a vertical line,
      // a diagonal through huge coordinates, tiny coordinates.
      {{0, 1}, {3, 7}, {1, 3}, {2, 5}, {5, 11}, {4, 9}, {9, 19}},
      {{7, 0}, {7, -3}, {7, 10}, {7, -3}, {7, 1}, {7, 4}},
      {{1e15, -1e15}, {-1e15, 1e15}, {0.5, -0.5}, {0, 0}, {3, -3}},
      {{tiny(1), tiny(3)}, {tiny(4), tiny(12)}, {tiny(2), tiny(6)}, {tiny(8), tiny(24)}, {tiny(5), tiny(15)}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "case " << i);
    const absl::StatusOr<AlphaFamily> built = Build(cases[i]);
    ASSERT_TRUE(built.ok()) << built.status();
    CheckChainFamily(*built, cases[i]);
  }
  // A long chain of integers on one line (many exact ties).
  std::vector<Point2> line;
  for (int i = 0; i < 500; ++i)
    line.push_back({static_cast<double>((i * 37) % 500), static_cast<double>(2 * ((i * 37) % 500) + 1)});
  const absl::StatusOr<AlphaFamily> built = Build(line);
  ASSERT_TRUE(built.ok()) << built.status();
  CheckChainFamily(*built, line);
  EXPECT_EQ(built->max_level(), 1);
}

INSTANTIATE_TEST_SUITE_P(Backends, InputTest, ::testing::Values(Backend::kCpu, Backend::kCuda), BackendParamName);

}  // namespace
}  // namespace galpha
