#include "core/family/area_ratio.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/base/status_macros.hpp"
#include "core/family/alpha_ranks.hpp"

namespace galpha {

namespace {

/// Coordinates as exact integers: every double is an integer multiple of 2^grid_log2 when
/// grid_log2 is the smallest ulp exponent among them, so a cross product x_a * y_b - x_b * y_a is
/// an integer times 2^(2 grid_log2), and sums of them are exact in mpz (faster than mpq, whose
/// every step reduces a fraction).
class IntegerCoordinates {
 public:
  explicit IntegerCoordinates(absl::Span<const Point2> points) {
    for (const Point2& p : points) {
      for (double v : {p.x, p.y}) {
        if (v != 0.0) grid_log2_ = std::min(grid_log2_, UlpExponent(v));
      }
    }
  }

  void Set(double v, mpz_class* out) const {
    if (v == 0.0) {
      *out = 0;
      return;
    }
    int exponent = 0;
    const double fraction = std::frexp(v, &exponent);
    *out = static_cast<long>(std::ldexp(fraction, 53));  // exact: an integer below 2^53
    *out <<= static_cast<mp_bitcnt_t>(exponent - 53 - grid_log2_);
  }

 private:
  /// v = m * 2^(exponent - 53) with an integer |m| < 2^53.
  static int UlpExponent(double v) {
    int exponent = 0;
    std::frexp(v, &exponent);
    return exponent - 53;
  }

