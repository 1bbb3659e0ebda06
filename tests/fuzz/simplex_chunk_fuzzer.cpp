// libFuzzer target: the compact Classify answer decoder (proto/codec/simplex_chunk_codec.hpp) on
// arbitrary chunks, what a client reads from a server it may not trust. The first byte picks the
// kind and encoding (DELTA or DELTA_ZSTD, or an undefined one), the next two the stated count
// (small, so that short inputs reach the varints), the rest is the data. Refusals are fine;
// crashes, sanitizer reports and hangs are not. A chunk that decodes must be in the form the
// encoder writes: strictly ascending simplices, classes 1..4, and encoding it again (DELTA) and
// decoding that must give the same chunk.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "proto/codec/simplex_chunk_codec.hpp"

namespace v1 = galpha::v1;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3) return 0;
  v1::EncodedSimplexChunk chunk;
  chunk.set_kind(static_cast<v1::SimplexKind>(data[0] % 4));  // 0 is not a kind
  const int encoding = (data[0] / 4) % 3;                     // 0: an encoding the decoder must refuse
  chunk.set_encoding(encoding == 0   ? static_cast<v1::SimplexEncoding>(7)
                     : encoding == 1 ? v1::SIMPLEX_ENCODING_DELTA
                                     : v1::SIMPLEX_ENCODING_DELTA_ZSTD);
  chunk.set_simplex_count(static_cast<uint32_t>(data[1]) | (static_cast<uint32_t>(data[2] & 0x3F) << 8));
  chunk.set_data(std::string(reinterpret_cast<const char*>(data + 3), size - 3));
  static galpha::wire::SimplexChunkDecoder decoder;
  v1::SimplexChunk decoded;
  if (!decoder.Decode(chunk, 0, &decoded).ok()) return 0;
  const int arity = galpha::wire::SimplexArity(decoded.kind());
  if (arity == 0 || decoded.classes().size() != chunk.simplex_count() ||
      static_cast<size_t>(decoded.vertex_indices_size()) != decoded.classes().size() * static_cast<size_t>(arity)) {
    std::abort();
  }
  static galpha::wire::SimplexChunkEncoder encoder;
  v1::EncodedSimplexChunk again;
  if (!encoder.Encode(decoded, v1::SIMPLEX_ENCODING_DELTA, &again).ok()) std::abort();  // not the encoder's form
  v1::SimplexChunk twice;
  if (!decoder.Decode(again, 0, &twice).ok()) std::abort();
  if (twice.SerializeAsString() != decoded.SerializeAsString()) std::abort();
  return 0;
}
