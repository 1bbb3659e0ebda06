// The command-line options the benchmarks share (delaunay_bench, alpha_bench, topology_bench).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "core/base/stage_time.hpp"
#include "gpu/triangulation/delaunay.hpp"
#include "tests/support/point_generators.hpp"

namespace galpha {

struct BenchOptions {
  Backend backend = Backend::kAuto;
  int repeat = 3;
  std::vector<size_t> sizes = {100000, 1000000};
  /// Every generator of tests/support/point_generators.hpp unless --dists names some.
  std::vector<std::string> distributions;
  uint64_t seed = 1;
  std::vector<std::string> data_files;
  /// Largest input the competitor runs on (alpha_bench's CGAL, --cgal-max; topology_bench's GUDHI,
  /// --gudhi-max): they take tens of seconds at 1M.
  size_t competitor_max = 1000000;
};

/// Parses --backend=, --repeat=, --seed=, --sizes=, --dists=, --data FILE (or --data=FILE) and,
/// when `competitor_max_flag` names one ("--cgal-max"), that flag. With --data and no
/// --sizes/--dists, only the files run.
absl::StatusOr<BenchOptions> ParseBenchArgs(int argc, char** argv, const char* competitor_max_flag);

/// Takes --weights=KIND (a kind of tests/support/weight_generators.hpp) out of argv, for the
/// benchmarks that build weighted inputs: the kind ("" without the flag) into *kind, every other
/// argument into *rest (ParseBenchArgs parses them). InvalidArgument for an unknown kind.
absl::Status TakeWeightsOption(int argc, char** argv, std::string* kind, std::vector<char*>* rest);

/// Takes --sets=SETSxPOINTS (the benchmarks of many sets in one build, issue 20) out of argv: the
/// counts into *sets and *points (0 sets without the flag), every other argument into *rest.
/// InvalidArgument for a value that is not two positive counts.
absl::Status TakeSetsOption(int argc, char** argv, size_t* sets, size_t* points, std::vector<char*>* rest);

/// `num_sets` sets of `points_per_set` points of `generator`, set s generated with seed + s, one
/// after the other in *points, with their offsets (num_sets + 1) in *set_begin.
void GenerateBenchSets(const gen::NamedGenerator& generator, size_t num_sets, size_t points_per_set, uint64_t seed,
                       std::vector<Point2>* points, std::vector<uint32_t>* set_begin);

/// Stage times as "name ms, name ms, ...", in milliseconds with two decimals.
std::string StageSummary(const std::vector<StageTime>& stages);

/// What the --sets benchmarks measure of one distribution (times in ms; the two last over a sample
/// of the sets, scaled to all of them).
struct PackedSetsRow {
  std::string name;
  size_t num_sets = 0, points_per_set = 0;
  std::string backend;
  double packed_ms = 0, whole_ms = 0, alone_ms = 0, competitor_ms = 0;
  bool sampled_equal = false;
  uint32_t built_alone = 0;
  std::vector<StageTime> stages;  // the packed build's
};

/// Prints the row (the columns: distribution, sets x points, backend, packed, all in one, packed /
/// all in one, one call a set, calls / packed, competitor, competitor / packed, sampled sets equal)
/// and the packed build's stages under it.
void PrintPackedSetsRow(const PackedSetsRow& row);

/// What a --sets benchmark times for one distribution (RunPackedSetsBench).
struct PackedSetsCalls {
  /// Builds all the sets in one packed call and keeps the result (for `alone`); false on failure,
  /// its message in *error.
  std::function<bool(const std::vector<Point2>& points, const std::vector<uint32_t>& set_begin, std::string* error)>
      packed;
  /// Frees the kept result (outside the timing).
  std::function<void()> release;
  /// Builds all the points as one set; false on failure.
  std::function<bool(const std::vector<Point2>& points)> whole;
  /// Builds set `s` alone; false on failure. *equal: whether it equals the kept result's set `s`.
  std::function<bool(absl::Span<const Point2> set, size_t s, bool* equal)> alone;
  /// The competitor's build of a set, timed best of `competitor_repeat`.
  std::function<void(absl::Span<const Point2> set)> competitor;
  int competitor_repeat = 1;
  /// The kept result's backend, sets built alone and stage times into the row.
  std::function<void(PackedSetsRow* row)> describe;
};

/// --sets for one distribution: SETS sets of POINTS points of it (GenerateBenchSets) in one packed
/// call (best of --repeat), against one call of SETS * POINTS points of it, one call a set and the
/// competitor a set (both over the first 200 sets, scaled to all); prints the row
/// (PrintPackedSetsRow). False on a failed call or a sampled set unlike its own build.
bool RunPackedSetsBench(const std::string& name, size_t num_sets, size_t points_per_set, const BenchOptions& options,
                        const PackedSetsCalls& calls);

/// Calls `run` with every input the options name: each distribution at each size (generated with
/// the seed), then each data file (named by its file name). An error reading a file stops there.
absl::Status ForEachBenchInput(
    const BenchOptions& options,
    const std::function<void(const std::string& name, const std::vector<Point2>& points)>& run);

}  // namespace galpha
