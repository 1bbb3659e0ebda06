// galpha._engine.SimplexSectionReader: the compact Classify chunks' data section
// (proto/sections/simplex_sections.hpp) decoded in C++ for the package's network client
// (python/src/galpha/_wire.py), which parses the few fields around it itself. The NumPy decoder
// there stays for installs without this module; both give the same arrays and the same refusals.
#pragma once

#include <pybind11/pybind11.h>

namespace galpha::python {

/// Adds SimplexSectionReader to `module`.
void RegisterSimplexSectionReader(pybind11::module_& module);

}  // namespace galpha::python
