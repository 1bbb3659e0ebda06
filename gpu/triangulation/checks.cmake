# galpha_checks: the exact, engine-independent validator of a Triangulation that the tests use
# (triangulation_checks.hpp). Kept apart from the engine's library: nothing in the engine calls it.
add_library(galpha_checks STATIC
  ${CMAKE_CURRENT_LIST_DIR}/triangulation_checks.cpp
  ${CMAKE_CURRENT_LIST_DIR}/triangulation_checks.hpp)
galpha_target_flags(galpha_checks)
target_link_libraries(galpha_checks PUBLIC galpha_triangulation galpha_exact galpha_base absl::status absl::strings)
