// CGAL's Alpha_shape_2 (CGAL 5.5, Debian libcgal-dev) as an exact oracle.
//
// What CGAL computes, read from <CGAL/Alpha_shape_2.h> (5.5.1). "r2(f)" is the squared
// circumradius of a finite face, "rho2(e)" the squared half length of an edge. An edge is
// ATTACHED iff the third vertex of one of its finite incident faces lies strictly inside its
// diametral circle (Side_of_bounded_circle_2 == ON_BOUNDED_SIDE; on the circle = unattached).
// The intervals and the spectrum are built once, in the constructor, and ONLY when the
// triangulation has dimension 2; otherwise every map stays empty.
//
// (a) Spectrum (alpha_begin()..alpha_end(), initialize_alpha_spectrum): the sorted merge of r2(f)
//     of every finite face and rho2(e) of every UNATTACHED finite edge (attached edges, stored
//     with rho = UNDEFINED, are skipped: their birth is an incident face's r2 anyway). A value is
//     appended only if it is > 0 and strictly greater than the last one appended, so the spectrum
//     is strictly increasing, exact ties are merged (the comparisons are exact with Epeck), and
//     0 (vertices) never appears. It does not depend on the mode. (number_of_alphas()'s comment
//     says "not necessarily different", but the code de-duplicates.)
// (b) Thresholds are CLOSED. Face: INTERIOR iff r2(f) <= alpha, infinite faces EXTERIOR. Edge
//     interval (rho, mu_low, mu_high): rho = rho2(e) or UNDEFINED (attached); mu_low = smaller r2
//     of its finite faces; mu_high = larger one, or Infinity for a convex-hull edge.
//       alpha < mu_low : SINGULAR iff unattached and rho <= alpha (GENERAL), else EXTERIOR;
//       alpha >= mu_low: REGULAR if hull edge or alpha < mu_high, else INTERIOR.
//     So at alpha == threshold the simplex is already in (SINGULAR from rho on, REGULAR from
//     mu_low on, INTERIOR from mu_high on). REGULARIZED mode turns the SINGULAR case into EXTERIOR.
//     (An attached edge is always attached by its smaller face, since the Delaunay angles
//     opposite it sum to <= pi, so min over all faces = min over the attaching ones.)
// (c) Vertices use incident FACES, not edges (the Edelsbrunner-Muecke edge-based code is commented
//     out in the header): range (mid, max), mid = min r2 over incident finite faces, max = Infinity
//     for a hull vertex (incident to an infinite face), else the max incident r2.
//       alpha < mid : SINGULAR in GENERAL mode (vertices are never EXTERIOR there; REGULARIZED:
//                     EXTERIOR);
//       alpha >= mid: REGULAR if hull vertex or alpha < max, else INTERIOR.
//     Hence a vertex that only has SINGULAR edges is SINGULAR for CGAL (REGULAR in the report
//     "Computing 2D Alpha Shapes Using GPU");
//     a hull vertex is never INTERIOR.
// (d) number_of_solid_components(alpha): connected components of the finite faces with
//     r2 <= alpha, two faces being connected iff they share an edge (BFS over neighbor());
//     sharing only a vertex does not connect; singular edges/vertices do not count; 0 when no
//     face is in (and in dimension < 2).
//     find_alpha_solid(): 0 with < 3 vertices, else max over vertices of their min incident r2:
//     the smallest alpha at which every vertex is REGULAR or INTERIOR by (c). (In dimension 1 with
//     >= 3 vertices it dereferences --end() of the empty face map: undefined behaviour.)
//     find_optimal_alpha(n): a = find_alpha_solid(), first = lower_bound(spectrum, a). If
//     nsc(a) == n it returns first+1 (first if first+1 is end). Otherwise it binary-searches
//     [first, end-1) for the first value s with nsc(s) <= n, assuming nsc monotone (it is not in
//     general), landing on end-1 if none, and again returns the NEXT iterator (that one if it is
//     the last). So, unlike its documentation ("the first alpha such that..."), CGAL answers the
//     spectrum value one step PAST the smallest qualifying one, unless that one is the last value;
//     alpha_end() only for an empty spectrum.
// Dimension < 2: CGAL classifies from default-constructed intervals (observed: edges EXTERIOR
// and vertices SINGULAR at alpha = 0, everything INTERIOR for alpha > 0), which is meaningless,
// so Classify reports the natural extension there (see the header).
#include "tests/support/cgal_alpha_oracle.hpp"

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <iterator>
#include <numeric>
#include <type_traits>

#include "tests/support/cgal_oracle_classes.hpp"

namespace galpha::testing {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using VertexBase =
    CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel, CGAL::Alpha_shape_vertex_base_2<Kernel>>;
using FaceBase = CGAL::Alpha_shape_face_base_2<Kernel>;
using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, DataStructure>;
using AlphaShape = CGAL::Alpha_shape_2<Delaunay>;
using FT = AlphaShape::FT;
using ExactType = std::decay_t<decltype(CGAL::exact(std::declval<FT>()))>;

// Lossless conversions between CGAL's exact field type and mpq_class, by overloading on that type
// (an unsupported one fails to compile here). With CGAL::CGAL and CGAL_WITH_GMPXX (Debian's
// default) the type is mpq_class itself; Gmpq is what CGAL picks with GMP but without gmpxx.
[[maybe_unused]] const mpq_class& ExactToMpq(const mpq_class& exact) { return exact; }
[[maybe_unused]] mpq_class MpqToExact(const mpq_class& value, const mpq_class* /*tag*/) { return value; }
#ifdef CGAL_USE_GMP
[[maybe_unused]] mpq_class ExactToMpq(const CGAL::Gmpq& exact) {
  mpq_class out;
  mpq_set(out.get_mpq_t(), exact.mpq());
  return out;
}
[[maybe_unused]] CGAL::Gmpq MpqToExact(const mpq_class& value, const CGAL::Gmpq* /*tag*/) {
  return CGAL::Gmpq(value.get_mpq_t());
}
#endif

mpq_class ToMpq(const FT& value) { return ExactToMpq(CGAL::exact(value)); }

FT FromMpq(const mpq_class& value) { return FT(MpqToExact(value, static_cast<const ExactType*>(nullptr))); }

OracleClass FromCgal(AlphaShape::Classification_type type) { return OracleClassOf<AlphaShape>(type); }

std::pair<uint32_t, uint32_t> EdgeKey(const AlphaShape::Edge& edge) { return EdgeKeyOf<AlphaShape>(edge); }

}  // namespace

