// alphactl's command line: the usage text, option parsing, strict numbers and the threshold choice.
// Everything here reports mistakes as InvalidArgument statuses whose one-line message names the
// option and the value; the commands turn them into exit status kExitUsage.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "core/family/alpha_family.hpp"
#include "gpu/triangulation/delaunay.hpp"

namespace galpha::alphactl {

/// Exit statuses: success, a failure of the work (unreadable file, bad input), a usage error.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

/// The full usage text (every command and its options), ending in a newline.
extern const char kUsage[];

/// The options that apply to every command, accepted before the command too (as git's and
/// kubectl's are): --backend, --server, --tls-ca, --encoding, --max-points, --layer.
extern const absl::string_view kGlobalOptions[12];

/// The command line split at its command.
struct Invocation {
  std::string command;
  /// The global options given before the command, then the words after it, for ParseCommandLine:
  /// an option given on both sides is an option given twice.
  std::vector<std::string> args;
};

/// Finds the command in `argv` (the words after the program's name): the first word that is not
/// a global option or its value. Options take their values as in ParseCommandLine.
///
/// Errors (InvalidArgument): an option before the command that is not a global one (named, with
/// the global ones listed), a global option without its value, '--' or nothing where the command
/// should be.
absl::StatusOr<Invocation> SplitAtCommand(absl::Span<const std::string> argv);

/// One command's arguments, split. Option names are kept without their leading "--".
struct CommandLine {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;  // in the order given

  /// The value of option `name`, or nullptr when it was not given.
  const std::string* Find(absl::string_view name) const;
};

/// Splits `args` (the words after the command's name). Every option takes a value, written
/// `--name VALUE` or `--name=VALUE` (so a value may start with '-'); `--` ends the options.
/// `allowed` lists the option names `command` accepts. (-h and --help are main's, before this.)
///
/// Errors (InvalidArgument): an option not in `allowed`, an option without its value, an option
/// given twice.
absl::StatusOr<CommandLine> ParseCommandLine(absl::string_view command, absl::Span<const std::string> args,
                                             absl::Span<const absl::string_view> allowed);

/// The whole of `text` as a finite double (decimal or hexadecimal floating point, no spaces).
/// Errors name `--option` and the text: empty, trailing characters, NaN, infinity, overflow.
absl::StatusOr<double> ParseFiniteDouble(absl::string_view option, const std::string& text);

/// The whole of `text` as an integer in [min_value, INT64_MAX] (decimal digits, an optional '-').
absl::StatusOr<int64_t> ParseInteger(absl::string_view option, const std::string& text, int64_t min_value);

/// Which threshold the user named, in the unit they used.
struct ThresholdArg {
  enum class Kind { kAlphaSq, kAlpha, kRank, kRatio };
  Kind kind = Kind::kRank;
  double value = 0.0;  ///< alpha_sq for kAlphaSq, the radius for kAlpha, the area ratio for kRatio
  int64_t rank = 0;    ///< for kRank
};

/// Exactly one of --alpha-sq, --alpha (a radius, >= 0), --rank (>= 0) or --ratio (an area ratio in
/// 0..1).
absl::StatusOr<ThresholdArg> ParseThreshold(const CommandLine& line);

/// --max-points (default kDefaultMaxPoints of point_input.hpp): an integer in 1..kMaxPoints, the
/// engine's own limit (core/io/input_validation.hpp).
absl::StatusOr<uint64_t> ParseMaxPoints(const CommandLine& line);

/// --backend (default auto).
absl::StatusOr<Backend> ParseBackend(const CommandLine& line);
/// --mode general|regularized (default general).
absl::StatusOr<ClassifyMode> ParseMode(const CommandLine& line);
/// --vertex-rule report|cgal (default report).
absl::StatusOr<VertexRule> ParseVertexRule(const CommandLine& line);

const char* ModeName(ClassifyMode mode);
const char* VertexRuleName(VertexRule rule);

}  // namespace galpha::alphactl
