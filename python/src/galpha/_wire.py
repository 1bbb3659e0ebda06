"""The few protocol-buffer messages whose bulk arrays must cross at memory speed, encoded and
decoded by hand with NumPy: point chunks going up, simplex chunks, master-list pages, spectrum
pages and persistence chunks coming down. Going through the protobuf library's repeated fields costs a Python object per
number (~50 ns each, 20 MB/s); here a packed field is one ``np.frombuffer``. Everything else uses
the generated classes. Field numbers are those of proto/galpha/v1/alpha_shapes.proto.
"""

from __future__ import annotations

from typing import Any, Dict, Iterator, List, Optional, Tuple

import numpy as np

_VARINT, _I64, _LEN, _I32 = 0, 1, 2, 5


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def _len_field(number: int, payload: bytes) -> bytes:
    return _varint((number << 3) | _LEN) + _varint(len(payload)) + payload


def encode_point_chunk_request(chunk: np.ndarray) -> bytes:
    """BuildRequest{points: PointChunk{coordinates: packed doubles}} for an (n, 2) float64 array, or
    a weighted stream's (n, 3) (x, y, w)."""
    packed = np.ascontiguousarray(chunk, dtype="<f8").tobytes()
    return _len_field(2, _len_field(1, packed))


def _read_varint(data: memoryview, pos: int) -> Tuple[int, int]:
    result = shift = 0
    while True:
        byte = data[pos]
        pos += 1
        result |= (byte & 0x7F) << shift
        if byte < 0x80:
            return result, pos
        shift += 7


def fields(data: bytes) -> Iterator[Tuple[int, int, object]]:
    """(field number, wire type, value) of each field: an int for VARINT/I64/I32 (raw bits), a
    memoryview for LEN."""
    view = memoryview(data)
    pos, end = 0, len(view)
    while pos < end:
        key, pos = _read_varint(view, pos)
        number, wire = key >> 3, key & 7
        if wire == _VARINT:
            value, pos = _read_varint(view, pos)
        elif wire == _LEN:
            size, pos = _read_varint(view, pos)
            value, pos = view[pos : pos + size], pos + size
        elif wire == _I64:
            value, pos = int.from_bytes(view[pos : pos + 8], "little"), pos + 8
        elif wire == _I32:
            value, pos = int.from_bytes(view[pos : pos + 4], "little"), pos + 4
        else:
            raise ValueError(f"unsupported wire type {wire} in field {number}")
        yield number, wire, value


def _packed(value: object, wire: int, dtype: str) -> np.ndarray:
    """A packed repeated field (LEN) as an array; a lone unpacked element also decodes."""
    if wire == _LEN:
        return np.frombuffer(value, dtype=dtype)  # type: ignore[arg-type]
    size = np.dtype(dtype).itemsize
    return np.frombuffer(int(value).to_bytes(size, "little"), dtype=dtype)  # type: ignore[arg-type]


def _packed_varints(value: object, wire: int) -> np.ndarray:
    """A packed repeated int64 field (LEN of varints), or a lone unpacked element, as int64: each
    varint's 7-bit groups shifted into place and summed per varint, without a Python loop."""
    if wire == _VARINT:
        return np.array([_int64(value)], dtype=np.int64)
    raw = np.frombuffer(value, dtype=np.uint8)  # type: ignore[arg-type]
    if raw.size == 0:
        return np.empty(0, dtype=np.int64)
    last = raw < 0x80  # the final byte of each varint
    ends = np.flatnonzero(last)
    if ends.size == 0 or ends[-1] != raw.size - 1:
        raise ValueError("a packed varint field ends inside a varint")
    starts = np.empty_like(ends)
    starts[0] = 0
    starts[1:] = ends[:-1] + 1
    position = np.arange(raw.size) - np.repeat(starts, ends - starts + 1)
    if position.max() > 9:
        raise ValueError("a varint in a packed field is longer than 10 bytes")
    groups = (raw & 0x7F).astype(np.uint64) << (7 * position).astype(np.uint64)
    return np.add.reduceat(groups, starts).view(np.int64)


