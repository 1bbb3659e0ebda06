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
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main)
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
    set_target_properties(${target} PROPERTIES CUDA_SEPARABLE_COMPILATION OFF POSITION_INDEPENDENT_CODE ON)
  endif()
endfunction()
