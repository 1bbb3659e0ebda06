// ResidentTablesOn<System>: a family's rank tables kept in its build's system memory after the
// build (resident_backend.hpp), and the queries that run there: classification of every simplex,
// the curves at a level and their searches, master-list and spectrum slices. Written once over
// the execution system (CpuSystem or CudaSystem) like the pipeline that fills it (alpha_impl.cuh).
#pragma once

#include <thrust/binary_search.h>
#include <thrust/find.h>
#include <thrust/for_each.h>
#include <thrust/functional.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/transform_reduce.h>

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/family/simplex_class.hpp"
#include "gpu/alpha/alpha_functors.cuh"
#include "gpu/alpha/persistence_backend.hpp"
#include "gpu/alpha/persistence_pairs.cuh"
#include "gpu/alpha/resident_backend.hpp"
#include "gpu/system/engine_system.cuh"

namespace galpha::detail {

/// Classes at one level of every simplex: ids 0..n-1 are input points, then edges, then triangles
/// (the rules of core/family/simplex_class.hpp, as AlphaFamily applies them).
struct ClassifyEverySimplex {
  const uint32_t* vertex_mu_low;
  const uint32_t* vertex_mu_high;
  const uint32_t* vertex_tri_low;
  const uint8_t* hidden;  // per input point; null when unweighted
  const uint32_t* edge_rho_rank;
  const uint32_t* edge_mu_low;
  const uint32_t* edge_mu_high;
  const uint32_t* tri_rank;
  uint32_t n, num_edges;
  int64_t level;
  ClassifyMode mode;
  VertexRule rule;
  SimplexClass* out;
  GALPHA_HD void operator()(uint32_t i) const {
    if (i < n) {
      out[i] = VertexClassAt(hidden != nullptr && hidden[i] != 0, vertex_mu_low[i], vertex_mu_high[i],
                             vertex_tri_low[i], level, mode, rule);
    } else if (i - n < num_edges) {
      const uint32_t e = i - n;
      out[i] = EdgeClassAt(edge_rho_rank[e], edge_mu_low[e], edge_mu_high[e], level, mode);
    } else {
      out[i] = TriangleClassAt(tri_rank[i - n - num_edges], level);
    }
  }
};

// ---- The shape's boundary at one level (ResidentTables::ShapeBoundaryAt) ----------------------------

/// Whether each triangle is in the shape's complex at `level` (INTERIOR, in either mode).
struct TriangleInComplex {
  const uint32_t* tri_rank;
  int64_t level;
  uint8_t* in;
  GALPHA_HD void operator()(uint32_t t) const {
    in[t] = TriangleClassAt(tri_rank[t], level) == SimplexClass::kInterior ? 1 : 0;
  }
};

// Relaxed atomic loads, stores and compare-and-swap on both backends (CUDA; GCC builtins on the
// host), for the pieces' union-find, whose threads read and write the same parents.
GALPHA_HD inline uint32_t LoadRelaxed(const uint32_t* p) {
#if defined(__CUDA_ARCH__)
  return *static_cast<const volatile uint32_t*>(p);
#else
  return __atomic_load_n(p, __ATOMIC_RELAXED);
#endif
}
GALPHA_HD inline void StoreRelaxed(uint32_t* p, uint32_t v) {
#if defined(__CUDA_ARCH__)
  *static_cast<volatile uint32_t*>(p) = v;
#else
  __atomic_store_n(p, v, __ATOMIC_RELAXED);
#endif
}
GALPHA_HD inline bool CompareAndSwap(uint32_t* p, uint32_t expected, uint32_t desired) {
#if defined(__CUDA_ARCH__)
  return atomicCAS(p, expected, desired) == expected;
#else
  return __atomic_compare_exchange_n(p, &expected, desired, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED);
#endif
}

/// The root of x's tree in `parent`, halving the path on the way. Concurrent unions only ever
/// point a root at another root and a non-root at one of its ancestors, so a read that another
/// thread has since changed still leads to the root.
GALPHA_HD inline uint32_t FindPieceRoot(uint32_t* parent, uint32_t x) {
  for (;;) {
    const uint32_t p = LoadRelaxed(parent + x);
    if (p == x) return x;
    const uint32_t grand = LoadRelaxed(parent + p);
    if (grand != p) StoreRelaxed(parent + x, grand);
    x = grand;
  }
}

/// Joins the pieces of triangles a and b: the larger root is hooked under the smaller (retried
/// when another thread hooked it first), so every root is its piece's smallest triangle id, and
/// the labels do not depend on the threads' order.
GALPHA_HD inline void UnitePieces(uint32_t* parent, uint32_t a, uint32_t b) {
  for (;;) {
    a = FindPieceRoot(parent, a);
    b = FindPieceRoot(parent, b);
    if (a == b) return;
    const uint32_t low = a < b ? a : b, high = a < b ? b : a;
    if (CompareAndSwap(parent + high, high, low)) return;
  }
}

/// Joins the two complex triangles of each edge between two of them (an edge of one piece).
struct JoinPiecesAcrossEdge {
  const EdgeTris* edge_triangles;
  const uint8_t* in;
  uint32_t* parent;
  GALPHA_HD void operator()(uint32_t e) const {
    const EdgeTris et = edge_triangles[e];
    if (et.t[0] >= 0 && et.t[1] >= 0 && in[et.t[0]] != 0 && in[et.t[1]] != 0) {
      UnitePieces(parent, static_cast<uint32_t>(et.t[0]), static_cast<uint32_t>(et.t[1]));
    }
  }
};

/// Each triangle's piece: its root (the piece's smallest triangle id), into an array of its own.
/// Not into `parent`: another thread's path halving may store an older ancestor over a root
/// written there, while every label here is final.
struct LabelPiece {
  uint32_t* parent;
  uint32_t* piece;
  GALPHA_HD void operator()(uint32_t t) const { piece[t] = FindPieceRoot(parent, t); }
};

/// An edge with a complex triangle on exactly one side (none: the hull's outside).
struct IsBoundaryEdge {
  const EdgeTris* edge_triangles;
  const uint8_t* in;
  GALPHA_HD bool operator()(uint32_t e) const {
    const EdgeTris et = edge_triangles[e];
    const bool in0 = et.t[0] >= 0 && in[et.t[0]] != 0, in1 = et.t[1] >= 0 && in[et.t[1]] != 0;
    return in0 != in1;
  }
};

/// A boundary edge's complex triangle and that triangle's piece.
struct BoundaryEdgeSide {
  const EdgeTris* edge_triangles;
  const uint8_t* in;
  const uint32_t* piece;
  const uint32_t* edges;  // the boundary edges' ids
  uint32_t* inside;
  uint32_t* inside_piece;
  GALPHA_HD void operator()(uint32_t i) const {
    const EdgeTris et = edge_triangles[edges[i]];
    const uint32_t t = static_cast<uint32_t>(et.t[0] >= 0 && in[et.t[0]] != 0 ? et.t[0] : et.t[1]);
    inside[i] = t;
    inside_piece[i] = piece[t];
  }
};

/// SINGULAR edges at a level (GENERAL mode: edges of the complex without a triangle of it).
struct IsSingularEdge {
  const uint32_t* edge_rho_rank;
  const uint32_t* edge_mu_low;
  const uint32_t* edge_mu_high;
  int64_t level;
  GALPHA_HD bool operator()(uint32_t e) const {
    return EdgeClassAt(edge_rho_rank[e], edge_mu_low[e], edge_mu_high[e], level, ClassifyMode::kGeneral) ==
           SimplexClass::kSingular;
  }
};

/// SINGULAR input points at a level (GENERAL mode, VertexRule::kReport: isolated points of the
/// complex; duplicates are the caller's to drop).
struct IsSingularVertex {
  const uint32_t* vertex_mu_low;
  const uint32_t* vertex_mu_high;
  const uint32_t* vertex_tri_low;
  const uint8_t* hidden;  // per input point; null when unweighted
  int64_t level;
  GALPHA_HD bool operator()(uint32_t v) const {
    return VertexClassAt(hidden != nullptr && hidden[v] != 0, vertex_mu_low[v], vertex_mu_high[v], vertex_tri_low[v],
                         level, ClassifyMode::kGeneral, VertexRule::kReport) == SimplexClass::kSingular;
  }
};

/// Whether a level's curve values are within the limits (b null: only a's).
struct CurvesWithin {
  const uint32_t* a;
  uint32_t max_a;
  const uint32_t* b;
  uint32_t max_b;
  GALPHA_HD bool operator()(uint32_t level) const { return a[level] <= max_a && (b == nullptr || b[level] <= max_b); }
};

/// A distinct point's first-triangle rank (0 for duplicates and hidden points: they do not count).
struct DistinctVertexTriLow {
  const uint32_t* representative;
  const uint8_t* hidden;  // null when unweighted
  const uint32_t* vertex_tri_low;
  GALPHA_HD uint32_t operator()(uint32_t v) const {
    if (representative[v] != v || (hidden != nullptr && hidden[v] != 0)) return 0;
    return vertex_tri_low[v];
  }
};

/// The tables the pipeline leaves behind, moved in by KeepResidentTables (alpha_impl.cuh).
template <class System>
struct ResidentTableBuffers {
  Buffer<double, System> spectrum;
  Buffer<uint32_t, System> spectrum_simplex, tri_rank, edge_rho_rank, edge_mu_low, edge_mu_high;
  Buffer<EdgeTris, System> edge_triangles;
  Buffer<uint32_t, System> vertex_mu_low, vertex_mu_high, vertex_tri_low;
  Buffer<uint8_t, System> hidden;  // weighted only
  Buffer<uint32_t, System> master_begin;
  Buffer<uint64_t, System> master;
  Buffer<uint32_t, System> components, solid_components, holes, regularized_components, regularized_holes;
  Buffer<unsigned long long, System> area_units;

