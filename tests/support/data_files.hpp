// Where the real point sets of data/ (data/README.md) are, for tests.
#pragma once

#include <string>
#include <vector>

namespace galpha::testdata {

/// The data directory: $GALPHA_DATA_DIR when set and non-empty, else the source tree's data/
/// (compiled in), so that a test binary also finds it when run outside ctest.
std::string DataDir();

/// Every `*.bin` points file in DataDir(), full paths, sorted by name.
std::vector<std::string> PointFiles();

}  // namespace galpha::testdata