std::ostream& operator<<(std::ostream& os, OracleClass c) {
  static const char* const kNames[] = {"EXTERIOR", "SINGULAR", "REGULAR", "INTERIOR"};
  return os << kNames[static_cast<int>(c)];
}

struct CgalAlphaOracle::Impl {
  AlphaShape shape;
  std::vector<mpq_class> spectrum;

  explicit Impl(Delaunay& dt) : shape(dt, FT(0), AlphaShape::GENERAL) {}
};

CgalAlphaOracle::CgalAlphaOracle(absl::Span<const galpha::Point2> points) {
  // The distinct points, each with the input index of its first occurrence.
  std::vector<uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return LexLess(points[a], points[b]); });
  std::vector<std::pair<Kernel::Point_2, uint32_t>> firsts;
  for (size_t r = 0; r < order.size(); ++r) {
    const uint32_t i = order[r];
    if (r > 0 && points[i] == points[order[r - 1]]) continue;
    firsts.emplace_back(Kernel::Point_2(points[i].x, points[i].y), i);  // doubles: exact
  }
  Delaunay dt(firsts.begin(), firsts.end());
  impl_ = std::make_unique<Impl>(dt);  // Alpha_shape_2 swaps the triangulation in
  for (auto it = impl_->shape.alpha_begin(); it != impl_->shape.alpha_end(); ++it) {
    impl_->spectrum.push_back(ToMpq(*it));
  }
}

CgalAlphaOracle::~CgalAlphaOracle() = default;

const std::vector<mpq_class>& CgalAlphaOracle::spectrum() const { return impl_->spectrum; }

int CgalAlphaOracle::dimension() const { return impl_->shape.dimension(); }

size_t CgalAlphaOracle::num_vertices() const { return impl_->shape.number_of_vertices(); }

CgalAlphaOracle::Classes CgalAlphaOracle::Classify(const mpq_class& alpha_sq) const {
  AlphaShape& shape = impl_->shape;
  Classes out;
  if (shape.dimension() < 2) {
    // No faces: edges are singular from their squared half length on, vertices always singular.
    for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
      const auto& p = e->first->vertex(AlphaShape::cw(e->second))->point();
      const auto& q = e->first->vertex(AlphaShape::ccw(e->second))->point();
      const mpq_class rho2 = ToMpq(CGAL::squared_distance(p, q)) / 4;
      const OracleClass c = alpha_sq < rho2 ? OracleClass::kExterior : OracleClass::kSingular;
      out.edges[EdgeKey(*e)] = c;
      if (c == OracleClass::kSingular) ++out.regularized_edges_singular;
    }
    for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v) {
      out.vertices[v->info()] = OracleClass::kSingular;
    }
    return out;
  }

  const FT alpha = FromMpq(alpha_sq);
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
    out.edges[EdgeKey(*e)] = FromCgal(shape.classify(*e, alpha));
  }
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v) {
    out.vertices[v->info()] = FromCgal(shape.classify(v, alpha));
  }
  for (auto f = shape.finite_faces_begin(); f != shape.finite_faces_end(); ++f) {
    if (shape.classify(f, alpha) == AlphaShape::INTERIOR) ++out.interior_triangles;
  }
  out.solid_components = shape.number_of_solid_components(alpha);

  // CGAL's own edge lists (a second code path: the sorted interval map, not classify()).
  const FT previous_alpha = shape.set_alpha(alpha);
  shape.set_mode(AlphaShape::REGULARIZED);
  const auto regular =
      static_cast<size_t>(std::distance(shape.alpha_shape_edges_begin(), shape.alpha_shape_edges_end()));
  shape.set_mode(AlphaShape::GENERAL);
  shape.set_alpha(alpha);  // drops the cached lists
  const auto general =
      static_cast<size_t>(std::distance(shape.alpha_shape_edges_begin(), shape.alpha_shape_edges_end()));
  shape.set_alpha(previous_alpha);
  out.regularized_edges_regular = regular;
  out.regularized_edges_singular = general - regular;
  return out;
}

std::optional<mpq_class> CgalAlphaOracle::OptimalAlpha(int num_components) const {
  AlphaShape& shape = impl_->shape;
  if (shape.dimension() < 2 || num_components < 0) return std::nullopt;
  const auto it = shape.find_optimal_alpha(static_cast<AlphaShape::size_type>(num_components));
  if (it == shape.alpha_end()) return std::nullopt;
  return ToMpq(*it);
}

std::optional<mpq_class> CgalAlphaOracle::AlphaSolid() const {
  const AlphaShape& shape = impl_->shape;
  if (shape.number_of_vertices() < 3) return mpq_class(0);
  if (shape.dimension() < 2) return std::nullopt;
  return ToMpq(shape.find_alpha_solid());
}

}  // namespace galpha::testing
