#include "bench/bench_options.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/io/point_formats.hpp"
#include "tests/support/point_generators.hpp"
#include "tests/support/weight_generators.hpp"

namespace galpha {

absl::StatusOr<BenchOptions> ParseBenchArgs(int argc, char** argv, const char* competitor_max_flag) {
  BenchOptions options;
  for (const gen::NamedGenerator& generator : gen::AllDistributions()) options.distributions.push_back(generator.name);
  bool explicit_generated = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value_of = [&](const std::string& flag) -> const char* {
      return arg.rfind(flag + "=", 0) == 0 ? argv[i] + flag.size() + 1 : nullptr;
    };
    if (const char* v = value_of("--backend")) {
      const std::string name = v;
      if (name == "auto") {
        options.backend = Backend::kAuto;
      } else if (name == "cpu") {
        options.backend = Backend::kCpu;
      } else if (name == "cuda") {
        options.backend = Backend::kCuda;
      } else {
        return absl::InvalidArgumentError(absl::StrCat("unknown backend '", name, "'"));
      }
    } else if (const char* v = value_of("--repeat")) {
      if (!absl::SimpleAtoi(v, &options.repeat) || options.repeat < 1) {
        return absl::InvalidArgumentError(absl::StrCat("bad --repeat '", v, "'"));
      }
    } else if (const char* v = value_of("--seed")) {
      if (!absl::SimpleAtoi(v, &options.seed)) return absl::InvalidArgumentError(absl::StrCat("bad --seed '", v, "'"));
    } else if (const char* v = competitor_max_flag != nullptr ? value_of(competitor_max_flag) : nullptr) {
      if (!absl::SimpleAtoi(v, &options.competitor_max)) {
        return absl::InvalidArgumentError(absl::StrCat("bad ", competitor_max_flag, " '", v, "'"));
      }
    } else if (const char* v = value_of("--sizes")) {
      options.sizes.clear();
      for (absl::string_view part : absl::StrSplit(v, ',', absl::SkipEmpty())) {
        size_t n;
        if (!absl::SimpleAtoi(part, &n)) return absl::InvalidArgumentError(absl::StrCat("bad size '", part, "'"));
        options.sizes.push_back(n);
      }
      explicit_generated = true;
    } else if (const char* v = value_of("--dists")) {
      options.distributions = absl::StrSplit(v, ',', absl::SkipEmpty());
      for (const std::string& name : options.distributions) {
        if (gen::FindDistribution(name) == nullptr) {
          return absl::InvalidArgumentError(absl::StrCat("unknown distribution '", name, "'"));
        }
      }
      explicit_generated = true;
    } else if (arg == "--data" && i + 1 < argc) {
      options.data_files.emplace_back(argv[++i]);
    } else if (const char* v = value_of("--data")) {
      options.data_files.emplace_back(v);
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown argument '", arg, "'"));
    }
  }
  if (!options.data_files.empty() && !explicit_generated) options.distributions.clear();
  return options;
}

absl::Status ForEachBenchInput(
    const BenchOptions& options,
    const std::function<void(const std::string& name, const std::vector<Point2>& points)>& run) {
  for (const std::string& name : options.distributions) {
    for (size_t n : options.sizes) run(name, gen::FindDistribution(name)->generate(n, options.seed));
  }
  for (const std::string& file : options.data_files) {
    absl::StatusOr<std::vector<Point2>> points = ReadPointsFile(file);
    if (!points.ok()) return points.status();
    const size_t slash = file.find_last_of('/');
    run(slash == std::string::npos ? file : file.substr(slash + 1), *points);
  }
  return absl::OkStatus();
}

absl::Status TakeWeightsOption(int argc, char** argv, std::string* kind, std::vector<char*>* rest) {
  kind->clear();
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--weights=", 0) != 0) {
      rest->push_back(argv[i]);
      continue;
    }
    *kind = arg.substr(10);
    const std::vector<std::string> kinds = gen::WeightKinds();
    if (std::find(kinds.begin(), kinds.end(), *kind) == kinds.end()) {
      return absl::InvalidArgumentError(absl::StrCat("unknown --weights kind '", *kind, "'"));
    }
  }
  return absl::OkStatus();
}

absl::Status TakeSetsOption(int argc, char** argv, size_t* sets, size_t* points, std::vector<char*>* rest) {
  *sets = 0;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--sets=", 0) != 0) {
      rest->push_back(argv[i]);
      continue;
    }
    const std::string value = arg.substr(7);
    const size_t x = value.find('x');
    if (x == std::string::npos || !absl::SimpleAtoi(value.substr(0, x), sets) ||
        !absl::SimpleAtoi(value.substr(x + 1), points) || *sets == 0 || *points == 0) {
      return absl::InvalidArgumentError(absl::StrCat("--sets: '", value, "' is not SETSxPOINTS (e.g. 10000x1000)"));
    }
  }
  return absl::OkStatus();
}

