// Atoms of molecular structures (PDB, mmCIF) as plane points: a projection of the atoms onto a
// coordinate plane, or a section (a slab of the third axis), read with gemmi (Debian's
// gemmi-dev). gemmi is optional (GALPHA_WITH_GEMMI): a build without it has the same functions,
// which refuse every file saying so. Its own library, galpha_molecule_io, so that only what reads
// these files (alphactl) compiles gemmi.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/io/georeferenced_points.hpp"

namespace galpha {

/// Whether `extension` (lower case, with its dot) names a structure format ReadMoleculePoints
/// reads: .pdb, .ent (PDB), .cif, .mmcif (mmCIF), each also gzip-compressed (.pdb.gz: pass the
/// extension before .gz).
inline bool IsMoleculeExtension(absl::string_view extension) {
  return extension == ".pdb" || extension == ".ent" || extension == ".cif" || extension == ".mmcif";
}

/// Which plane the atoms are put in, and which of them.
struct MoleculeSection {
  /// The plane: "xy" (x, y; the default), "yz" (y, z) or "zx" (z, x), right-handed in each case.
  std::string plane = "xy";
  /// A section: only atoms whose third coordinate (z for xy, x for yz, y for zx) lies in
  /// [min, max]; nullopt: every atom (a projection).
  std::optional<std::pair<double, double>> slab;
};

/// Parses "xy", "yz" or "zx" and "MIN:MAX" (MIN <= MAX, finite) into a section; InvalidArgument
/// naming the option (--plane, --slab) otherwise.
absl::StatusOr<MoleculeSection> ParseMoleculeSection(const std::string* plane, const std::string* slab);

/// The atoms of the first model of the structure at `path` (format by content: PDB or mmCIF;
/// gzip-compressed files too), alternative conformations reduced to the first, as points of
/// `section`, in file order. Coordinates are the file's (ångström), each the double that gemmi
/// parses from the file's decimal text. No CRS (the points are not georeferenced). `radii`, when
/// given, gets each kept atom's radius: its element's van der Waals radius in gemmi's table
/// (Bondi's for the common elements: C 1.70, N 1.55, O 1.52, S 1.80 Å), as the double nearest
/// the table's decimal; NaN for an atom whose element gemmi does not know.
///
/// Errors name the file: InvalidArgument when this build has no gemmi, when gemmi cannot read
/// the file (its message attached), or when its first model has no atoms (a slab may keep none:
/// that is no error); ResourceExhausted when more than
/// `max_points` atoms are kept.
absl::StatusOr<GeoreferencedPoints> ReadMoleculePoints(const std::string& path, const MoleculeSection& section,
                                                       uint64_t max_points = std::numeric_limits<uint64_t>::max(),
                                                       std::vector<double>* radii = nullptr);

}  // namespace galpha
