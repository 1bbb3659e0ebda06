#include "core/io/point_set_handle.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace galpha {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "handles hash doubles in their in-memory order, which must be little-endian");
static_assert(sizeof(Point2) == 2 * sizeof(double), "Point2 must be two packed doubles");

namespace {

// Changes whenever the meaning of a handle changes, so that old handles stop matching.
constexpr char kDomainTag[] = "galpha.v2.points";
constexpr char kWeightedDomainTag[] = "galpha.v2.weighted-points";
constexpr size_t kDigestBytes = 32;

/// SHA-256 of the concatenation of `parts`. Allocation failure of the 200-byte context is the
/// only way OpenSSL's digest calls fail here.
void Sha256(std::initializer_list<std::pair<const void*, size_t>> parts, unsigned char* digest) {
  EVP_MD_CTX* context = EVP_MD_CTX_new();
  if (context == nullptr || EVP_DigestInit_ex(context, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(context);
    throw std::bad_alloc();
  }
  for (const auto& [data, bytes] : parts) {
    if (bytes != 0) EVP_DigestUpdate(context, data, bytes);
  }
  unsigned int length = 0;
  EVP_DigestFinal_ex(context, digest, &length);
  EVP_MD_CTX_free(context);
}

/// The handle's tree over `total` bytes under `tag` (with its NUL).
template <size_t kTagBytes>
std::string TreeHandle(const unsigned char* bytes, uint64_t total, const char (&tag)[kTagBytes]) {
  const int64_t num_leaves = static_cast<int64_t>((total + kHandleLeafBytes - 1) / kHandleLeafBytes);
  std::vector<unsigned char> leaves(static_cast<size_t>(num_leaves) * kDigestBytes);
  const unsigned char leaf_prefix = 0;
  // A leaf is ~0.6 ms of one core: worth a parallel region from two leaves on.
#pragma omp parallel for schedule(dynamic) if (num_leaves > 1)
  for (int64_t i = 0; i < num_leaves; ++i) {
    const size_t begin = static_cast<size_t>(i) * kHandleLeafBytes;
    const size_t size = std::min<size_t>(kHandleLeafBytes, total - begin);
    Sha256({{&leaf_prefix, 1}, {bytes + begin, size}}, &leaves[static_cast<size_t>(i) * kDigestBytes]);
  }
  unsigned char root[kDigestBytes];
  Sha256({{tag, kTagBytes}, {&total, sizeof(total)}, {leaves.data(), leaves.size()}}, root);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string handle = "sha256-";
  for (unsigned char b : root) {
    handle += kHex[b >> 4];
    handle += kHex[b & 15];
  }
  return handle;
}

}  // namespace

std::string PointSetHandle(absl::Span<const Point2> points) {
  return TreeHandle(reinterpret_cast<const unsigned char*>(points.data()), points.size() * sizeof(Point2), kDomainTag);
}

std::string WeightedPointSetHandle(absl::Span<const Point2> points, absl::Span<const double> weights) {
  std::vector<double> triples(3 * points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    triples[3 * i] = points[i].x;
    triples[3 * i + 1] = points[i].y;
    triples[3 * i + 2] = i < weights.size() ? weights[i] : 0.0;
  }
  return TreeHandle(reinterpret_cast<const unsigned char*>(triples.data()), triples.size() * sizeof(double),
                    kWeightedDomainTag);
}

bool IsWellFormedHandle(const std::string& handle) {
  if (handle.size() != 7 + 64 || handle.compare(0, 7, "sha256-") != 0) return false;
  for (size_t i = 7; i < handle.size(); ++i) {
    const char c = handle[i];
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace galpha
