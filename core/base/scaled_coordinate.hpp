// The double a scaled integer coordinate stands for, as LAS point clouds (ASPRS LAS 1.4 R15,
// section 2.6) and the wire's integer point chunks (docs/design.md, "Wire encodings of points")
// define it: x = offset + scale * X in IEEE-754 binary64.
#pragma once

#include <cstdint>

namespace galpha {

/// offset + scale * X with two roundings: X converted to double (exact for |X| <= 2^53), the
/// product rounded to nearest-even, then the sum. Never one fused multiply-add, whose single
/// rounding gives another double for some inputs (scale 0.1, X 3, offset -0.3): every galpha
/// target is compiled with -ffp-contract=off (galpha_target_flags), and the unit tests
/// ScaledCoordinate.IsNeverFused and PointChunkCodec.ScaledValueIsNeverFused fail if it were fused.
inline double ScaledCoordinate(double offset, double scale, int64_t x) {
  return offset + scale * static_cast<double>(x);
}

}  // namespace galpha
