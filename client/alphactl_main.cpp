// alphactl: galpha on the command line, working locally with no server (the embedded engine).
//
//   alphactl [GLOBAL OPTIONS] COMMAND FILE [OPTIONS]   (alphactl --help lists them: cli_args.cpp)
//
// Output is for scripts (docs/design.md, "Formats"): JSON on one line, or one simplex or value per line.
// Errors are one line on standard error starting with "alphactl: ", and a non-zero exit status:
// 2 for a usage error, 1 for a failure (unreadable file, bad input).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "client/cli_args.hpp"
#include "client/commands.hpp"

namespace {

struct Command {
  absl::string_view name;
  int (*run)(galpha::alphactl::Args args);
};

constexpr Command kCommands[] = {
    {"triangulate", galpha::alphactl::RunTriangulate},
    {"spectrum", galpha::alphactl::RunSpectrum},
    {"classify", galpha::alphactl::RunClassify},
    {"summary", galpha::alphactl::RunSummary},
    {"shape", galpha::alphactl::RunShape},
    {"masterlist", galpha::alphactl::RunMasterList},
    {"optimal", galpha::alphactl::RunOptimal},
    {"persistence", galpha::alphactl::RunPersistence},
    {"holes", galpha::alphactl::RunHoles},
    {"bench", galpha::alphactl::RunBench},
};

/// -h or --help anywhere before "--".
bool AsksForHelp(const std::vector<std::string>& args) {
  for (const std::string& arg : args) {
    if (arg == "--") return false;
    if (arg == "-h" || arg == "--help") return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = galpha::alphactl;
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fputs(cli::kUsage, stdout);
    return cli::kExitUsage;
  }
  if (AsksForHelp(args)) {
    std::fputs(cli::kUsage, stdout);
    return cli::kExitOk;
  }
  // Global options may come before the command: they are handed to it with its own words.
  auto invocation = cli::SplitAtCommand(args);
  if (!invocation.ok()) return cli::UsageError(invocation.status());
  if (invocation->command == "help") {
    std::fputs(cli::kUsage, stdout);
    return cli::kExitOk;
  }
  for (const Command& command : kCommands) {
    if (invocation->command != command.name) continue;
    // The engine reports its errors as statuses; anything thrown past it is still one line.
    try {
      return command.run(invocation->args);
    } catch (const std::exception& e) {
      return cli::Failure(absl::InternalError(absl::StrCat(invocation->command, " failed: ", e.what())));
    }
  }
  return cli::UsageError(absl::InvalidArgumentError(absl::StrCat("unknown command '", invocation->command, "'")));
}
