// The handle's hash tree, checked against the construction its header documents, computed here
// the slow way: whole buffers assembled byte by byte and hashed with OpenSSL's one-shot digest.
#include "core/io/point_set_handle.hpp"

#include <gtest/gtest.h>
#include <omp.h>
#include <openssl/evp.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace galpha {
namespace {

std::vector<unsigned char> Digest(const std::vector<unsigned char>& bytes) {
  std::vector<unsigned char> digest(EVP_MAX_MD_SIZE);
  unsigned int length = 0;
  EXPECT_EQ(EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr), 1);
  digest.resize(length);
  return digest;
}

/// The documented tree; with `weights`, over (x, y, w) triples under the weighted tag.
std::string DocumentedHandle(const std::vector<Point2>& points, const std::vector<double>* weights = nullptr) {
  const size_t per_point = weights != nullptr ? 3 : 2;
  std::vector<unsigned char> coordinates(points.size() * 8 * per_point);
  for (size_t i = 0; i < points.size(); ++i) {
    // Little-endian IEEE doubles, x then y (then w), written out byte by byte.
    for (size_t axis = 0; axis < per_point; ++axis) {
      uint64_t bits;
      const double value = axis == 0 ? points[i].x : (axis == 1 ? points[i].y : (*weights)[i]);
      std::memcpy(&bits, &value, 8);
      for (int b = 0; b < 8; ++b) {
        coordinates[8 * per_point * i + 8 * axis + b] = static_cast<unsigned char>(bits >> (8 * b));
      }
    }
  }
  const std::string tag = weights != nullptr ? "galpha.v2.weighted-points" : "galpha.v2.points";
  std::vector<unsigned char> root(tag.begin(), tag.end());
  root.push_back(0);
  const uint64_t total = coordinates.size();
  for (int b = 0; b < 8; ++b) root.push_back(static_cast<unsigned char>(total >> (8 * b)));
  for (size_t begin = 0; begin < coordinates.size(); begin += kHandleLeafBytes) {
    std::vector<unsigned char> leaf{0};
    leaf.insert(leaf.end(), coordinates.begin() + static_cast<ptrdiff_t>(begin),
                coordinates.begin() + static_cast<ptrdiff_t>(std::min(coordinates.size(), begin + kHandleLeafBytes)));
    const std::vector<unsigned char> digest = Digest(leaf);
    root.insert(root.end(), digest.begin(), digest.end());
  }
  std::string handle = "sha256-";
  char hex[3];
  for (unsigned char b : Digest(root)) {
    std::snprintf(hex, sizeof hex, "%02x", b);
    handle += hex;
  }
  return handle;
}

std::vector<Point2> Points(size_t n) {
  std::vector<Point2> points(n);
  for (size_t i = 0; i < n; ++i) points[i] = {0.5 * static_cast<double>(i) - 3.25, 1e9 + static_cast<double>(i % 977)};
  return points;
}

TEST(PointSetHandleTest, FollowsTheDocumentedHashTree) {
  constexpr size_t kPointsPerLeaf = kHandleLeafBytes / sizeof(Point2);
  for (size_t n : {size_t{0}, size_t{1}, size_t{7}, kPointsPerLeaf - 1, kPointsPerLeaf, kPointsPerLeaf + 1,
                   7 * kPointsPerLeaf / 2}) {
    const std::vector<Point2> points = Points(n);
    const std::string handle = PointSetHandle(points);
    EXPECT_EQ(handle, DocumentedHandle(points)) << n << " points";
    EXPECT_TRUE(IsWellFormedHandle(handle));
  }
}

TEST(PointSetHandleTest, WeightedHandlesCoverTheWeights) {
  for (size_t n : {size_t{0}, size_t{5}, kHandleLeafBytes / 24 + 3}) {
    const std::vector<Point2> points = Points(n);
    std::vector<double> weights(n);
    for (size_t i = 0; i < n; ++i) weights[i] = 0.25 * static_cast<double>(i % 13);
    const std::string handle = WeightedPointSetHandle(points, weights);
    EXPECT_EQ(handle, DocumentedHandle(points, &weights)) << n << " points";
    EXPECT_NE(handle, PointSetHandle(points));  // never an unweighted family's
    if (n == 0) continue;
    std::vector<double> changed = weights;
    changed.back() = std::nextafter(changed.back(), 10.0);
    EXPECT_NE(WeightedPointSetHandle(points, changed), handle);
  }
}

TEST(PointSetHandleTest, EveryBitOrderAndLengthCounts) {
  const std::vector<Point2> points = Points(300000);  // several leaves
  const std::string handle = PointSetHandle(points);
  std::vector<Point2> changed = points;
  changed.back().y = std::nextafter(changed.back().y, 2e9);
  EXPECT_NE(PointSetHandle(changed), handle);
  changed = points;
  std::swap(changed[5], changed[6]);
  EXPECT_NE(PointSetHandle(changed), handle);
  changed = points;
  changed.push_back(points.back());  // a duplicate still changes the handle: answers name indices
  EXPECT_NE(PointSetHandle(changed), handle);
  EXPECT_NE(PointSetHandle({}), PointSetHandle(absl::MakeConstSpan(points).subspan(0, 1)));
}

TEST(PointSetHandleTest, SameOnAnyNumberOfThreads) {
  const std::vector<Point2> points = Points(1000003);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::string one = PointSetHandle(points);
  omp_set_num_threads(8);
  const std::string eight = PointSetHandle(points);
  omp_set_num_threads(threads);
  EXPECT_EQ(one, eight);
  EXPECT_EQ(one, DocumentedHandle(points));
}

TEST(PointSetHandleTest, WellFormedHandles) {
  EXPECT_TRUE(IsWellFormedHandle("sha256-" + std::string(64, 'a')));
  EXPECT_FALSE(IsWellFormedHandle("sha256-" + std::string(63, 'a')));
  EXPECT_FALSE(IsWellFormedHandle("sha256-" + std::string(64, 'A')));
  EXPECT_FALSE(IsWellFormedHandle("sha512-" + std::string(64, 'a')));
  EXPECT_FALSE(IsWellFormedHandle(""));
}

}  // namespace
}  // namespace galpha
