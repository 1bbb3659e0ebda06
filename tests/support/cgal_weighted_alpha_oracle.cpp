// CGAL's weighted Alpha_shape_2 (CGAL 5.5, Debian libcgal-dev) as an exact oracle.
//
// Over a Regular_triangulation_2, Alpha_shape_2 computes the same intervals as over a Delaunay
// triangulation (tests/support/cgal_alpha_oracle.cpp, (a) to (c)) with the weighted constructions:
// a face's alpha is the squared radius of its smallest orthogonal circle, an edge's rho that of
// the edge, and an edge is attached when the third vertex of a face has negative power with
// respect to the edge's circle (power_side_of_bounded_power_circle_2 == ON_BOUNDED_SIDE).
//
// Vertices below alpha = 0: see Classify.
//
// One trap: CGAL marks "no value" in its intervals with the sentinels Infinity = -1 and
// UNDEFINED = -2 (Alpha_shape_2.h), which weighted thresholds can equal. Adding a constant c to
// every weight changes neither the regular triangulation (every lift moves by -c) nor the
// attachment, and lowers every threshold by exactly c; so where a threshold of the shape built
// with c = 0 is -1 or -2, the oracle builds it again with c = 1/3 (exact in Epeck), and reports
// thresholds + c and classifies at alpha - c.
#include "tests/support/cgal_weighted_alpha_oracle.hpp"

// GCC 12 flags a copy inside CGAL's Weighted_point_2 (a boost tuple, through Epeck's static
// filters) as maybe-uninitialized at -O3; the warning is CGAL's, not this file's.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include <CGAL/Alpha_shape_2.h>
#include <CGAL/Alpha_shape_face_base_2.h>
#include <CGAL/Alpha_shape_vertex_base_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <map>
#include <tuple>
#include <type_traits>

#include "tests/support/cgal_oracle_classes.hpp"

namespace galpha::testing {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using VertexBase = CGAL::Alpha_shape_vertex_base_2<
    Kernel,
    CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel, CGAL::Regular_triangulation_vertex_base_2<Kernel>>>;
using FaceBase = CGAL::Alpha_shape_face_base_2<Kernel, CGAL::Regular_triangulation_face_base_2<Kernel>>;
using DataStructure = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Regular = CGAL::Regular_triangulation_2<Kernel, DataStructure>;
using AlphaShape = CGAL::Alpha_shape_2<Regular>;
using FT = AlphaShape::FT;

// Lossless conversion of CGAL's exact field type (mpq_class itself with Debian's CGAL_USE_GMPXX,
// Gmpq with GMP alone; anything else fails to compile here).
[[maybe_unused]] const mpq_class& ExactToMpq(const mpq_class& exact) { return exact; }
#ifdef CGAL_USE_GMP
[[maybe_unused]] mpq_class ExactToMpq(const CGAL::Gmpq& exact) {
  mpq_class out;
  mpq_set(out.get_mpq_t(), exact.mpq());
  return out;
}
#endif

mpq_class ToMpq(const FT& value) { return ExactToMpq(CGAL::exact(value)); }

OracleClass FromCgal(AlphaShape::Classification_type type) { return OracleClassOf<AlphaShape>(type); }

std::pair<uint32_t, uint32_t> EdgeKey(const AlphaShape::Edge& edge) { return EdgeKeyOf<AlphaShape>(edge); }

}  // namespace

struct CgalWeightedAlphaOracle::Impl {
  Regular regular;  // built here, then swapped into `shape` (Alpha_shape_2's constructor)
  std::unique_ptr<AlphaShape> shape;
  FT shift = FT(0);
  std::vector<mpq_class> thresholds;
  std::vector<uint32_t> hidden;

  void Build(const std::vector<std::pair<Kernel::Weighted_point_2, uint32_t>>& input) {
    regular.clear();
    std::vector<std::pair<Kernel::Weighted_point_2, uint32_t>> shifted;
    shifted.reserve(input.size());
    for (const auto& [wp, index] : input) {
      shifted.emplace_back(Kernel::Weighted_point_2(wp.point(), wp.weight() + shift), index);
    }
    regular.insert(shifted.begin(), shifted.end());
    shape = std::make_unique<AlphaShape>(regular, FT(0), AlphaShape::GENERAL);
  }

