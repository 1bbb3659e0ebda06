// A named, timed engine stage (plain C++: shared by the engine backends and the public API).
#pragma once

#include <string>

namespace galpha {

/// Wall-clock time of one named engine stage, in seconds.
struct StageTime {
  std::string stage;
  double seconds = 0.0;
};

}  // namespace galpha
