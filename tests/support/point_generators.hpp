// Deterministic point distributions for tests and benchmarks: every hard case of a Delaunay
// triangulation (STYLE.md item 13). Each generator is a pure function of (n, seed), built on
// std::mt19937_64, so a failure reproduces from its name, size and seed alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/base/point.hpp"

namespace galpha::gen {

/// Uniform in the unit square [0, 1)^2.
std::vector<Point2> Uniform(size_t n, uint64_t seed);

/// Standard normal in each coordinate.
std::vector<Point2> Gaussian(size_t n, uint64_t seed);

/// 100 tight gaussian clusters (sigma 1e-3) with centres uniform in the unit square.
std::vector<Point2> Clustered(size_t n, uint64_t seed);

/// The first n cells (row-major) of a ceil(sqrt(n))-wide integer grid, shuffled: every unit square
/// is an exactly co-circular quadruple and every row an exactly collinear run.
std::vector<Point2> Grid(size_t n, uint64_t seed);

/// Points (cos t, sin t) of the unit circle, built as mirror images (+-x, +-y) of random first-
/// quadrant angles, so that besides the near-co-circularity of the rounded circle, every four
/// mirror images are exactly co-circular (they form a rectangle).
std::vector<Point2> Circle(size_t n, uint64_t seed);

/// Uniform angle, radius uniform in [1, 1 + 1e-6]: an annulus far thinner than its diameter.
std::vector<Point2> ThinCircle(size_t n, uint64_t seed);

/// Half the points on each of two crossing lines, (3t, 2t + 5) and (s, 7 - 4s) for distinct random
/// integers t, s: long exactly collinear runs, crossing at (3/7, 37/7), between input points.
std::vector<Point2> TwoLines(size_t n, uint64_t seed);

/// Half the points on each of the parallel lines y = 2x and y = 2x + 3 (integer x): every triangle
/// spans both lines, with long runs of exactly collinear hull points.
std::vector<Point2> ParallelLines(size_t n, uint64_t seed);

/// Uniform in the unit square, with about 10% of the points exact repeats of earlier ones.
std::vector<Point2> WithDuplicates(size_t n, uint64_t seed);

/// Uniform in [0, 1000)^2 shifted by `offset` in both coordinates (1e9 leaves about 2^-23 of
/// resolution; 1e15 rounds to multiples of 0.125, so it also has duplicates and lattice structure).
std::vector<Point2> HugeOffset(size_t n, uint64_t seed, double offset);

/// Distinct points with coordinates near 1e-301 (random integers times 2^-1000) and, for half of
/// them, subnormal (random integers times 2^-1074). Products of such coordinates underflow, which
/// floating-point filters and naive expansions must survive.
std::vector<Point2> Tiny(size_t n, uint64_t seed);

/// A lattice as reprojection or unit conversion leaves it: the first n cells (row-major) of a
/// ceil(sqrt(n))-wide lattice of spacing 0.1 at offset (1000, 2000), each coordinate computed in
/// doubles and then moved by -2..2 units in the last place, shuffled. Millions of squared radii
/// agree to 40 bits and more: the spectrum's hardest near ties.
std::vector<Point2> UlpLattice(size_t n, uint64_t seed);

/// Airborne LiDAR as stored in LAS files: integer centimetres times 0.01 plus a UTM-like offset
/// (500000, 4000000), uniform over a 200 m tile (so exact repeats occur), computed in doubles.
std::vector<Point2> LidarCentimetres(size_t n, uint64_t seed);

/// A generator with the name tests print (SCOPED_TRACE) and benchmarks select by.
struct NamedGenerator {
  std::string name;
  std::function<std::vector<Point2>(size_t n, uint64_t seed)> generate;
  /// True when, except with negligible probability, no four distinct points are exactly
  /// co-circular and no three exactly collinear: then the Delaunay triangulation is unique and any
  /// two correct implementations agree edge for edge.
  bool general_position = false;
};

/// Every distribution above (HugeOffset twice: 1e9 and 1e15).
std::vector<NamedGenerator> AllDistributions();

/// The distribution named `name` in AllDistributions(), or nullptr.
const NamedGenerator* FindDistribution(const std::string& name);

/// A small fixed input with the name tests print.
struct NamedPoints {
  std::string name;
  std::vector<Point2> points;
};

/// The degenerate and tiny sets the engine's comparison tests share: a 60 x 45 integer grid (ties
/// everywhere) and the same with every third point removed, evenly spaced and spreading collinear
/// points, 1,500 uniform points each three times, and 0, 1, 1 twice, 2, 3 and 4 co-circular
/// points.
std::vector<NamedPoints> SmallDegenerateSets();

}  // namespace galpha::gen
