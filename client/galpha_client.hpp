// The C++ client library of galpha.v1.AlphaShapes: connect (plaintext or TLS, optional bearer
// token), build a point set (computing its handle locally and skipping the upload when the server
// already holds it), and run every query, with gRPC statuses returned as absl::Status.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/base/point.hpp"
#include "galpha/v1/alpha_shapes.grpc.pb.h"

namespace galpha::client {

struct ClientOptions {
  /// "host:port".
  std::string target;
  /// PEM root certificates: set turns TLS on.
  std::string tls_root_certs_pem;
  /// Sent as "authorization: Bearer TOKEN" when not empty.
  std::string bearer_token;
  /// Per-call deadline; zero: none.
  std::chrono::milliseconds deadline{0};
  /// Classify reads an answer as this many parts at once (ClassifyRequest.part_count), each call on
  /// a connection of its own, and hands it over in the order of one call: one stream carries about
  /// 1 GB/s on loopback, several about that each (bench/README.md). 1: one call; 0 (the default):
  /// half this machine's cores, at least 1 and at most 8 (on 2 cores shared with a server, parts
  /// only add work; on a 16-core host 8 parts read an answer 2.7x as fast as one call). At most 64;
  /// summary-only requests, and requests that name a part themselves, are one call.
  uint32_t classify_parts = 0;
};

/// The request header a gRPC-aware load balancer hashes on (deploy/k8s/envoy.yaml), so that a
/// handle's Build and queries reach the replica that holds it. Sent on every call with a handle.
inline constexpr char kHandleHeader[] = "x-galpha-handle";

/// Points per Build chunk: 1 MiB of doubles, well under gRPC's 4 MiB message limit.
inline constexpr size_t kPointsPerChunk = 65536;

/// The most parts a Classify answer is read in (ClientOptions::classify_parts; the server refuses
/// a part_count above it), and the most the default picks.
inline constexpr uint32_t kMaxClassifyParts = 64;
inline constexpr uint32_t kMaxDefaultClassifyParts = 8;

/// Most threads Build encodes chunks on at once (one chunk each).
inline constexpr size_t kMaxEncodingThreads = 8;

/// How Build sends the points (proto/galpha/v1/alpha_shapes.proto, EncodedPointChunk). Every
/// choice decodes to the same doubles, so the handle and the family are the same.
enum class PointEncoding {
  /// Per chunk, the smallest: exact scaled integers where the data has them, else float64, each
  /// with the transform that compresses best, zstd-compressed unless that grows it; else raw.
  kAuto,
  /// PointChunk doubles (16 bytes a point): what servers older than EncodedPointChunk accept.
  kRaw,
  /// Float64 bit patterns, the best transform, zstd.
  kFloat64Compressed,
  /// Exact scaled integers, uncompressed (InvalidArgument when a chunk's points have none).
  kScaledIntegers,
  /// Exact scaled integers, the best transform, zstd (InvalidArgument as kScaledIntegers).
  kScaledIntegersCompressed,
};

struct BuildResult {
  std::string handle;
  /// The server already held the family (nothing was computed).
  bool cached = false;
  /// The points were streamed (false when the handle was found before any upload).
  bool uploaded = false;
  /// Bytes of the stream's point messages as sent (their protobuf encoding, without gRPC's
  /// framing); 0 without an upload.
  uint64_t upload_bytes = 0;
  galpha::v1::BuildSummary summary;
};

struct BuildCallOptions {
  std::string name;
  /// Ask Describe first and skip the upload when the server holds the handle.
  bool skip_upload_if_cached = true;
  /// Called after each chunk with the number of points sent.
  std::function<void(uint64_t sent)> progress;
  PointEncoding encoding = PointEncoding::kAuto;
  /// zstd's level for compressed encodings (1..19; higher: smaller and slower to encode).
  int zstd_level = 3;
  /// BuildHeader.crs: the points' CRS, projected by the server when geographic (empty: planar).
  /// The Describe pre-check is skipped then (the handle is the projected points').
  std::string crs;
  /// Weighted points (BuildHeader.weighted): one weight per point, the squared radius of its disk
  /// (finite, possibly negative); empty: unweighted. Not owned: it must outlive the call. The
  /// handle then covers the weights (WeightedPointSetHandle). InvalidArgument, before anything is
  /// sent, for a count other than the points'.
  absl::Span<const double> weights;
};

/// One set of a BuildBatch call.
struct BatchSet {
  /// BuildHeader.name: the set's label (its feature or group id), echoed in its answer.
  std::string name;
  absl::Span<const Point2> points;
  /// Its weights (BuildCallOptions::weights); empty: unweighted.
  absl::Span<const double> weights;
};

struct BuildBatchCallOptions {
  PointEncoding encoding = PointEncoding::kAuto;
  int zstd_level = 3;
  /// Every set's BuildHeader.crs (empty: planar).
  std::string crs;
  /// Called after each set's points are sent with the number of sets sent.
  std::function<void(size_t sets_sent)> progress;
};

/// gRPC status to absl::Status (the codes are the same numbers).
absl::Status FromGrpc(const grpc::Status& status);

class AlphaClient {
 public:
  /// Does not contact the server (gRPC connects lazily); errors only for unreadable options.
  static absl::StatusOr<std::unique_ptr<AlphaClient>> Connect(const ClientOptions& options);