  explicit ResidentTableBuffers(System& sys)
      : spectrum(sys, 0),
        spectrum_simplex(sys, 0),
        tri_rank(sys, 0),
        edge_rho_rank(sys, 0),
        edge_mu_low(sys, 0),
        edge_mu_high(sys, 0),
        edge_triangles(sys, 0),
        vertex_mu_low(sys, 0),
        vertex_mu_high(sys, 0),
        vertex_tri_low(sys, 0),
        hidden(sys, 0),
        master_begin(sys, 0),
        master(sys, 0),
        components(sys, 0),
        solid_components(sys, 0),
        holes(sys, 0),
        regularized_components(sys, 0),
        regularized_holes(sys, 0),
        area_units(sys, 0) {}
};

/// Sizes of the kept tables.
struct ResidentSizes {
  uint32_t n = 0, num_tri = 0, num_edges = 0, num_ranks = 0, num_master = 0;
  std::optional<int64_t> solid_level;
};

template <class System>
class ResidentTablesOn final : public ResidentTables {
 public:
  /// `owner` keeps what the system runs on alive (the CUDA stream; null on the CPU): it is
  /// released after the system and the tables.
  ResidentTablesOn(std::shared_ptr<void> owner, std::unique_ptr<System> system)
      : owner_(std::move(owner)), system_(std::move(system)), tables_(*system_) {}

