"""The few protocol-buffer messages whose bulk arrays must cross at memory speed, encoded and
decoded by hand with NumPy: point chunks going up, simplex chunks, master-list pages, spectrum
pages and persistence chunks coming down. Going through the protobuf library's repeated fields costs a Python object per
number (~50 ns each, 20 MB/s); here a packed field is one ``np.frombuffer``. Everything else uses
the generated classes. Field numbers are those of proto/galpha/v1/alpha_shapes.proto.
"""

from __future__ import annotations

from typing import Dict, Iterator, List, Tuple

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