  absl::StatusOr<BuildResult> Build(absl::Span<const Point2> points, const BuildCallOptions& options = {});
  /// Many sets in one BuildBatch stream (proto: BuildBatch): one answer a set, in their order, each
  /// the set's BuildResult (handle, cached, summary; uploaded) or the error of its build alone. The
  /// call's own error (a set the server refused to read, named by its index and name; the
  /// connection) fails it whole. InvalidArgument, before anything is sent, for weights whose count
  /// is not their set's points' or more than 100,000 sets. Chunks are encoded on up to
  /// kMaxEncodingThreads threads ahead of the writes.
  absl::StatusOr<std::vector<absl::StatusOr<BuildResult>>> BuildBatch(absl::Span<const BatchSet> sets,
                                                                      const BuildBatchCallOptions& options = {});
  absl::StatusOr<galpha::v1::DescribeResponse> Describe(const std::string& handle);
  absl::StatusOr<galpha::v1::SpectrumResponse> Spectrum(const galpha::v1::SpectrumRequest& request);
  absl::StatusOr<galpha::v1::ComponentsResponse> Components(const galpha::v1::ComponentsRequest& request);
  absl::StatusOr<galpha::v1::OptimalAlphaResponse> OptimalAlpha(const galpha::v1::OptimalAlphaRequest& request);
  absl::StatusOr<galpha::v1::BettiResponse> Betti(const galpha::v1::BettiRequest& request);
  absl::StatusOr<galpha::v1::ReleaseResponse> Release(const std::string& handle);

  /// Server-streamed answers: `on_message` sees each message; an error it returns cancels the
  /// call and is returned.
  /// Classify's chunks arrive as the request's simplex_encoding asks; `on_message` always sees
  /// SimplexChunk messages (EncodedSimplexChunks are decoded first, an undecodable one fails the
  /// call with InvalidArgument naming it), so callers do not depend on the encoding. `wire_bytes`,
  /// when given, gets the protobuf bytes of the messages as they arrived.
  /// With ClientOptions::classify_parts above 1, the answer is read in that many parts at once and
  /// handed over in the same order and messages (client/classify_parts_merger.hpp); from a server
  /// that does not split answers, as one call's.
  absl::Status Classify(const galpha::v1::ClassifyRequest& request,
                        const std::function<absl::Status(const galpha::v1::ClassifyResponse&)>& on_message,
                        uint64_t* wire_bytes = nullptr);
  absl::Status MasterList(const galpha::v1::MasterListRequest& request,
                          const std::function<absl::Status(const galpha::v1::MasterListResponse&)>& on_message);
  absl::Status Shape(const galpha::v1::ShapeRequest& request,
                     const std::function<absl::Status(const galpha::v1::ShapeResponse&)>& on_message);
  absl::Status Persistence(const galpha::v1::PersistenceRequest& request,
                           const std::function<absl::Status(const galpha::v1::PersistenceResponse&)>& on_message);

  /// For callers that need more (tests, benchmarks): a context with the token and deadline set,
  /// and the handle in the routing header (kHandleHeader) when one is given.
  void PrepareContext(grpc::ClientContext* context, const std::string& handle = "") const;
  galpha::v1::AlphaShapes::Stub& stub() { return *stub_; }
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }

 private:
  template <typename Response, typename Request>
  absl::Status ReadStream(const std::string& handle,
                          std::unique_ptr<grpc::ClientReader<Response>> (galpha::v1::AlphaShapes::Stub::*call)(
                              grpc::ClientContext*, const Request&),
                          const Request& request, const std::function<absl::Status(const Response&)>& on_message);

  absl::Status ClassifyInParts(const galpha::v1::ClassifyRequest& request,
                               const std::function<absl::Status(const galpha::v1::ClassifyResponse&)>& on_message,
                               uint64_t* wire_bytes);

  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<galpha::v1::AlphaShapes::Stub> stub_;
  /// Parts 1.. of a split Classify answer (part 0 takes stub_), each channel a connection of its
  /// own (connected on first use).
  std::vector<std::shared_ptr<grpc::Channel>> part_channels_;
  std::vector<std::unique_ptr<galpha::v1::AlphaShapes::Stub>> part_stubs_;
};

}  // namespace galpha::client