  System& system() { return *system_; }
  ResidentTableBuffers<System>& tables() { return tables_; }
  void set_sizes(const ResidentSizes& sizes) { sizes_ = sizes; }

  size_t Bytes() const override {
    const ResidentTableBuffers<System>& t = tables_;
    return t.spectrum.size() * sizeof(double) +
           (t.spectrum_simplex.size() + t.tri_rank.size() + t.edge_rho_rank.size() + t.edge_mu_low.size() +
            t.edge_mu_high.size() + t.vertex_mu_low.size() + t.vertex_mu_high.size() + t.vertex_tri_low.size() +
            t.master_begin.size() + t.components.size() + t.solid_components.size() + t.holes.size() +
            t.regularized_components.size() + t.regularized_holes.size()) *
               sizeof(uint32_t) +
           t.edge_triangles.size() * sizeof(EdgeTris) + t.hidden.size() + t.master.size() * sizeof(uint64_t) +
           t.area_units.size() * sizeof(unsigned long long);
  }
  bool InDeviceMemory() const override { return !System::kHostMemory; }
  uint32_t num_ranks() const override { return sizes_.num_ranks; }
  uint64_t num_master() const override { return sizes_.num_master; }
  std::optional<int64_t> solid_level() const override { return sizes_.solid_level; }

  void Classify(int64_t level, ClassifyMode mode, VertexRule rule, SimplexClass* vertices, SimplexClass* edges,
                SimplexClass* triangles) override {
    System& sys = *system_;
    const ResidentTableBuffers<System>& t = tables_;
    const size_t total = size_t{sizes_.n} + sizes_.num_edges + sizes_.num_tri;
    Buffer<SimplexClass, System> classes(sys, total);
    thrust::for_each_n(sys.policy(), thrust::counting_iterator<uint32_t>(0), total,
                       ClassifyEverySimplex{t.vertex_mu_low.data(), t.vertex_mu_high.data(), t.vertex_tri_low.data(),
                                            t.hidden.size() > 0 ? t.hidden.data() : nullptr, t.edge_rho_rank.data(),
                                            t.edge_mu_low.data(), t.edge_mu_high.data(), t.tri_rank.data(), sizes_.n,
                                            sizes_.num_edges, level, mode, rule, classes.data()});
    sys.Download({{vertices, classes.data(), size_t{sizes_.n}},
                  {edges, classes.data() + sizes_.n, size_t{sizes_.num_edges}},
                  {triangles, classes.data() + sizes_.n + sizes_.num_edges, size_t{sizes_.num_tri}}});
  }