def decode_persistence_chunk(data: bytes) -> Tuple[int, Dict[str, np.ndarray]]:
    """PersistenceResponse: (dimension, {birth_rank, death_rank (int64), birth_alpha_sq,
    death_alpha_sq (float64), creator_vertices, killer_vertices (uint32, flat)})."""
    dimension = 0
    parts: Dict[int, List[np.ndarray]] = {n: [] for n in range(2, 8)}
    for number, wire, value in fields(data):
        if number == 1:
            dimension = int(value)  # type: ignore[arg-type]
        elif number in (2, 3):
            parts[number].append(_packed_varints(value, wire))
        elif number in (4, 5):
            parts[number].append(_packed(value, wire, "<f8"))
        elif number in (6, 7):
            parts[number].append(_packed(value, wire, "<u4"))
    return dimension, {
        "birth_rank": _concat(parts[2], np.int64),
        "death_rank": _concat(parts[3], np.int64),
        "birth_alpha_sq": _concat(parts[4], "<f8"),
        "death_alpha_sq": _concat(parts[5], "<f8"),
        "creator_vertices": _concat(parts[6], "<u4"),
        "killer_vertices": _concat(parts[7], "<u4"),
    }


def split_oneof(data: bytes) -> Tuple[int, memoryview]:
    """The one set field of a message that is a oneof of submessages: (number, payload)."""
    for number, wire, value in fields(data):
        if wire == _LEN:
            return number, value  # type: ignore[return-value]
    return 0, memoryview(b"")


def decode_simplex_chunk(payload: memoryview) -> Tuple[int, np.ndarray, np.ndarray]:
    """SimplexChunk: (kind, vertex indices as uint32, classes as uint8)."""
    kind, parts_idx, parts_cls = 0, [], []
    for number, wire, value in fields(payload):
        if number == 1:
            kind = int(value)  # type: ignore[arg-type]
        elif number == 2:
            parts_idx.append(_packed(value, wire, "<u4"))
        elif number == 3:
            parts_cls.append(np.frombuffer(value, dtype=np.uint8))  # type: ignore[arg-type]
    return kind, _concat(parts_idx, "<u4"), _concat(parts_cls, np.uint8)


#: The most simplices one EncodedSimplexChunk may state (the proto's limit).
MAX_SIMPLICES_PER_ENCODED_CHUNK = 1 << 20
SIMPLEX_ENCODING_DELTA, SIMPLEX_ENCODING_DELTA_ZSTD = 2, 3


class EncodedChunkError(ValueError):
    """An EncodedSimplexChunk that does not decode; the message names what is wrong."""


def _segment_base(starts: np.ndarray, base_at_start: np.ndarray) -> np.ndarray:
    """For each row, base_at_start of the last row at or before it where ``starts`` is True (row 0
    always starts)."""
    last = np.maximum.accumulate(np.where(starts, np.arange(starts.size), 0))
    return base_at_start[last]


def native_section_reader() -> Optional[Any]:
    """A reader of compact chunks' data in C++ (galpha._engine.SimplexSectionReader, one a stream),
    or None where the compiled module is missing (decode_encoded_simplex_chunk then uses NumPy)."""
    try:
        from . import _engine
    except ImportError:
        return None
    return _engine.SimplexSectionReader()


