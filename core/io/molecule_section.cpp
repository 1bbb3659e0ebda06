#include <cmath>
#include <cstdlib>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/io/molecule_points.hpp"

namespace galpha {

namespace {

/// The whole of `text` as a finite double, else nullopt.
std::optional<double> FiniteNumber(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

absl::StatusOr<MoleculeSection> ParseMoleculeSection(const std::string* plane, const std::string* slab) {
  MoleculeSection section;
  if (plane != nullptr) {
    if (*plane != "xy" && *plane != "yz" && *plane != "zx") {
      return absl::InvalidArgumentError(absl::StrCat("--plane '", *plane, "' is not xy, yz or zx"));
    }
    section.plane = *plane;
  }
  if (slab != nullptr) {
    const size_t colon = slab->find(':');
    const std::optional<double> low = colon == std::string::npos ? std::nullopt : FiniteNumber(slab->substr(0, colon));
    const std::optional<double> high =
        colon == std::string::npos ? std::nullopt : FiniteNumber(slab->substr(colon + 1));
    if (!low || !high || *low > *high) {
      return absl::InvalidArgumentError(
          absl::StrCat("--slab '", *slab, "' is not MIN:MAX with finite numbers MIN <= MAX (angstrom)"));
    }
    section.slab = std::make_pair(*low, *high);
  }
  return section;
}

}  // namespace galpha
