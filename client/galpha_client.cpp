#include "client/galpha_client.hpp"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/classify_answer_decoder.hpp"
#include "client/classify_parts_merger.hpp"
#include "core/io/point_set_handle.hpp"
#include "proto/codec/point_chunk_codec.hpp"
#include "proto/codec/simplex_chunk_codec.hpp"

namespace galpha::client {

namespace v1 = galpha::v1;

absl::Status FromGrpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

absl::StatusOr<std::unique_ptr<AlphaClient>> AlphaClient::Connect(const ClientOptions& options) {
  if (options.target.empty()) return absl::InvalidArgumentError("no server address (host:port)");
  std::unique_ptr<AlphaClient> client(new AlphaClient());
  client->options_ = options;
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (!options.tls_root_certs_pem.empty()) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = options.tls_root_certs_pem;
    credentials = grpc::SslCredentials(ssl);
  }
  grpc::ChannelArguments arguments;
  // Answers are chunked below 4 MiB, but a large Describe or Components answer may exceed it.
  arguments.SetMaxReceiveMessageSize(std::numeric_limits<int>::max());
  // A connection of its own: gRPC otherwise shares one connection among the channels of a process
  // to the same server, and the concurrent uploads of tens of megabytes of several clients would
  // share that connection's flow control.
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  if (options.classify_parts > kMaxClassifyParts) {
    return absl::InvalidArgumentError(absl::StrCat("classify_parts ", options.classify_parts, " is over ",
                                                   kMaxClassifyParts, " (0: half this machine's cores, at most ",
                                                   kMaxDefaultClassifyParts, ")"));
  }
  const uint32_t parts = options.classify_parts > 0 ? options.classify_parts
                                                    : std::clamp<uint32_t>(std::thread::hardware_concurrency() / 2, 1,
                                                                           kMaxDefaultClassifyParts);
  client->channel_ = grpc::CreateCustomChannel(options.target, credentials, arguments);
  client->stub_ = v1::AlphaShapes::NewStub(client->channel_);
  for (uint32_t part = 1; part < parts; ++part) {
    client->part_channels_.push_back(grpc::CreateCustomChannel(options.target, credentials, arguments));
    client->part_stubs_.push_back(v1::AlphaShapes::NewStub(client->part_channels_.back()));
  }
  return client;
}

void AlphaClient::PrepareContext(grpc::ClientContext* context, const std::string& handle) const {
  if (!handle.empty()) context->AddMetadata(kHandleHeader, handle);
  if (!options_.bearer_token.empty()) context->AddMetadata("authorization", "Bearer " + options_.bearer_token);
  if (options_.deadline.count() > 0) context->set_deadline(std::chrono::system_clock::now() + options_.deadline);
}