  int grid_log2_ = std::numeric_limits<int>::max();
};

/// Twice the exact area of the regularized complex at `level`, in units of the coordinates' grid
/// squared: the shoelace sum over its boundary (edges with exactly one incident triangle in),
/// each edge directed as in that triangle, so that only the boundary's edges cost exact work.
mpz_class TwiceAreaExact(const AlphaFamily& family, int64_t level, const IntegerCoordinates& grid) {
  const AlphaRanks& r = family.ranks();
  auto in = [&](int32_t t) {
    return t >= 0 && r.tri_rank[static_cast<size_t>(t)] != kNeverRank &&
           static_cast<int64_t>(r.tri_rank[static_cast<size_t>(t)]) <= level;
  };
  mpz_class sum = 0, xa, ya, xb, yb;
  for (size_t e = 0; e < family.edges().size(); ++e) {
    const auto [t0, t1] = r.edge_triangles[e];
    const bool in0 = in(t0), in1 = in(t1);
    if (in0 == in1) continue;
    const std::array<uint32_t, 3>& tri = family.triangles()[static_cast<size_t>(in0 ? t0 : t1)];
    uint32_t a = family.edges()[e][0], b = family.edges()[e][1];
    const bool forward = (tri[0] == a && tri[1] == b) || (tri[1] == a && tri[2] == b) || (tri[2] == a && tri[0] == b);
    if (!forward) std::swap(a, b);
    const Point2 pa = family.points()[a], pb = family.points()[b];
    grid.Set(pa.x, &xa);
    grid.Set(pa.y, &ya);
    grid.Set(pb.x, &xb);
    grid.Set(pb.y, &yb);
    sum += xa * yb - xb * ya;
  }
  return abs(sum);
}

/// The first level L in [first, last) for which `holds(L)` is true, or `last` when none is;
/// `holds` must be false and then true as L grows (a binary search: O(log) calls).
template <class Predicate>
int64_t FirstLevelWhere(int64_t first, int64_t last, const Predicate& holds) {
  while (first < last) {
    const int64_t mid = first + (last - first) / 2;
    if (holds(mid)) {
      last = mid;
    } else {
      first = mid + 1;
    }
  }
  return first;
}

/// ratio = mantissa * 2^-shift, an integer mantissa below 2^53 and shift >= 52 (ratio in (0, 1]).
struct DyadicRatio {
  uint64_t mantissa = 0;
  int shift = 0;
};

DyadicRatio DyadicOf(double ratio) {
  int exponent = 0;
  const double fraction = std::frexp(ratio, &exponent);
  return {static_cast<uint64_t>(std::ldexp(fraction, 53)), 53 - exponent};
}

/// mantissa * x * 2^-shift rounded up (round_up) or down, in 128 bits (the product is below 2^117).
__int128 ScaleBy(const DyadicRatio& ratio, uint64_t x, bool round_up) {
  const unsigned __int128 product = static_cast<unsigned __int128>(ratio.mantissa) * x;
  if (ratio.shift >= 120) return round_up && product != 0 ? 1 : 0;
  const unsigned __int128 quotient = product >> ratio.shift;
  const bool exact = (quotient << ratio.shift) == product;
  return static_cast<__int128>(quotient) + (round_up && !exact ? 1 : 0);
}

}  // namespace

double RegularizedAreaApprox(const AlphaFamily& family, int64_t level) {
  const AlphaRanks& r = family.ranks();
  if (level < 0 || r.area_units.empty()) return 0.0;
  const size_t at = std::min(static_cast<size_t>(level), r.area_units.size() - 1);
  return std::ldexp(static_cast<double>(r.area_units[at]), r.area_scale.unit_log2);
}

double HullAreaApprox(const AlphaFamily& family) { return RegularizedAreaApprox(family, family.max_level()); }

absl::StatusOr<AreaRatioBracket> BracketAreaRatio(const AreaCurveReader& curve, double ratio) {
  if (!(ratio >= 0.0 && ratio <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("ratio ", ratio, " is outside 0..1 (the share of the convex hull's area the shape must cover)"));
  }
  const int64_t k = curve.max_level;
  if (ratio == 0.0) return AreaRatioBracket{-1, 0};     // every area is >= 0
  if (!curve.complete) return AreaRatioBracket{-1, k};  // level k always qualifies (ratio <= 1)
  const DyadicRatio dyadic = DyadicOf(ratio);
  // The filter: with exact areas X (in units) within E of the curve Q at every level,
  //   Q_L - E >= ratio (Q_K + E)  proves X_L >= ratio X_K, and
  //   Q_L + E <  ratio (Q_K - E)  proves X_L <  ratio X_K.
  // Both are monotone in L (Q never decreases): two binary searches bound the answer to (low, high].
  const __int128 error = static_cast<__int128>(curve.error_units);
  absl::Status read_failure;
  auto units = [&](int64_t level) -> __int128 {
    absl::StatusOr<uint64_t> value = curve.units_at(level);
    if (!value.ok()) {
      if (read_failure.ok()) read_failure = value.status();
      return 0;
    }
    return static_cast<__int128>(*value);
  };
  const __int128 hull = units(k);
  const __int128 need_up = ScaleBy(dyadic, static_cast<uint64_t>(hull) + curve.error_units, /*round_up=*/true);
  const __int128 need_down =
      hull >= error ? ScaleBy(dyadic, static_cast<uint64_t>(hull - error), /*round_up=*/false) : 0;
  auto surely_enough = [&](int64_t level) { return units(level) - error >= need_up; };
  auto surely_short = [&](int64_t level) { return units(level) + error < need_down; };
  AreaRatioBracket bracket;
  bracket.high = FirstLevelWhere(0, k, surely_enough);  // or k, which qualifies anyway
  // The largest surely-short level below it (surely_short holds, then fails, as L grows).
  bracket.low = FirstLevelWhere(0, bracket.high, [&](int64_t level) { return !surely_short(level); }) - 1;
  if (!read_failure.ok()) return read_failure;
  return bracket;
}

int64_t LevelForAreaRatioWithin(const AlphaFamily& family, double ratio, AreaRatioBracket bracket) {
  if (bracket.decided()) return bracket.high;
  // Undecided levels: exact areas, by binary search in (low, high] (high qualifies).
  const DyadicRatio dyadic = DyadicOf(ratio);
  const IntegerCoordinates grid(absl::MakeConstSpan(family.points()));
  const mpz_class hull_times_mantissa =
      TwiceAreaExact(family, family.max_level(), grid) * mpz_class(static_cast<unsigned long>(dyadic.mantissa));
  auto exactly_enough = [&](int64_t level) {
    mpz_class twice = TwiceAreaExact(family, level, grid);
    twice <<= static_cast<mp_bitcnt_t>(dyadic.shift);
    return twice >= hull_times_mantissa;
  };
  return FirstLevelWhere(bracket.low + 1, bracket.high, exactly_enough);
}

absl::StatusOr<int64_t> LevelForAreaRatio(const AlphaFamily& family, double ratio) {
  const AlphaRanks& r = family.ranks();
  AreaCurveReader curve;
  curve.max_level = family.max_level();
  curve.complete = r.area_units.size() == static_cast<size_t>(curve.max_level) + 1;
  curve.error_units = r.area_scale.error_units;
  curve.units_at = [&r](int64_t level) -> absl::StatusOr<uint64_t> { return r.area_units[static_cast<size_t>(level)]; };
  GALPHA_ASSIGN_OR_RETURN(const AreaRatioBracket bracket, BracketAreaRatio(curve, ratio));
  return LevelForAreaRatioWithin(family, ratio, bracket);
}

}  // namespace galpha
