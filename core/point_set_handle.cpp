#include "core/point_set_handle.hpp"

#include <openssl/evp.h>

#include <cstdint>
#include <stdexcept>

namespace galpha {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "handles hash doubles in their in-memory order, which must be little-endian");
static_assert(sizeof(Point2) == 2 * sizeof(double), "Point2 must be two packed doubles");

namespace {
// Changes whenever the meaning of a handle changes, so that old handles stop matching.
constexpr char kDomainTag[] = "galpha.v1.points";
}  // namespace

struct PointSetHasher::State {
  EVP_MD_CTX* context = nullptr;
};

PointSetHasher::PointSetHasher() : state_(std::make_unique<State>()) {
  state_->context = EVP_MD_CTX_new();
  // Allocation failure of a 200-byte context is the only way these fail.
  if (state_->context == nullptr || EVP_DigestInit_ex(state_->context, EVP_sha256(), nullptr) != 1) {
    throw std::bad_alloc();
  }
  EVP_DigestUpdate(state_->context, kDomainTag, sizeof(kDomainTag));
}

PointSetHasher::~PointSetHasher() {
  if (state_ && state_->context != nullptr) EVP_MD_CTX_free(state_->context);
}

void PointSetHasher::AddCoordinates(absl::Span<const double> coordinates) {
  if (!coordinates.empty()) EVP_DigestUpdate(state_->context, coordinates.data(), coordinates.size() * sizeof(double));
}

void PointSetHasher::AddPoints(absl::Span<const Point2> points) {
  if (!points.empty()) EVP_DigestUpdate(state_->context, points.data(), points.size() * sizeof(Point2));
}

std::string PointSetHasher::Finish() {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(state_->context, digest, &length);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string handle = "sha256-";
  for (unsigned int i = 0; i < length; ++i) {
    handle += kHex[digest[i] >> 4];
    handle += kHex[digest[i] & 15];
  }
  return handle;
}

std::string PointSetHandle(absl::Span<const Point2> points) {
  PointSetHasher hasher;
  hasher.AddPoints(points);
  return hasher.Finish();
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
