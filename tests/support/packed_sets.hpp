// Point sets packed one after the other with their offsets, as TriangulateSets and
// BuildAlphaFamilies take them, with the names a failure prints; and the batches both tests pack
// (header only).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha::testing {

struct SetsToPack {
  std::vector<std::string> names;
  std::vector<Point2> points;
  std::vector<uint32_t> set_begin{0};

  void Add(std::string name, const std::vector<Point2>& set) {
    names.push_back(std::move(name));
    points.insert(points.end(), set.begin(), set.end());
    set_begin.push_back(static_cast<uint32_t>(points.size()));
  }
  /// Set s's points.
  absl::Span<const Point2> Set(size_t s) const {
    return absl::Span<const Point2>(points.data() + set_begin[s], set_begin[s + 1] - set_begin[s]);
  }
};

/// Every generator at each size, each set with its own seed.
inline SetsToPack SetsOfEveryGenerator(const std::vector<size_t>& sizes) {
  SetsToPack sets;
  uint64_t seed = 1;
  for (const gen::NamedGenerator& g : gen::AllDistributions()) {
    for (const size_t n : sizes) sets.Add(g.name + " n=" + std::to_string(n), g.generate(n, seed++));
  }
  return sets;
}

/// The shared degenerate sets, sets on one line (a chain, no mesh) between sets with meshes, a set
/// of one point repeated and an empty set.
inline SetsToPack DegenerateSetsAndChains() {
  SetsToPack sets;
  for (const gen::NamedPoints& p : gen::SmallDegenerateSets()) sets.Add(p.name, p.points);
  std::vector<Point2> line, diagonal;
  for (int i = 0; i < 40; ++i) line.push_back({0.25 * i, 3.0});
  for (int i = 0; i < 25; ++i) diagonal.push_back({i * 1.0, i * 2.0 + 1.0});
  sets.Add("horizontal line", line);
  sets.Add("uniform", gen::Uniform(500, 9));
  sets.Add("diagonal line", diagonal);
  sets.Add("one point four times", std::vector<Point2>(4, Point2{2.0, -1.0}));
  sets.Add("empty", {});
  return sets;
}

/// No set with a mesh: every one on a line, or of at most two distinct points.
inline SetsToPack SetsWithoutAMesh() {
  SetsToPack sets;
  std::vector<Point2> vertical, repeated_pair;
  for (int i = 0; i < 30; ++i) vertical.push_back({-2.0, 0.125 * (i % 17) + i});
  for (int i = 0; i < 9; ++i) repeated_pair.push_back(i % 2 == 0 ? Point2{1.0, 1.0} : Point2{3.0, -5.0});
  sets.Add("vertical line", vertical);
  sets.Add("empty", {});
  sets.Add("two points, repeated", repeated_pair);
  sets.Add("one point", {Point2{0.5, 0.5}});
  return sets;
}

/// Fifty sets of three points, each its own first triangle (nothing left to insert in any set).
inline SetsToPack SetsOfThreePoints() {
  SetsToPack sets;
  for (int s = 0; s < 50; ++s) {
    const double d = 1.0 + s;
    sets.Add("triangle " + std::to_string(s), {Point2{0.0, 0.0}, Point2{d, s % 2 == 0 ? 0.0 : 1.0}, Point2{0.0, d}});
  }
  return sets;
}

/// Each set's own scaling: tiny coordinates beside an offset of 1e15, ordinary ones, and the
/// same uniform points moved.
inline SetsToPack SetsOfVeryDifferentMagnitudes() {
  SetsToPack sets;
  sets.Add("tiny", gen::Tiny(800, 3));
  sets.Add("huge offset 1e15", gen::HugeOffset(800, 4, 1e15));
  sets.Add("uniform", gen::Uniform(800, 5));
  sets.Add("tiny again", gen::Tiny(300, 6));
  std::vector<Point2> shifted = gen::Uniform(800, 5);
  for (Point2& q : shifted) q = {q.x + 1024.0, q.y - 4096.0};
  sets.Add("the same uniform points shifted", shifted);
  return sets;
}

/// A batch as issue 20's users send it: `count` features of 20 to 299 points, every kind.
inline SetsToPack SmallSetsOfEveryKind(uint32_t count) {
  SetsToPack sets;
  const std::vector<gen::NamedGenerator> generators = gen::AllDistributions();
  for (uint32_t s = 0; s < count; ++s) {
    const gen::NamedGenerator& g = generators[s % generators.size()];
    const size_t n = 20 + (s * 37) % 280;
    sets.Add(g.name + " n=" + std::to_string(n), g.generate(n, 1000 + s));
  }
  return sets;
}

}  // namespace galpha::testing
