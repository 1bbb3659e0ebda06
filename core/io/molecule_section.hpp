// The plane and slab of a molecular section (molecule_points.hpp), shared by the reader and its
// build without gemmi.
#pragma once

#include "core/io/molecule_points.hpp"

namespace galpha {

/// Indices (0 x, 1 y, 2 z) of the plane's two axes and of the third.
struct SectionAxes {
  int u = 0, v = 1, w = 2;
};

inline SectionAxes AxesOf(const MoleculeSection& section) {
  if (section.plane == "yz") return {1, 2, 0};
  if (section.plane == "zx") return {2, 0, 1};
  return {0, 1, 2};
}

inline bool InSection(const MoleculeSection& section, const SectionAxes& axes, const double* xyz) {
  return !section.slab || (xyz[axes.w] >= section.slab->first && xyz[axes.w] <= section.slab->second);
}

}  // namespace galpha
