// What the query_answers_test files share: the families every test runs on (built once, on the
// CPU backend, from every kind of input the service must handle), a large family whose answers span
// several messages, thresholds of every kind, and draining a chunk source.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/family/alpha_family.hpp"
#include "galpha/v1/alpha_shapes.pb.h"
#include "server/cached_family.hpp"
#include "server/query_answers.hpp"

namespace galpha::server::testing {

/// A family in one of the forms the service caches (`cached`: in host memory, or resident), and
/// the same points' family in host memory, which the tests read their expectations from.
struct NamedFamily {
  std::string name;
  std::shared_ptr<const CachedFamily> cached;
  std::shared_ptr<const AlphaFamily> oracle;
};

/// Points (i, 2i + 1) in shuffled order: exactly collinear, so edges only.
std::vector<Point2> OneLine(size_t n, uint64_t seed);

/// The families every test runs on, built once: uniform, a grid, duplicates, two crossing lines,
/// one line, and 0, 1, 2 (and 2 equal) points, each in host memory and resident ("NAME/resident").
const std::vector<NamedFamily>& Families();

/// Enough points that every kind of Classify chunk, and the master list, span several messages.
std::shared_ptr<const CachedFamily> LargeFamily();

v1::Threshold Rank(int64_t rank);
v1::Threshold AlphaSq(double alpha_sq);
v1::Threshold Alpha(double alpha);
v1::Threshold Ratio(double ratio);

/// ResolveLevel on a family in host memory (the tests' expectations).
absl::StatusOr<ResolvedLevel> ResolveOn(const AlphaFamily& family, const v1::Threshold& threshold);

/// Thresholds of every kind that hit interesting levels of `family`.
std::vector<v1::Threshold> Thresholds(const AlphaFamily& family);

/// Every message of `source`, which must end (and stay ended).
template <typename Message>
std::vector<Message> Drain(ChunkSource<Message>& source) {
  std::vector<Message> messages;
  Message message;
  while (source.Next(&message)) {
    messages.push_back(message);
    if (messages.size() > 100000) {
      ADD_FAILURE() << "the source does not end";
      break;
    }
  }
  EXPECT_FALSE(source.Next(&message)) << "a finished source stays finished";
  return messages;
}

}  // namespace galpha::server::testing
