# Flags and helpers shared by every galpha target.

# Warnings are errors in our code; third-party headers come in as SYSTEM includes.
function(galpha_target_flags target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Werror -ffp-contract=off>
    # Expansion arithmetic must never be fused into FMAs on the device either.
    $<$<COMPILE_LANGUAGE:CUDA>:--fmad=false -Werror=all-warnings -Xcompiler=-Wall,-Wextra,-ffp-contract=off,-fopenmp --expt-relaxed-constexpr --extended-lambda>)
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR})
endfunction()

# Thrust/libcu++ headers for code that runs the engine's algorithms.
function(galpha_use_cccl target)
  target_include_directories(${target} SYSTEM PUBLIC ${GALPHA_CCCL_INCLUDE_DIR})
  # Plain C++ files see Thrust with OpenMP as the "device" system; .cu files keep CUDA's.
  target_compile_definitions(${target} PUBLIC
    $<$<COMPILE_LANGUAGE:CXX>:THRUST_DEVICE_SYSTEM=THRUST_DEVICE_SYSTEM_OMP>)
endfunction()

# galpha_add_test(NAME name SOURCES ... LIBS ...): a GoogleTest executable registered with CTest.
function(galpha_add_test)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  galpha_target_flags(${ARG_NAME})
  # A test's own sources compile at -O1 in Release builds (after CMake's -O3, so it wins): the code
  # under test is in the libraries, compiled at the build's level; GoogleTest's assertions and the
  # fixtures gain nothing from -O3, which took twice as long to compile them (alphactl_test.cpp:
  # 56 s against 28 s on the 2-core machine), and they are 63 of the 152 units CI compiles. The
  # header-only exact arithmetic the unit tests include runs at -O1 there: the same IEEE results
  # (no FMA contraction, no fast-math at any level), and the engine libraries that the family tests
  # exercise compile it at -O3.
  target_compile_options(${ARG_NAME} PRIVATE $<$<AND:$<CONFIG:Release>,$<COMPILE_LANGUAGE:CXX>>:-O1>)
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main)
  if(GALPHA_UNITY_TESTS)
    set_target_properties(${ARG_NAME} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 0)
  endif()
  add_test(NAME ${ARG_NAME} COMMAND ${ARG_NAME})
  set_tests_properties(${ARG_NAME} PROPERTIES ENVIRONMENT "GALPHA_DATA_DIR=${GALPHA_DATA_DIR}")
endfunction()

# The engine's libraries: Thrust for the OpenMP backend, and in CUDA builds the CUDA runtime
# (static) with whole-program compilation of each .cu file.
function(galpha_engine_library target)
  galpha_target_flags(${target})
  galpha_use_cccl(${target})
  target_link_libraries(${target} PRIVATE OpenMP::OpenMP_CXX)
  if(GALPHA_CUDA_ENABLED)
    target_link_libraries(${target} PRIVATE CUDA::cudart_static)
    set_target_properties(${target} PROPERTIES CUDA_SEPARABLE_COMPILATION OFF)
  endif()
endfunction()