  /// The thresholds of the built triangulation, before the shift is added back, from the
  /// kernel's constructions as Alpha_shape_2 uses them: every finite face's squared radius, and
  /// every finite edge's that no third vertex of its faces attaches.
  std::vector<FT> RawThresholds() const {
    std::vector<FT> out;
    const Regular& regular = *shape;  // the shape took the triangulation over (it swaps it in)
    if (regular.dimension() != 2) return out;
    const Kernel kernel;
    const auto radius = kernel.compute_squared_radius_smallest_orthogonal_circle_2_object();
    const auto side = kernel.power_side_of_bounded_power_circle_2_object();
    for (auto f = regular.finite_faces_begin(); f != regular.finite_faces_end(); ++f) {
      out.push_back(radius(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point()));
    }
    for (auto e = regular.finite_edges_begin(); e != regular.finite_edges_end(); ++e) {
      const Regular::Face_handle faces[2] = {e->first, e->first->neighbor(e->second)};
      const int opposite[2] = {e->second, faces[1]->index(e->first)};
      const auto& p = e->first->vertex(Regular::cw(e->second))->point();
      const auto& q = e->first->vertex(Regular::ccw(e->second))->point();
      bool attached = false;
      for (int k = 0; k < 2; ++k) {
        if (regular.is_infinite(faces[k])) continue;
        attached = attached || side(p, q, faces[k]->vertex(opposite[k])->point()) == CGAL::ON_BOUNDED_SIDE;
      }
      if (!attached) out.push_back(radius(p, q));
    }
    return out;
  }
};

CgalWeightedAlphaOracle::CgalWeightedAlphaOracle(absl::Span<const Point2> points, absl::Span<const double> weights)
    : impl_(std::make_unique<Impl>()) {
  std::map<std::tuple<double, double, double>, uint32_t> first;
  std::vector<std::pair<Kernel::Weighted_point_2, uint32_t>> input;
  for (uint32_t i = 0; i < points.size(); ++i) {
    if (first.emplace(std::make_tuple(points[i].x + 0.0, points[i].y + 0.0, weights[i] + 0.0), i).second) {
      input.emplace_back(Kernel::Weighted_point_2(Kernel::Point_2(points[i].x, points[i].y), weights[i]), i);
    }
  }
  impl_->Build(input);
  std::vector<FT> raw = impl_->RawThresholds();
  if (std::any_of(raw.begin(), raw.end(), [](const FT& v) { return v == FT(-1) || v == FT(-2); })) {
    impl_->shift = FT(1) / FT(3);
    impl_->Build(input);
    raw = impl_->RawThresholds();
  }
  for (const FT& v : raw) impl_->thresholds.push_back(ToMpq(v + impl_->shift));
  std::sort(impl_->thresholds.begin(), impl_->thresholds.end());
  impl_->thresholds.erase(std::unique(impl_->thresholds.begin(), impl_->thresholds.end()), impl_->thresholds.end());
  const Regular& regular = *impl_->shape;
  for (auto v = regular.hidden_vertices_begin(); v != regular.hidden_vertices_end(); ++v) {
    impl_->hidden.push_back(v->info());
  }
  std::sort(impl_->hidden.begin(), impl_->hidden.end());
}

CgalWeightedAlphaOracle::~CgalWeightedAlphaOracle() = default;

const std::vector<mpq_class>& CgalWeightedAlphaOracle::thresholds() const { return impl_->thresholds; }
int CgalWeightedAlphaOracle::dimension() const { return impl_->shape->dimension(); }
const std::vector<uint32_t>& CgalWeightedAlphaOracle::hidden() const { return impl_->hidden; }

CgalWeightedAlphaOracle::Classes CgalWeightedAlphaOracle::Classify(const mpq_class& alpha_sq) const {
  Classes out;
  const AlphaShape& shape = *impl_->shape;
  const FT alpha = FT(alpha_sq) - impl_->shift;
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
    out.edges[EdgeKey(*e)] = FromCgal(shape.classify(*e, alpha));
  }
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v) {
    if (alpha >= FT(0)) {
      out.vertices[v->info()] = FromCgal(shape.classify(v, alpha));
      continue;
    }
    // Below 0, CGAL's own answer is off: it starts the largest alpha of a vertex's faces at 0
    // (initialize_interval_vertex_map), so a vertex whose faces are all born below 0 stays REGULAR
    // until 0. Its rule with the true maximum, over the same faces and alphas:
    bool hull = false, any_face = false;
    FT low = FT(0), high = FT(0);
    auto face = shape.incident_faces(v), done = face;
    do {
      if (shape.is_infinite(face)) {
        hull = true;
      } else {
        const FT a = face->get_alpha();
        low = any_face ? CGAL::min(low, a) : a;
        high = any_face ? CGAL::max(high, a) : a;
        any_face = true;
      }
    } while (++face != done);
    OracleClass cls = OracleClass::kSingular;
    if (any_face && alpha >= low) cls = hull || alpha < high ? OracleClass::kRegular : OracleClass::kInterior;
    out.vertices[v->info()] = cls;
  }
  for (auto f = shape.finite_faces_begin(); f != shape.finite_faces_end(); ++f) {
    if (shape.classify(f, alpha) == AlphaShape::INTERIOR) ++out.interior_triangles;
  }
  return out;
}

}  // namespace galpha::testing
