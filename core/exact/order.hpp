// The answer of an exact comparison that runs in bounded buffers: the order of the two values, or
// kUndecided when the buffers or the exponent range do not suffice (the caller then asks an
// unbounded path). An enum rather than an int sign, so that "undecided" cannot pass for a sign.
#pragma once

#include "core/base/hd.hpp"

namespace galpha {

/// The order of a against b. The decided values are the sign of a - b, so that SignOf and
/// OrderOfSign are plain conversions.
enum class Order : int { kLess = -1, kEqual = 0, kGreater = 1, kUndecided = 2 };

/// The order from the sign of a - b (-1, 0 or 1).
GALPHA_HD constexpr Order OrderOfSign(int sign) { return static_cast<Order>(sign); }

/// The sign of a - b (-1, 0 or 1) for a decided order.
GALPHA_HD constexpr int SignOf(Order order) { return static_cast<int>(order); }

}  // namespace galpha
