// GALPHA_HD marks functions that run on the host and, when compiled by nvcc, on the device.
// One macro instead of bare __host__ __device__ so that plain C++ compilers see nothing.
#pragma once

#if defined(__CUDACC__)
#define GALPHA_HD __host__ __device__
#define GALPHA_FORCEINLINE __forceinline__
#define GALPHA_NOINLINE __noinline__
#else
#define GALPHA_HD
#define GALPHA_FORCEINLINE inline __attribute__((always_inline))
#define GALPHA_NOINLINE __attribute__((noinline))
#endif
