// alphactl's commands, each run on the words after its name and returning the exit status
// (cli_args.hpp: kExitOk, kExitFailure, kExitUsage), and what they share: loading a family with
// progress on standard error, resolving a threshold, one-line error reports.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "client/cli_args.hpp"
#include "core/alpha_family.hpp"
#include "core/point.hpp"

namespace galpha::alphactl {

using Args = absl::Span<const std::string>;

int RunTriangulate(Args args);
int RunSpectrum(Args args);
int RunClassify(Args args);
int RunSummary(Args args);
int RunShape(Args args);
int RunMasterList(Args args);
int RunOptimal(Args args);
int RunBench(Args args);

// ---- shared by the commands (command_support.cpp) ----

/// Prints "alphactl: MESSAGE (see 'alphactl --help')" on one line to stderr; returns kExitUsage.
int UsageError(const absl::Status& status);
/// A usage error that the help text would not fix (a rank outside this file's spectrum): prints
/// "alphactl: MESSAGE" on one line to stderr; returns kExitUsage.
int ArgumentError(const absl::Status& status);
/// Prints "alphactl: MESSAGE" on one line to stderr; returns kExitFailure.
int Failure(const absl::Status& status);

/// What every command parses first: its options, its one FILE and --backend.
struct CommonArgs {
  CommandLine line;
  std::string file;
  Backend backend = Backend::kAuto;
};
/// ParseCommandLine, then exactly one positional FILE and a valid --backend ("backend" is added to
/// `allowed`). Errors are usage errors.
absl::StatusOr<CommonArgs> ParseCommon(absl::string_view command, Args args,
                                       absl::Span<const absl::string_view> allowed);

/// ReadPointsFile, with a directory or an I/O exception reported as an error.
absl::StatusOr<std::vector<Point2>> ReadPoints(const std::string& file);

/// Reads FILE and builds its family; for 100000 points or more, reports each build phase on
/// stderr. `input_points` receives the number of points read.
absl::StatusOr<AlphaFamily> LoadFamily(const std::string& file, Backend backend, size_t* input_points);

/// A threshold resolved against a family: its level, and the alpha_sq it stands for (for a rank
/// K > 0 the published spectrum double spectrum[K-1]; 0 for rank 0; the given value for --alpha-sq;
/// R*R rounded to a double for --alpha R).
struct ResolvedThreshold {
  int64_t level = 0;
  double alpha_sq = 0.0;
};
/// Errors (InvalidArgument, for ArgumentError): a rank outside 0..K.
absl::StatusOr<ResolvedThreshold> ResolveThreshold(const AlphaFamily& family, const ThresholdArg& threshold);

/// The alpha_sq of level `level` >= 0 as published: spectrum[level - 1], 0 for level 0.
double LevelAlphaSq(const AlphaFamily& family, int64_t level);

}  // namespace galpha::alphactl
