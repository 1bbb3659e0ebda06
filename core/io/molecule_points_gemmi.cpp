#include <gemmi/gz.hpp>
#include <gemmi/mmread.hpp>
#include <gemmi/modify.hpp>

#include <charconv>
#include <exception>
#include <limits>
#include <string>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "core/io/molecule_points.hpp"
#include "core/io/molecule_section.hpp"

namespace galpha {

namespace {

/// The van der Waals radius of `element` as the double nearest the decimal in gemmi's table
/// (which stores floats: 1.7f widened would be 1.7000000476837158, not 1.7); NaN for an element
/// gemmi does not know (El::X), for which its table holds 1.0 in place of a radius.
double VanDerWaalsRadius(gemmi::Element element) {
  if (element.elem == gemmi::El::X) return std::numeric_limits<double>::quiet_NaN();
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, element.vdw_r());  // shortest round trip
  double radius = std::numeric_limits<double>::quiet_NaN();
  if (written.ec == std::errc()) std::from_chars(text, written.ptr, radius);
  return radius;
}

}  // namespace

absl::StatusOr<GeoreferencedPoints> ReadMoleculePoints(const std::string& path, const MoleculeSection& section,
                                                       uint64_t max_points, std::vector<double>* radii) {
  const std::string named = absl::StrCat("structure file '", path, "'");
  gemmi::Structure structure;
  try {
    // gemmi reports bad input by exceptions; none may cross into galpha.
    structure = gemmi::read_structure(gemmi::MaybeGzipped(path));
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat(named, " cannot be read by gemmi: ", e.what()));
  }
  if (structure.models.empty()) return absl::InvalidArgumentError(absl::StrCat(named, " has no model"));
  gemmi::remove_alternative_conformations(structure);
  size_t atoms = 0;
  for (const gemmi::Chain& chain : structure.models.front().chains) {
    for (const gemmi::Residue& residue : chain.residues) atoms += residue.atoms.size();
  }
  // gemmi reads text that is no structure as an empty one: no atom at all is not a structure.
  if (atoms == 0) return absl::InvalidArgumentError(absl::StrCat(named, " has no atoms in its first model"));
  const SectionAxes axes = AxesOf(section);
  GeoreferencedPoints out;
  if (radii != nullptr) radii->clear();
  for (const gemmi::Chain& chain : structure.models.front().chains) {
    for (const gemmi::Residue& residue : chain.residues) {
      for (const gemmi::Atom& atom : residue.atoms) {
        const double xyz[3] = {atom.pos.x, atom.pos.y, atom.pos.z};
        if (!InSection(section, axes, xyz)) continue;
        if (out.points.size() == max_points) {
          return absl::ResourceExhaustedError(
              absl::StrCat(named, " has more than ", max_points, " atoms in the section: more than the limit"));
        }
        out.points.push_back({xyz[axes.u], xyz[axes.v]});
        if (radii != nullptr) radii->push_back(VanDerWaalsRadius(atom.element));
      }
    }
  }
  return out;
}

}  // namespace galpha