  ShapeBoundary ShapeBoundaryAt(int64_t level, ClassifyMode mode) override {
    System& sys = *system_;
    const ResidentTableBuffers<System>& t = tables_;
    const uint32_t num_tri = sizes_.num_tri, num_edges = sizes_.num_edges, n = sizes_.n;
    const thrust::counting_iterator<uint32_t> zero(0);
    ShapeBoundary out;
    Buffer<uint8_t, System> in(sys, num_tri);
    thrust::for_each_n(sys.policy(), zero, num_tri, TriangleInComplex{t.tri_rank.data(), level, in.data()});
    // The pieces: the complex's triangles joined across the edges between two of them.
    Buffer<uint32_t, System> parent(sys, num_tri), piece(sys, num_tri);
    thrust::sequence(sys.policy(), parent.data(), parent.data() + num_tri);
    thrust::for_each_n(sys.policy(), zero, num_edges,
                       JoinPiecesAcrossEdge{t.edge_triangles.data(), in.data(), parent.data()});
    thrust::for_each_n(sys.policy(), zero, num_tri, LabelPiece{parent.data(), piece.data()});
    Buffer<uint32_t, System> edges(sys, num_edges);
    const auto boundary = static_cast<size_t>(thrust::copy_if(sys.policy(), zero, zero + num_edges, edges.data(),
                                                              IsBoundaryEdge{t.edge_triangles.data(), in.data()}) -
                                              edges.data());
    Buffer<uint32_t, System> inside(sys, boundary), inside_piece(sys, boundary);
    thrust::for_each_n(sys.policy(), zero, boundary,
                       BoundaryEdgeSide{t.edge_triangles.data(), in.data(), piece.data(), edges.data(), inside.data(),
                                        inside_piece.data()});
    out.edges.resize(boundary);
    out.inside.resize(boundary);
    out.piece.resize(boundary);
    out.triangle_in_complex.resize(num_tri);
    std::vector<HostCopy> parts = {{out.edges.data(), edges.data(), boundary * sizeof(uint32_t)},
                                   {out.inside.data(), inside.data(), boundary * sizeof(uint32_t)},
                                   {out.piece.data(), inside_piece.data(), boundary * sizeof(uint32_t)},
                                   {out.triangle_in_complex.data(), in.data(), size_t{num_tri}}};
    Buffer<uint32_t, System> singular_edges(sys, mode == ClassifyMode::kGeneral ? num_edges : 0);
    Buffer<uint32_t, System> singular_vertices(sys, mode == ClassifyMode::kGeneral ? n : 0);
    if (mode == ClassifyMode::kGeneral) {
      const auto edge_count = static_cast<size_t>(
          thrust::copy_if(sys.policy(), zero, zero + num_edges, singular_edges.data(),
                          IsSingularEdge{t.edge_rho_rank.data(), t.edge_mu_low.data(), t.edge_mu_high.data(), level}) -
          singular_edges.data());
      const auto vertex_count = static_cast<size_t>(
          thrust::copy_if(sys.policy(), zero, zero + n, singular_vertices.data(),
                          IsSingularVertex{t.vertex_mu_low.data(), t.vertex_mu_high.data(), t.vertex_tri_low.data(),
                                           t.hidden.size() > 0 ? t.hidden.data() : nullptr, level}) -
          singular_vertices.data());
      out.singular_edges.resize(edge_count);
      out.singular_vertices.resize(vertex_count);
      parts.push_back({out.singular_edges.data(), singular_edges.data(), edge_count * sizeof(uint32_t)});
      parts.push_back({out.singular_vertices.data(), singular_vertices.data(), vertex_count * sizeof(uint32_t)});
    }
    // Nothing to copy for empty parts (their vectors may have no storage).
    parts.erase(std::remove_if(parts.begin(), parts.end(), [](const HostCopy& c) { return c.bytes == 0; }),
                parts.end());
    if (!parts.empty()) sys.Download(parts);
    return out;
  }

