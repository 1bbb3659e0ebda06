// The command-line options both benchmarks share (delaunay_bench, alpha_bench).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "gpu/triangulation/delaunay.hpp"

namespace galpha {

struct BenchOptions {
  Backend backend = Backend::kAuto;
  int repeat = 3;
  std::vector<size_t> sizes = {100000, 1000000};
  /// Every generator of tests/support/point_generators.hpp unless --dists names some.
  std::vector<std::string> distributions;
  uint64_t seed = 1;
  std::vector<std::string> data_files;
  /// Largest input CGAL runs on (alpha_bench only: CGAL's alpha shapes take tens of seconds at 1M).
  size_t cgal_max = 1000000;
};

/// Parses --backend=, --repeat=, --seed=, --sizes=, --dists=, --data FILE (or --data=FILE) and,
/// when `accept_cgal_max`, --cgal-max=. With --data and no --sizes/--dists, only the files run.
absl::StatusOr<BenchOptions> ParseBenchArgs(int argc, char** argv, bool accept_cgal_max);

}  // namespace galpha