namespace {

// One chunk of `points` (and their `weights`, when weighted) as `encoding` says, into `message`
// (its points or encoded_points).
absl::Status EncodeChunk(absl::Span<const Point2> points, absl::Span<const double> weights, PointEncoding encoding,
                         wire::PointChunkEncoder* encoder, v1::BuildRequest* message) {
  if (encoding == PointEncoding::kAuto) return encoder->EncodeSmallest(points, weights, message);
  if (encoding == PointEncoding::kRaw) {
    auto* coordinates = message->mutable_points()->mutable_coordinates();
    if (weights.empty()) {
      coordinates->Assign(&points[0].x, &points[0].x + 2 * points.size());
      return absl::OkStatus();
    }
    coordinates->Clear();
    coordinates->Reserve(static_cast<int>(3 * points.size()));
    for (size_t i = 0; i < points.size(); ++i) {
      coordinates->AddAlreadyReserved(points[i].x);
      coordinates->AddAlreadyReserved(points[i].y);
      coordinates->AddAlreadyReserved(weights[i]);
    }
    return absl::OkStatus();
  }
  wire::ChunkEncoding chunk;
  if (encoding != PointEncoding::kFloat64Compressed) {
    std::optional<wire::ScaledAxes> scaled = wire::FindScaledIntegers(points, weights);
    if (!scaled) {
      return absl::InvalidArgumentError(
          absl::StrCat("the points are not exact scaled integers (offset + scale * X or X / 10^k on each axis",
                       weights.empty() ? "" : ", the weights included", ") in every chunk"));
    }
    chunk.value_type = scaled->value_type;
    chunk.x_scale = scaled->x;
    chunk.y_scale = scaled->y;
    chunk.w_scale = scaled->w;
  }
  if (encoding != PointEncoding::kScaledIntegers) {
    chunk.compression = v1::POINT_COMPRESSION_ZSTD;
    chunk.transform = encoder->ChooseTransform(points, weights, chunk);
  }
  return encoder->Encode(points, weights, chunk, message->mutable_encoded_points());
}

// Point chunks encoded ahead of the writes, one thread a chunk, up to `window` at once, and handed
// over in order as each is ready: encoding costs 2-16 ms a 1 MiB chunk on one core (zstd and the
// trial encodings), as much as sending it over 1 Gb/s, so the writes of the first chunks overlap
// the encoding of the next ones instead of waiting for a whole batch. Build and BuildBatch use it.
class ChunksEncodedAhead {
 public:
  // Chunk `chunk`'s points and weights (empty: unweighted).
  using ChunkPoints = std::function<std::pair<absl::Span<const Point2>, absl::Span<const double>>(size_t chunk)>;

  ChunksEncodedAhead(size_t chunk_count, PointEncoding encoding, int zstd_level, ChunkPoints points)
      : chunk_count_(chunk_count),
        encoding_(encoding),
        window_(encoding == PointEncoding::kRaw
                    ? 1
                    : std::clamp<size_t>(std::thread::hardware_concurrency(), 1, kMaxEncodingThreads)),
        points_(std::move(points)),
        slots_(window_) {
    for (Slot& slot : slots_) slot.encoder = std::make_unique<wire::PointChunkEncoder>(zstd_level);
    for (size_t chunk = 0; chunk < std::min(window_, chunk_count_); ++chunk) Start(chunk);
  }
  // After a failure (a bad chunk, or the server's answer ending the stream) the chunks still being
  // encoded are waited for, then dropped.
  ~ChunksEncodedAhead() {
    for (Slot& slot : slots_) {
      if (slot.worker.joinable()) slot.worker.join();
    }
  }
  ChunksEncodedAhead(const ChunksEncodedAhead&) = delete;
  ChunksEncodedAhead& operator=(const ChunksEncodedAhead&) = delete;

  // The next chunk's message, in order, or its encoding's error; valid until the next call (the
  // caller writes it in between: its slot then takes the chunk `window` ahead).
  absl::StatusOr<v1::BuildRequest*> Next() {
    if (next_ > 0 && next_ - 1 + window_ < chunk_count_) Start(next_ - 1 + window_);
    Slot& slot = slots_[next_ % window_];
    if (window_ > 1) {
      slot.worker.join();
    } else {
      Encode(next_);  // with one slot there is nothing to overlap: each chunk is encoded here
    }
    ++next_;
    if (!slot.status.ok()) return slot.status;
    return &slot.message;
  }

 private:
  struct Slot {
    std::unique_ptr<wire::PointChunkEncoder> encoder;
    v1::BuildRequest message;
    absl::Status status;
    std::thread worker;
  };

  void Encode(size_t chunk) {
    Slot& slot = slots_[chunk % window_];
    const auto [points, weights] = points_(chunk);
    slot.status = EncodeChunk(points, weights, encoding_, slot.encoder.get(), &slot.message);
  }
  void Start(size_t chunk) {
    if (window_ > 1) slots_[chunk % window_].worker = std::thread([this, chunk] { Encode(chunk); });
  }