  CurveValues CurvesAt(int64_t level) override {
    System& sys = *system_;
    const auto at = static_cast<size_t>(level);
    CurveValues v;
    sys.Download({{&v.components, tables_.components.data() + at, sizeof(uint32_t)},
                  {&v.solid_components, tables_.solid_components.data() + at, sizeof(uint32_t)},
                  {&v.holes, tables_.holes.data() + at, sizeof(uint32_t)},
                  {&v.regularized_components, tables_.regularized_components.data() + at, sizeof(uint32_t)},
                  {&v.regularized_holes, tables_.regularized_holes.data() + at, sizeof(uint32_t)},
                  {&v.area_units, tables_.area_units.data() + at, sizeof(uint64_t)}});
    return v;
  }

  std::vector<CurveValues> CurvesBetween(int64_t first, int64_t last) override {
    const auto count = static_cast<size_t>(last - first + 1);
    std::vector<uint32_t> components(count), solid(count), holes(count), regularized(count), regularized_holes(count);
    std::vector<uint64_t> area(count);
    const auto at = static_cast<size_t>(first);
    system_->Download({{components.data(), tables_.components.data() + at, count * sizeof(uint32_t)},
                       {solid.data(), tables_.solid_components.data() + at, count * sizeof(uint32_t)},
                       {holes.data(), tables_.holes.data() + at, count * sizeof(uint32_t)},
                       {regularized.data(), tables_.regularized_components.data() + at, count * sizeof(uint32_t)},
                       {regularized_holes.data(), tables_.regularized_holes.data() + at, count * sizeof(uint32_t)},
                       {area.data(), tables_.area_units.data() + at, count * sizeof(uint64_t)}});
    std::vector<CurveValues> values(count);
    for (size_t i = 0; i < count; ++i) {
      values[i] = CurveValues{components[i], solid[i], holes[i], regularized[i], regularized_holes[i], area[i]};
    }
    return values;
  }

  std::optional<int64_t> FirstLevelWhere(int64_t from, FamilyCurve a, uint32_t max_a,
                                         std::optional<std::pair<FamilyCurve, uint32_t>> b) override {
    System& sys = *system_;
    const int64_t levels = int64_t{sizes_.num_ranks} + 1;
    if (from >= levels) return std::nullopt;
    const thrust::counting_iterator<uint32_t> first(static_cast<uint32_t>(from)), last(static_cast<uint32_t>(levels));
    const auto found = thrust::find_if(
        sys.policy(), first, last, CurvesWithin{Curve(a), max_a, b ? Curve(b->first) : nullptr, b ? b->second : 0u});
    if (found == last) return std::nullopt;
    return static_cast<int64_t>(*found);
  }

  std::vector<uint32_t> MasterBegins(int64_t first_rank, int64_t count) override {
    std::vector<uint32_t> begins(static_cast<size_t>(count));
    if (count > 0) {
      system_->Download({{begins.data(), tables_.master_begin.data() + first_rank, begins.size() * sizeof(uint32_t)}});
    }
    return begins;
  }

  std::vector<MasterEntry> MasterEntries(uint64_t position, uint64_t count) override {
    static_assert(sizeof(MasterEntry) == sizeof(uint64_t), "the packed entries are the list");
    std::vector<MasterEntry> entries(count);
    if (count > 0) {
      system_->Download({{entries.data(), tables_.master.data() + position, count * sizeof(uint64_t)}});
    }
    return entries;
  }

  std::vector<double> Spectrum(int64_t first, int64_t count) override {
    std::vector<double> values(static_cast<size_t>(count));
    if (count > 0) {
      system_->Download({{values.data(), tables_.spectrum.data() + first, values.size() * sizeof(double)}});
    }
    return values;
  }

  uint32_t SpectrumSimplex(int64_t index) override { return system_->Read(tables_.spectrum_simplex.data() + index); }

  std::pair<int64_t, int64_t> SpectrumIndicesBetween(double lo, double hi) override {
    System& sys = *system_;
    const double* begin = tables_.spectrum.data();
    const double* end = begin + sizes_.num_ranks;
    const int64_t first = thrust::lower_bound(sys.policy(), begin, end, lo) - begin;
    const int64_t last = thrust::upper_bound(sys.policy(), begin, end, hi) - begin;
    return {first, std::max(first, last)};
  }

