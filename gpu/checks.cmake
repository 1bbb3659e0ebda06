# galpha_checks: the exact, engine-independent validator of a Triangulation that the tests use.
# Included from gpu/CMakeLists.txt (kept apart so that the engine's build file has one owner).
add_library(galpha_checks STATIC
  ${CMAKE_CURRENT_LIST_DIR}/triangulation_checks.cpp
  ${CMAKE_CURRENT_LIST_DIR}/triangulation_checks.hpp)
galpha_target_flags(galpha_checks)
target_link_libraries(galpha_checks
  PUBLIC galpha_engine galpha_exact galpha_core absl::status absl::strings)
