// The fixture of the engine's tests that run on every backend: parameterised by Backend, the CUDA
// instance skips where this build or machine has none. Tests derive from it (or alias it) and
// instantiate their suite with GALPHA_INSTANTIATE_BACKEND_TEST_SUITE, which names the instances
// Backends/<Suite>.<Test>/cpu and .../cuda.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "gpu/system/backend.hpp"

namespace galpha::testing {

class BackendTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::kCuda && !CudaBackendAvailable()) {
      GTEST_SKIP() << "no CUDA backend in this build, or no visible GPU";
    }
  }
};

/// The backend's name as a test parameter name: "cpu", "cuda".
inline std::string BackendParamName(const ::testing::TestParamInfo<Backend>& info) { return BackendName(info.param); }

}  // namespace galpha::testing

/// Instantiates the BackendTest suite `suite` on the CPU and the CUDA backend.
#define GALPHA_INSTANTIATE_BACKEND_TEST_SUITE(suite)                                                              \
  INSTANTIATE_TEST_SUITE_P(Backends, suite, ::testing::Values(::galpha::Backend::kCpu, ::galpha::Backend::kCuda), \
                           ::galpha::testing::BackendParamName)
