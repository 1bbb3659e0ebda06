// vector_file_writer.hpp in a build without GDAL: nothing is written.
#include "tests/support/vector_file_writer.hpp"

namespace galpha::testing {

bool VectorWriterAvailable() { return false; }

absl::Status WriteVectorFile(const std::string& /*path*/, const std::string& /*driver*/,
                             const std::vector<VectorLayer>& /*layers*/) {
  return absl::UnimplementedError("this build has no GDAL (GALPHA_WITH_GDAL=OFF)");
}

}  // namespace galpha::testing