void GenerateBenchSets(const gen::NamedGenerator& generator, size_t num_sets, size_t points_per_set, uint64_t seed,
                       std::vector<Point2>* points, std::vector<uint32_t>* set_begin) {
  points->clear();
  points->reserve(num_sets * points_per_set);
  set_begin->assign(1, 0);
  for (size_t s = 0; s < num_sets; ++s) {
    const std::vector<Point2> set = generator.generate(points_per_set, seed + s);
    points->insert(points->end(), set.begin(), set.end());
    set_begin->push_back(static_cast<uint32_t>(points->size()));
  }
}

std::string StageSummary(const std::vector<StageTime>& stages) {
  std::string out;
  for (const StageTime& stage : stages) {
    absl::StrAppend(&out, out.empty() ? "" : ", ", stage.stage, " ");
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.2f", stage.seconds * 1e3);
    absl::StrAppend(&out, ms);
  }
  return out;
}

void PrintPackedSetsRow(const PackedSetsRow& row) {
  std::string equal = row.sampled_equal ? "yes" : "NO: MISMATCH";
  if (row.sampled_equal && row.built_alone > 0) equal = absl::StrCat("yes (", row.built_alone, " built alone)");
  std::printf("| %s | %zux%zu | %s | %.1f | %.1f | %.2f | %.1f | %.1f | %.1f | %.1f | %s |\n", row.name.c_str(),
              row.num_sets, row.points_per_set, row.backend.c_str(), row.packed_ms, row.whole_ms,
              row.packed_ms / row.whole_ms, row.alone_ms, row.alone_ms / row.packed_ms, row.competitor_ms,
              row.competitor_ms / row.packed_ms, equal.c_str());
  std::printf("|  | stages (ms) | %s |||||||||\n", StageSummary(row.stages).c_str());
  std::fflush(stdout);
}

bool RunPackedSetsBench(const std::string& name, size_t num_sets, size_t points_per_set, const BenchOptions& options,
                        const PackedSetsCalls& calls) {
  constexpr size_t kSampledSets = 200;
  const gen::NamedGenerator* generator = gen::FindDistribution(name);
  std::vector<Point2> points;
  std::vector<uint32_t> set_begin;
  GenerateBenchSets(*generator, num_sets, points_per_set, options.seed, &points, &set_begin);
  const auto since = [](std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  PackedSetsRow row;
  row.name = name;
  row.num_sets = num_sets;
  row.points_per_set = points_per_set;
  row.packed_ms = row.whole_ms = std::numeric_limits<double>::infinity();
  for (int r = 0; r < options.repeat; ++r) {
    calls.release();  // the last run's result is freed outside the timing
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    if (!calls.packed(points, set_begin, &error)) {
      std::printf("| %s | %zux%zu | error: %s | | | | | | | |\n", name.c_str(), num_sets, points_per_set,
                  error.c_str());
      return false;
    }
    row.packed_ms = std::min(row.packed_ms, since(start));
  }
  {
    const std::vector<Point2> whole = generator->generate(num_sets * points_per_set, options.seed);
    for (int r = 0; r < options.repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      if (!calls.whole(whole)) return false;
      row.whole_ms = std::min(row.whole_ms, since(start));
    }
  }
  // The sampled sets one call each, and by the competitor; their packed results checked against their own.
  const size_t sampled = std::min(num_sets, kSampledSets);
  row.sampled_equal = true;
  for (size_t s = 0; s < sampled; ++s) {
    const absl::Span<const Point2> set(points.data() + set_begin[s], set_begin[s + 1] - set_begin[s]);
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < options.repeat; ++r) {
      bool equal = false;
      const auto start = std::chrono::steady_clock::now();
      if (!calls.alone(set, s, &equal)) return false;
      best = std::min(best, since(start));
      row.sampled_equal &= equal;
    }
    row.alone_ms += best;
    best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < calls.competitor_repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      calls.competitor(set);
      best = std::min(best, since(start));
    }
    row.competitor_ms += best;
  }
  const double scale = static_cast<double>(num_sets) / static_cast<double>(sampled);
  row.alone_ms *= scale;
  row.competitor_ms *= scale;
  calls.describe(&row);
  PrintPackedSetsRow(row);
  calls.release();
  return row.sampled_equal;
}

}  // namespace galpha