  const size_t chunk_count_;
  const PointEncoding encoding_;
  const size_t window_;
  const ChunkPoints points_;
  std::vector<Slot> slots_;
  size_t next_ = 0;
};

// A Build stream's message as the BuildBatch stream's message it is (the same parts).
v1::BuildBatchRequest AsBatchMessage(v1::BuildRequest message) {
  v1::BuildBatchRequest out;
  if (message.has_points()) {
    *out.mutable_points() = std::move(*message.mutable_points());
  } else if (message.has_encoded_points()) {
    *out.mutable_encoded_points() = std::move(*message.mutable_encoded_points());
  } else if (message.has_header()) {
    *out.mutable_header() = std::move(*message.mutable_header());
  }
  return out;
}

}  // namespace

absl::StatusOr<BuildResult> AlphaClient::Build(absl::Span<const Point2> points, const BuildCallOptions& options) {
  BuildResult result;
  const absl::Span<const double> weights = options.weights;
  const bool weighted = !weights.empty();
  if (weighted && weights.size() != points.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(points.size(), " points need ", points.size(), " weights, not ", weights.size()));
  }
  // The handle before the upload: to skip it when the server holds the family, and to route the
  // stream to the replica that would hold it.
  const std::string handle = weighted ? WeightedPointSetHandle(points, weights) : PointSetHandle(points);
  // With a CRS the server hashes the projected points: the handle is not known here.
  if (options.skip_upload_if_cached && options.crs.empty()) {
    auto described = Describe(handle);
    if (described.ok()) {
      result.handle = handle;
      result.cached = true;
      result.summary = described->summary();
      // The server keeps no name with a family (proto: BuildHeader.name): the caller's label is
      // this call's, as a Build answer would carry it.
      result.summary.set_name(options.name);
      return result;
    }
    if (!absl::IsNotFound(described.status())) return described.status();
  }
  grpc::ClientContext context;
  PrepareContext(&context, handle);
  v1::BuildResponse response;
  std::unique_ptr<grpc::ClientWriter<v1::BuildRequest>> writer = stub_->Build(&context, &response);
  v1::BuildRequest message;
  message.mutable_header()->set_name(options.name);
  message.mutable_header()->set_expected_points(points.size());
  message.mutable_header()->set_crs(options.crs);
  message.mutable_header()->set_weighted(weighted);
  bool open = writer->Write(message);
  const size_t chunk_count = (points.size() + kPointsPerChunk - 1) / kPointsPerChunk;
  absl::Status encoded;
  {
    ChunksEncodedAhead chunks(chunk_count, options.encoding, options.zstd_level, [&](size_t chunk) {
      const size_t begin = chunk * kPointsPerChunk;
      const size_t count = std::min(kPointsPerChunk, points.size() - begin);
      return std::make_pair(points.subspan(begin, count), weighted ? weights.subspan(begin, count) : weights);
    });
    for (size_t written = 0; open && written < chunk_count; ++written) {
      absl::StatusOr<v1::BuildRequest*> message = chunks.Next();
      if (!message.ok()) {
        encoded = message.status();
        break;
      }
      result.upload_bytes += (*message)->ByteSizeLong();
      open = writer->Write(**message);
      const size_t sent = std::min(points.size(), (written + 1) * kPointsPerChunk);
      if (open && options.progress) options.progress(sent);
    }
  }
  if (!encoded.ok()) {
    context.TryCancel();
    writer->Finish();
    return encoded;
  }
  // A write fails when the server has already answered (an error): Finish returns that answer.
  if (open) writer->WritesDone();
  absl::Status status = FromGrpc(writer->Finish());
  if (!status.ok()) return status;
  result.handle = response.handle();
  result.cached = response.cached();
  result.uploaded = true;
  result.summary = response.summary();
  return result;
}