  void Persistence(const PersistenceIn& mesh, bool host_finish, PersistenceOut* out) override {
    const ResidentTableBuffers<System>& t = tables_;
    PersistenceIn in = mesh;
    in.edge_tris = t.edge_triangles.data();
    in.edge_rho_rank = t.edge_rho_rank.data();
    in.edge_mu_low = t.edge_mu_low.data();
    in.tri_rank = t.tri_rank.data();
    if constexpr (System::kHostMemory) {
      PersistenceOnCpu(in, host_finish, out);
    } else {
      PersistenceOnCudaWithTables(in, host_finish, system_->stream(), out);
    }
  }

  void DownloadInto(AlphaRanks* out) override {
    const ResidentTableBuffers<System>& t = tables_;
    const size_t n = sizes_.n, num_tri = sizes_.num_tri, num_edges = sizes_.num_edges, levels = sizes_.num_ranks + 1;
    out->spectrum.resize(sizes_.num_ranks);
    out->spectrum_simplex.resize(sizes_.num_ranks);
    out->tri_rank.resize(num_tri);
    out->edge_rho_rank.resize(num_edges);
    out->edge_mu_low.resize(num_edges);
    out->edge_mu_high.resize(num_edges);
    out->edge_triangles.resize(num_edges);
    out->vertex_mu_low.resize(n);
    out->vertex_mu_high.resize(n);
    out->vertex_tri_low.resize(n);
    out->master_begin.resize(levels + 1);
    out->master.resize(sizes_.num_master);
    out->components.resize(levels);
    out->solid_components.resize(levels);
    out->holes.resize(levels);
    out->regularized_components.resize(levels);
    out->regularized_holes.resize(levels);
    out->area_units.resize(levels);
    system_->Download({{out->spectrum.data(), t.spectrum.data(), sizes_.num_ranks * sizeof(double)},
                       {out->spectrum_simplex.data(), t.spectrum_simplex.data(), sizes_.num_ranks * sizeof(uint32_t)},
                       {out->tri_rank.data(), t.tri_rank.data(), num_tri * sizeof(uint32_t)},
                       {out->edge_rho_rank.data(), t.edge_rho_rank.data(), num_edges * sizeof(uint32_t)},
                       {out->edge_mu_low.data(), t.edge_mu_low.data(), num_edges * sizeof(uint32_t)},
                       {out->edge_mu_high.data(), t.edge_mu_high.data(), num_edges * sizeof(uint32_t)},
                       {out->edge_triangles.data(), t.edge_triangles.data(), num_edges * sizeof(EdgeTris)},
                       {out->vertex_mu_low.data(), t.vertex_mu_low.data(), n * sizeof(uint32_t)},
                       {out->vertex_mu_high.data(), t.vertex_mu_high.data(), n * sizeof(uint32_t)},
                       {out->vertex_tri_low.data(), t.vertex_tri_low.data(), n * sizeof(uint32_t)},
                       {out->master_begin.data(), t.master_begin.data(), (levels + 1) * sizeof(uint32_t)},
                       {out->master.data(), t.master.data(), size_t{sizes_.num_master} * sizeof(uint64_t)},
                       {out->components.data(), t.components.data(), levels * sizeof(uint32_t)},
                       {out->solid_components.data(), t.solid_components.data(), levels * sizeof(uint32_t)},
                       {out->holes.data(), t.holes.data(), levels * sizeof(uint32_t)},
                       {out->regularized_components.data(), t.regularized_components.data(), levels * sizeof(uint32_t)},
                       {out->regularized_holes.data(), t.regularized_holes.data(), levels * sizeof(uint32_t)},
                       {out->area_units.data(), t.area_units.data(), levels * sizeof(uint64_t)}});
  }

 private:
  const uint32_t* Curve(FamilyCurve c) const {
    switch (c) {
      case FamilyCurve::kComponents:
        return tables_.components.data();
      case FamilyCurve::kSolidComponents:
        return tables_.solid_components.data();
      case FamilyCurve::kHoles:
        return tables_.holes.data();
      case FamilyCurve::kRegularizedComponents:
        return tables_.regularized_components.data();
      case FamilyCurve::kRegularizedHoles:
        return tables_.regularized_holes.data();
    }
    return nullptr;
  }

  // Destroyed in reverse: the tables (their frees queued on the system's stream), the system,
  // then what it runs on.
  std::shared_ptr<void> owner_;
  std::unique_ptr<System> system_;
  ResidentTableBuffers<System> tables_;
  ResidentSizes sizes_;
};

}  // namespace galpha::detail
