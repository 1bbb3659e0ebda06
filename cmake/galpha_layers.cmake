# Layers: every folder of core/ and gpu/ is one library target, and its link dependencies are the
# only folders its files may include. galpha_layer() records the folder and what it may use; a
# build-time check (check_layering.cmake) reads every file of the folder and fails the build on an
# include of a folder the layer does not depend on, so the dependency rules of
# docs/architecture.md hold by construction, not by review.

set(GALPHA_LAYER_CHECK_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/check_layering.cmake)

# galpha_layer(<target> [NO_CUDA] [USES <layer targets...>])
#   <target>  the library target of the calling folder (defined before this call).
#   USES      the layers it is built on; their folders (and theirs, transitively) may be included,
#             and the target links them PUBLIC.
#   NO_CUDA   the folder must not see CUDA: no .cu/.cuh files, no include of a .cuh header and no
#             CUDA, Thrust, CUB or libcu++ include (core/, server/, client/: they see the engine
#             through its CUDA-free .hpp headers only).
function(galpha_layer target)
  cmake_parse_arguments(ARG "NO_CUDA" "" "USES" ${ARGN})
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  set(allowed ${folder})
  foreach(dep IN LISTS ARG_USES)
    get_property(dep_allowed GLOBAL PROPERTY GALPHA_LAYER_ALLOWED_${dep})
    if(NOT dep_allowed)
      message(FATAL_ERROR "galpha_layer(${target}): ${dep} is not a layer declared before it")
    endif()
    list(APPEND allowed ${dep_allowed})
  endforeach()
  list(REMOVE_DUPLICATES allowed)
  set_property(GLOBAL PROPERTY GALPHA_LAYER_ALLOWED_${target} "${allowed}")

  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    target_link_libraries(${target} INTERFACE ${ARG_USES})
  else()
    target_link_libraries(${target} PUBLIC ${ARG_USES})
  endif()

  file(GLOB layer_files CONFIGURE_DEPENDS
       ${CMAKE_CURRENT_SOURCE_DIR}/*.hpp ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp
       ${CMAKE_CURRENT_SOURCE_DIR}/*.cuh ${CMAKE_CURRENT_SOURCE_DIR}/*.cu)
  set(stamp ${CMAKE_CURRENT_BINARY_DIR}/${target}.layering.stamp)
  string(REPLACE ";" "," allowed_arg "${allowed}")
  add_custom_command(
    OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DLAYER=${target} -DFOLDER=${folder} "-DALLOWED=${allowed_arg}"
            -DNO_CUDA=$<BOOL:${ARG_NO_CUDA}> -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DSTAMP=${stamp}
            -P ${GALPHA_LAYER_CHECK_SCRIPT}
    DEPENDS ${layer_files} ${GALPHA_LAYER_CHECK_SCRIPT}
    COMMENT "Checking the includes of layer ${target} (${folder})"
    VERBATIM)
  add_custom_target(${target}_layering ALL DEPENDS ${stamp})
  if(NOT type STREQUAL "INTERFACE_LIBRARY")
    add_dependencies(${target} ${target}_layering)
  endif()
endfunction()