absl::StatusOr<std::vector<absl::StatusOr<BuildResult>>> AlphaClient::BuildBatch(absl::Span<const BatchSet> sets,
                                                                                 const BuildBatchCallOptions& options) {
  constexpr size_t kMaxSets = 100'000;  // the server's (server/build_batch_reactor.hpp)
  if (sets.size() > kMaxSets) {
    return absl::InvalidArgumentError(
        absl::StrCat(sets.size(), " sets; a BuildBatch call carries at most ", kMaxSets, ": split them"));
  }
  if (sets.empty()) return std::vector<absl::StatusOr<BuildResult>>();
  // The chunks of every set in stream order.
  struct ChunkRef {
    size_t set;
    size_t begin;
    size_t count;
  };
  std::vector<ChunkRef> chunks;
  std::vector<size_t> first_chunk(sets.size() + 1, 0);
  for (size_t i = 0; i < sets.size(); ++i) {
    const BatchSet& set = sets[i];
    if (!set.weights.empty() && set.weights.size() != set.points.size()) {
      return absl::InvalidArgumentError(absl::StrCat("set ", i, " ('", set.name, "'): ", set.points.size(),
                                                     " points need ", set.points.size(), " weights, not ",
                                                     set.weights.size()));
    }
    first_chunk[i] = chunks.size();
    for (size_t begin = 0; begin < set.points.size(); begin += kPointsPerChunk) {
      chunks.push_back({i, begin, std::min(kPointsPerChunk, set.points.size() - begin)});
    }
  }
  first_chunk[sets.size()] = chunks.size();

  grpc::ClientContext context;
  PrepareContext(&context);
  std::unique_ptr<grpc::ClientReaderWriter<v1::BuildBatchRequest, v1::BuildBatchResponse>> stream =
      stub_->BuildBatch(&context);
  bool open = true;
  absl::Status encoded;
  std::vector<uint64_t> upload_bytes(sets.size(), 0);
  {
    // As Build's, the sets' headers written between their chunks.
    ChunksEncodedAhead ahead(chunks.size(), options.encoding, options.zstd_level, [&](size_t chunk) {
      const ChunkRef& ref = chunks[chunk];
      const BatchSet& set = sets[ref.set];
      return std::make_pair(set.points.subspan(ref.begin, ref.count),
                            set.weights.empty() ? set.weights : set.weights.subspan(ref.begin, ref.count));
    });
    for (size_t i = 0; open && encoded.ok() && i < sets.size(); ++i) {
      v1::BuildBatchRequest header;
      header.mutable_header()->set_name(sets[i].name);
      header.mutable_header()->set_expected_points(sets[i].points.size());
      header.mutable_header()->set_crs(options.crs);
      header.mutable_header()->set_weighted(!sets[i].weights.empty());
      open = stream->Write(header);
      for (size_t chunk = first_chunk[i]; open && chunk < first_chunk[i + 1]; ++chunk) {
        absl::StatusOr<v1::BuildRequest*> message = ahead.Next();
        if (!message.ok()) {
          encoded = absl::Status(message.status().code(),
                                 absl::StrCat("set ", i, " ('", sets[i].name, "'): ", message.status().message()));
          break;
        }
        upload_bytes[i] += (*message)->ByteSizeLong();
        open = stream->Write(AsBatchMessage(std::move(**message)));
      }
      if (open && encoded.ok() && options.progress) options.progress(i + 1);
    }
  }
  if (!encoded.ok()) {
    context.TryCancel();
    stream->Finish();
    return encoded;
  }
  // A write fails when the server has already answered (an error): Finish returns that answer.
  if (open) stream->WritesDone();
  std::vector<absl::StatusOr<BuildResult>> results;
  results.reserve(sets.size());
  v1::BuildBatchResponse page;
  absl::Status malformed;
  while (stream->Read(&page)) {
    if (page.first_set() != results.size() || page.set_count() != sets.size() ||
        results.size() + static_cast<size_t>(page.sets_size()) > sets.size()) {
      malformed = absl::DataLossError(absl::StrCat("the server's BuildBatch answer is out of order: a page for sets ",
                                                   page.first_set(), " on of ", page.set_count(), " after ",
                                                   results.size(), " of ", sets.size()));
      context.TryCancel();
      break;
    }
    for (v1::BatchedBuild& answer : *page.mutable_sets()) {
      const size_t i = results.size();
      if (answer.code() != 0) {
        results.emplace_back(absl::Status(static_cast<absl::StatusCode>(answer.code()), answer.message()));
        continue;
      }
      if (answer.result().handle().empty()) {
        malformed =
            absl::DataLossError(absl::StrCat("the server's BuildBatch answer has set ", i, " built without a handle"));
        context.TryCancel();
        break;
      }
      BuildResult result;
      result.handle = answer.result().handle();
      result.cached = answer.result().cached();
      result.uploaded = true;
      result.upload_bytes = upload_bytes[i];
      result.summary = std::move(*answer.mutable_result()->mutable_summary());
      results.emplace_back(std::move(result));
    }
    if (!malformed.ok()) break;
  }
  absl::Status status = FromGrpc(stream->Finish());
  if (!malformed.ok()) return malformed;
  if (!status.ok()) return status;
  if (results.size() != sets.size()) {
    return absl::DataLossError(
        absl::StrCat("the server's BuildBatch answer ended after ", results.size(), " of ", sets.size(), " sets"));
  }
  return results;
}