def decode_encoded_simplex_chunk(
    payload: memoryview, chunk_index: int, reader: Optional[Any] = None
) -> Tuple[int, np.ndarray, np.ndarray]:
    """EncodedSimplexChunk (proto: the layout; docs/design.md, "Compact Classify answers") as
    (kind, vertex indices as uint32, classes as uint8), what decode_simplex_chunk gives for the raw
    chunk. With ``reader`` (native_section_reader) the data section is decoded in C++ with the GIL
    released (5-10x faster); else with NumPy (no Python loop over simplices): the varints' 7-bit
    groups summed per varint, the differences turned into indices by cumulative sums within runs of
    equal prefixes. Either way EncodedChunkError naming the chunk for everything the proto says a
    client refuses, with the same messages."""
    def refuse(what: str) -> EncodedChunkError:
        return EncodedChunkError(f"encoded simplex chunk {chunk_index}: {what}")

    kind = count = encoding = 0
    data: object = b""
    try:
        parsed = list(fields(payload))
    except (IndexError, ValueError) as e:
        raise refuse(f"it is not a well-formed message ({e})") from None
    for number, wire, value in parsed:
        if number in (1, 2, 3):
            if wire != _VARINT:
                raise refuse(f"its field {number} has wire type {wire}, not a varint")
            # As the C++ decoder reads them: uint32 and enums keep their low 32 bits.
            low = int(value) & 0xFFFFFFFF  # type: ignore[arg-type]
            if number == 1:
                kind = low
            elif number == 2:
                count = low
            else:
                encoding = low
        elif number == 4:
            if wire != _LEN:
                raise refuse(f"its data (field 4) has wire type {wire}, not bytes")
            data = value

    arity = {1: 1, 2: 2, 3: 3}.get(kind, 0)
    if arity == 0:
        raise refuse(f"its kind {kind} is not a simplex kind")
    if encoding not in (SIMPLEX_ENCODING_DELTA, SIMPLEX_ENCODING_DELTA_ZSTD):
        raise refuse(f"its encoding {encoding} is not DELTA (2) or DELTA_ZSTD (3)")
    if count == 0 or count > MAX_SIMPLICES_PER_ENCODED_CHUNK:
        raise refuse(f"it states {count} simplices; a chunk holds 1 to {MAX_SIMPLICES_PER_ENCODED_CHUNK}")
    if reader is not None:
        from . import _engine

        try:
            indices, classes = reader.read(arity, count, encoding == SIMPLEX_ENCODING_DELTA_ZSTD, data, chunk_index)
        except _engine.EngineError as e:
            raise EncodedChunkError(e.message) from None
        return kind, indices, classes
    class_bytes = (count + 3) // 4
    bound = class_bytes + count * arity * 5
    if encoding == SIMPLEX_ENCODING_DELTA_ZSTD:
        try:
            import zstandard  # Debian's python3-zstandard; connect() checks for it before asking for zstd
        except ImportError:
            raise refuse("it is zstd-compressed and the zstandard module is missing (python3-zstandard)") from None

        frame = bytes(data)  # type: ignore[call-overload]
        too_large = f"its zstd frame decompresses to more than the {bound} bytes {count} simplices can take"
        try:
            declared = zstandard.frame_content_size(frame)
        except zstandard.ZstdError as e:
            raise refuse(f"its data is not a zstd frame ({e})") from None
        if declared > bound:
            raise refuse(too_large)
        try:
            # Never more than bound + 1 bytes out, whatever the frame declares (no zip bombs: a
            # declared size is checked only at the frame's end): read through a bounded reader
            # first; only a frame proven small is then decoded whole, for its end and what follows.
            # One read fills up to its size (or the frame's end); a second one would go on into
            # what follows the frame.
            reader = zstandard.ZstdDecompressor().stream_reader(frame, read_across_frames=False)
            if len(reader.read(bound + 1)) > bound:
                raise refuse(too_large)
            stream = zstandard.ZstdDecompressor().decompressobj()
            sections = stream.decompress(frame)
        except zstandard.ZstdError as e:
            raise refuse(f"its zstd frame is corrupt ({e})") from None
        if not stream.eof:
            raise refuse("its data ends inside its zstd frame")
        if stream.unused_data:
            raise refuse(f"it has {len(stream.unused_data)} bytes after its zstd frame")
        if len(sections) > bound:
            raise refuse(too_large)
    else:
        sections = bytes(data)  # type: ignore[call-overload]
        if len(sections) > bound:
            raise refuse(f"its {len(sections)} bytes are more than the {bound} bytes {count} simplices can take")
    raw = np.frombuffer(sections, dtype=np.uint8)
    if raw.size < class_bytes:
        raise refuse(f"its {raw.size} bytes end before its {class_bytes} bytes of classes")
    packed = raw[:class_bytes]
    tail = count % 4
    if tail and int(packed[-1]) >> (2 * tail):
        raise refuse("the unused bits of its last class byte are not 0")
    classes = (np.stack([(packed >> s) & 3 for s in (0, 2, 4, 6)], axis=1).reshape(-1)[:count] + 1).astype(np.uint8)

    varints = raw[class_bytes:]
    last = varints < 0x80  # the final byte of each varint
    ends = np.flatnonzero(last)
    values_needed = count * arity
    starts = np.empty_like(ends)
    if ends.size:
        starts[0] = 0
        starts[1:] = ends[:-1] + 1
    lengths = ends - starts + 1
    # In stream order, as the C++ decoder finds them: a varint over 5 bytes (complete or not),
    # then the end of the data inside the simplices.
    unfinished = varints.size - (int(ends[-1]) + 1 if ends.size else 0)
    too_long = np.flatnonzero(lengths[:values_needed] > 5)
    if too_long.size:
        raise refuse(f"simplex {int(too_long[0]) // arity} has a varint longer than 5 bytes")
    if ends.size < values_needed:
        if unfinished > 5:
            raise refuse(f"simplex {ends.size // arity} has a varint longer than 5 bytes")
        raise refuse(f"its varints end inside simplex {ends.size // arity} (truncated)")
    if ends.size > values_needed or unfinished:
        extra = varints.size - 1 - int(ends[values_needed - 1])
        raise refuse(f"it has {extra} bytes after its {count} simplices")
    position = np.arange(varints.size) - np.repeat(starts, lengths)
    groups = (varints & 0x7F).astype(np.int64) << (7 * position).astype(np.int64)
    v = np.add.reduceat(groups, starts).reshape(count, arity)

    # Index k of simplex i (proto): after the previous simplex's index k where the prefix before k
    # is the same (plus 1 at the last position), else after index k - 1 of the same simplex plus 1.
    index = np.empty((count, arity), dtype=np.int64)
    if arity == 1:
        steps = v[:, 0] + 1
        steps[0] = v[0, 0]
        index[:, 0] = np.cumsum(steps)
    else:
        index[:, 0] = np.cumsum(v[:, 0])  # k = 0 is never the last position here
        same = np.zeros(count, dtype=bool)
        same[1:] = v[1:, 0] == 0  # the prefix u[0] repeats
        for k in range(1, arity):
            is_last = k == arity - 1
            # Within a run of equal prefixes (started where `same` is False) index k grows by
            # v + (1 at the last position); the run's first takes index k - 1 + v + 1.
            steps = v[:, k] + (1 if is_last else 0)
            total = np.cumsum(steps)
            first = index[:, k - 1] + v[:, k] + 1
            base = _segment_base(~same, first - total)
            index[:, k] = base + total
            same = same & (v[:, k] == 0)
    if index.max() > 0xFFFFFFFF:
        raise refuse(f"simplex {int(np.argmax((index > 0xFFFFFFFF).any(axis=1)))} has an index over 2^32 - 1")
    return kind, index.astype(np.uint32).reshape(-1), classes


