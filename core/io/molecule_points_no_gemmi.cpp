// Built without gemmi (GALPHA_WITH_GEMMI=OFF): structure files are refused by name.
#include "absl/strings/str_cat.h"
#include "core/io/molecule_points.hpp"

namespace galpha {

absl::StatusOr<GeoreferencedPoints> ReadMoleculePoints(const std::string& path, const MoleculeSection& /*section*/,
                                                       uint64_t /*max_points*/, std::vector<double>* /*radii*/) {
  return absl::InvalidArgumentError(absl::StrCat("structure file '", path,
                                                 "': this build has no gemmi (GALPHA_WITH_GEMMI=OFF), which reads "
                                                 "PDB and mmCIF files"));
}

}  // namespace galpha
