#include "tests/support/data_files.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace galpha::testdata {

std::string DataDir() {
  const char* from_environment = std::getenv("GALPHA_DATA_DIR");
  if (from_environment != nullptr && from_environment[0] != '\0') return from_environment;
  return GALPHA_SOURCE_DATA_DIR;
}

std::vector<std::string> PointFiles() {
  std::vector<std::string> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir(), error)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bin") {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace galpha::testdata