def decode_master_list_page(data: bytes) -> Dict[str, np.ndarray]:
    """MasterListResponse: ranks (fixed64), kinds, endpoints (bytes), vertex_indices (fixed32)."""
    parts: Dict[int, List[np.ndarray]] = {1: [], 2: [], 3: [], 4: []}
    for number, wire, value in fields(data):
        if number == 1:
            parts[1].append(_packed(value, wire, "<u8"))
        elif number in (2, 3):
            parts[number].append(np.frombuffer(value, dtype=np.uint8))  # type: ignore[arg-type]
        elif number == 4:
            parts[4].append(_packed(value, wire, "<u4"))
    return {
        "ranks": _concat(parts[1], "<u8").astype(np.int64),
        "kinds": _concat(parts[2], np.uint8),
        "endpoints": _concat(parts[3], np.uint8),
        "vertex_indices": _concat(parts[4], "<u4"),
    }


def decode_spectrum_page(data: bytes) -> Tuple[int, np.ndarray, int, int]:
    """SpectrumResponse: (first_rank, alpha_sq values, next_rank, spectrum_size)."""
    first_rank = next_rank = size = 0
    values: List[np.ndarray] = []
    for number, wire, value in fields(data):
        if number == 1:
            first_rank = _int64(value)
        elif number == 2:
            values.append(_packed(value, wire, "<f8"))
        elif number == 3:
            next_rank = _int64(value)
        elif number == 4:
            size = _int64(value)
    return first_rank, _concat(values, "<f8"), next_rank, size


def _int64(value: object) -> int:
    v = int(value)  # type: ignore[arg-type]
    return v - (1 << 64) if v >= 1 << 63 else v


def _concat(parts: List[np.ndarray], dtype: object) -> np.ndarray:
    if not parts:
        return np.empty(0, dtype=dtype)  # type: ignore[call-overload]
    if len(parts) == 1:
        return parts[0]
    return np.concatenate(parts)