absl::StatusOr<v1::DescribeResponse> AlphaClient::Describe(const std::string& handle) {
  grpc::ClientContext context;
  PrepareContext(&context, handle);
  v1::DescribeRequest request;
  request.set_handle(handle);
  v1::DescribeResponse response;
  absl::Status status = FromGrpc(stub_->Describe(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

absl::StatusOr<v1::SpectrumResponse> AlphaClient::Spectrum(const v1::SpectrumRequest& request) {
  grpc::ClientContext context;
  PrepareContext(&context, request.handle());
  v1::SpectrumResponse response;
  absl::Status status = FromGrpc(stub_->Spectrum(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

absl::StatusOr<v1::ComponentsResponse> AlphaClient::Components(const v1::ComponentsRequest& request) {
  grpc::ClientContext context;
  PrepareContext(&context, request.handle());
  v1::ComponentsResponse response;
  absl::Status status = FromGrpc(stub_->Components(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

absl::StatusOr<v1::OptimalAlphaResponse> AlphaClient::OptimalAlpha(const v1::OptimalAlphaRequest& request) {
  grpc::ClientContext context;
  PrepareContext(&context, request.handle());
  v1::OptimalAlphaResponse response;
  absl::Status status = FromGrpc(stub_->OptimalAlpha(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

absl::StatusOr<v1::BettiResponse> AlphaClient::Betti(const v1::BettiRequest& request) {
  grpc::ClientContext context;
  PrepareContext(&context, request.handle());
  v1::BettiResponse response;
  absl::Status status = FromGrpc(stub_->Betti(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

absl::StatusOr<v1::ReleaseResponse> AlphaClient::Release(const std::string& handle) {
  grpc::ClientContext context;
  PrepareContext(&context, handle);
  v1::ReleaseRequest request;
  request.set_handle(handle);
  v1::ReleaseResponse response;
  absl::Status status = FromGrpc(stub_->Release(&context, request, &response));
  if (!status.ok()) return status;
  return response;
}

template <typename Response, typename Request>
absl::Status AlphaClient::ReadStream(
    const std::string& handle,
    std::unique_ptr<grpc::ClientReader<Response>> (v1::AlphaShapes::Stub::*call)(grpc::ClientContext*, const Request&),
    const Request& request, const std::function<absl::Status(const Response&)>& on_message) {
  grpc::ClientContext context;
  PrepareContext(&context, handle);
  std::unique_ptr<grpc::ClientReader<Response>> reader = ((*stub_).*call)(&context, request);
  Response message;
  absl::Status consumer_error;
  while (reader->Read(&message)) {
    consumer_error = on_message(message);
    if (!consumer_error.ok()) {
      context.TryCancel();
      while (reader->Read(&message)) {}
      break;
    }
  }
  absl::Status status = FromGrpc(reader->Finish());
  return consumer_error.ok() ? status : consumer_error;
}

absl::Status AlphaClient::Classify(const v1::ClassifyRequest& request,
                                   const std::function<absl::Status(const v1::ClassifyResponse&)>& on_message,
                                   uint64_t* wire_bytes) {
  if (wire_bytes != nullptr) *wire_bytes = 0;
  // A request that names a part itself goes as it is (the server checks it).
  if (!part_stubs_.empty() && !request.summary_only() && request.part_count() == 0 && request.part_index() == 0) {
    return ClassifyInParts(request, on_message, wire_bytes);
  }
  const v1::SimplexEncoding encoding = request.simplex_encoding();
  if (encoding != v1::SIMPLEX_ENCODING_DELTA && encoding != v1::SIMPLEX_ENCODING_DELTA_ZSTD) {
    // Raw chunks, handed over as they come (an encoded one is decoded all the same).
    wire::SimplexChunkDecoder decoder;
    v1::ClassifyResponse decoded;
    uint64_t chunk_index = 0;
    return ReadStream(request.handle(), &v1::AlphaShapes::Stub::Classify, request,
                      std::function<absl::Status(const v1::ClassifyResponse&)>(
                          [&](const v1::ClassifyResponse& message) -> absl::Status {
                            if (wire_bytes != nullptr) *wire_bytes += message.ByteSizeLong();
                            if (message.has_summary()) return on_message(message);
                            const uint64_t index = chunk_index++;
                            if (!message.has_encoded_chunk()) return on_message(message);
                            absl::Status status =
                                decoder.Decode(message.encoded_chunk(), index, decoded.mutable_chunk());
                            return status.ok() ? on_message(decoded) : status;
                          }));
  }

  // Encoded answers: a thread reads (and parses) the next messages while a few others decode the
  // chunks, so that the decoding is neither added to the transfer nor held to one core; this
  // thread hands them over in order.
  const size_t threads = std::clamp<size_t>(std::thread::hardware_concurrency() / 2, 1, 4);
  ClassifyAnswerDecoder answer(threads, 2 * threads + 2);
  grpc::ClientContext context;
  PrepareContext(&context, request.handle());
  std::unique_ptr<grpc::ClientReader<v1::ClassifyResponse>> reader = stub_->Classify(&context, request);
  uint64_t read_bytes = 0;
  std::thread read_ahead([&] {
    v1::ClassifyResponse message;
    while (reader->Read(&message)) {
      read_bytes += message.ByteSizeLong();
      answer.Push(std::move(message));  // after a Stop: dropped, read on to the end
      message.Clear();
    }
    answer.End();
  });
  absl::Status consumer_error;
  try {
    for (;;) {
      absl::StatusOr<const v1::ClassifyResponse*> next = answer.Next();
      consumer_error = next.ok() ? (*next == nullptr ? absl::OkStatus() : on_message(**next)) : next.status();
      if (next.ok() && *next == nullptr) break;
      if (!consumer_error.ok()) {
        context.TryCancel();
        answer.Stop();
        break;
      }
    }
  } catch (...) {
    // A caller's callback that throws: the call ends and the reading thread is joined first.
    context.TryCancel();
    answer.Stop();
    read_ahead.join();
    throw;
  }
  read_ahead.join();
  if (wire_bytes != nullptr) *wire_bytes = read_bytes;
  absl::Status status = FromGrpc(reader->Finish());
  return consumer_error.ok() ? status : consumer_error;
}

absl::Status AlphaClient::ClassifyInParts(const v1::ClassifyRequest& request,
                                          const std::function<absl::Status(const v1::ClassifyResponse&)>& on_message,
                                          uint64_t* wire_bytes) {
  const size_t parts = part_stubs_.size() + 1;
  // A few messages a part ahead of the caller: enough to keep each connection busy, and the
  // memory held is a few chunks a part (at most about 1.7 MB each).
  ClassifyPartsMerger merger(parts, 4);
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  for (size_t part = 0; part < parts; ++part) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    PrepareContext(contexts.back().get(), request.handle());
  }
  std::vector<uint64_t> read_bytes(parts, 0);
  // Part `part`'s call, read on its own thread; its chunks decoded there (P parts, P decoders).
  const auto read_part = [&](size_t part, const v1::ClassifyRequest& part_request) {
    grpc::ClientContext& context = *contexts[part];
    v1::AlphaShapes::Stub& stub = part == 0 ? *stub_ : *part_stubs_[part - 1];
    std::unique_ptr<grpc::ClientReader<v1::ClassifyResponse>> reader = stub.Classify(&context, part_request);
    wire::SimplexChunkDecoder decoder;
    v1::ClassifyResponse message, decoded;
    // This part's chunks so far. Its chunk k is the answer's chunk part + parts * k, unless the server
    // (older than parts) answered part 0 whole; a decoding error names the part and k, right in both.
    uint64_t chunks = 0;
    absl::Status failed;
    while (reader->Read(&message)) {
      read_bytes[part] += message.ByteSizeLong();
      if (!failed.ok()) continue;  // read on to the end after a failure
      try {
        if (message.has_encoded_chunk()) {
          failed = decoder.Decode(message.encoded_chunk(), chunks, decoded.mutable_chunk());
          if (!failed.ok()) {
            failed = absl::Status(failed.code(), absl::StrCat("part ", part, " of ", parts,
                                                              " of the Classify answer, its ", failed.message()));
            context.TryCancel();
            continue;
          }
          message.Swap(&decoded);
        }
        if (!message.has_summary()) ++chunks;
        merger.Push(part, std::move(message));  // refused once the merger stopped reading this part: read on
      } catch (const std::exception& e) {       // out of memory: this part fails, and the answer with it
        failed = absl::ResourceExhaustedError(
            absl::StrCat("reading part ", part, " of ", parts, " of the Classify answer: ", e.what()));
        context.TryCancel();
      }
      message.Clear();
      decoded.Clear();
    }
    const absl::Status status = FromGrpc(reader->Finish());
    merger.End(part, failed.ok() ? status : failed);
  };
  const auto stop_all = [&] {
    merger.Stop();
    for (auto& context : contexts) context->TryCancel();
  };
  std::vector<std::thread> readers;
  readers.reserve(parts);
  absl::Status result;
  bool others_cancelled = false;
  try {
    for (size_t part = 0; part < parts; ++part) {
      v1::ClassifyRequest part_request = request;
      part_request.set_part_index(static_cast<uint32_t>(part));
      part_request.set_part_count(static_cast<uint32_t>(parts));
      readers.emplace_back(read_part, part, std::move(part_request));
    }
    for (;;) {
      absl::StatusOr<const v1::ClassifyResponse*> next = merger.Next();
      if (!next.ok()) {
        result = next.status();
        stop_all();
        break;
      }
      if (*next == nullptr) break;
      if (!others_cancelled && merger.whole_from_part_zero()) {
        // The server answered every part whole: part 0 alone is read.
        for (size_t part = 1; part < parts; ++part) contexts[part]->TryCancel();
        others_cancelled = true;
      }
      result = on_message(**next);
      if (!result.ok()) {
        stop_all();
        break;
      }
    }
  } catch (...) {
    // A thread that could not start, or a caller's callback that throws: the calls end and the
    // started readers are joined first.
    stop_all();
    for (std::thread& reader : readers) reader.join();
    throw;
  }
  for (std::thread& reader : readers) reader.join();
  if (wire_bytes != nullptr) {
    *wire_bytes = 0;
    for (uint64_t bytes : read_bytes) *wire_bytes += bytes;
  }
  return result;
}

absl::Status AlphaClient::MasterList(const v1::MasterListRequest& request,
                                     const std::function<absl::Status(const v1::MasterListResponse&)>& on_message) {
  return ReadStream(request.handle(), &v1::AlphaShapes::Stub::MasterList, request, on_message);
}

absl::Status AlphaClient::Shape(const v1::ShapeRequest& request,
                                const std::function<absl::Status(const v1::ShapeResponse&)>& on_message) {
  return ReadStream(request.handle(), &v1::AlphaShapes::Stub::Shape, request, on_message);
}

absl::Status AlphaClient::Persistence(const v1::PersistenceRequest& request,
                                      const std::function<absl::Status(const v1::PersistenceResponse&)>& on_message) {
  return ReadStream(request.handle(), &v1::AlphaShapes::Stub::Persistence, request, on_message);
}

}  // namespace galpha::client
