"""Compact, lossless encodings of a Build stream's points (galpha.v1.EncodedPointChunk): the
encoder the network client sends with, and a decoder that is the executable spec (tests use it).

The format is docs/design.md, "Wire encodings of points"; the C++ codec
(proto/codec/point_chunk_codec.cpp) is the reference this module follows in NumPy: per chunk, exact
scaled integers found from the data (``X / 10^k``, ``fl(10^-k) * X``, LAS-style ``offset +
fl(10^-k) * X``, ``2^-k * X``), each verified bit for bit with the server's arithmetic; every
transform tried on a sample as float64 and as integers, zstd level 3; the smallest kept, and a raw
PointChunk when nothing beats 8 bytes a value (16 a point, 24 weighted). Messages are encoded by hand like ``_wire.py``'s
(the fields are few and small; the data is one bytes field), so a chunk's bytes are copied once.

Points are (n, 2) float64 arrays; the points of a weighted stream (BuildHeader.weighted) are (n, 3)
arrays of x, y and the weight w, which is a third axis throughout (its own scale, w_scale).
"""

from __future__ import annotations

import dataclasses
import math
import struct
import threading
from typing import List, Optional, Tuple

import numpy as np

from . import _wire
from ._errors import InvalidInput

# The proto's enum numbers (proto/galpha/v1/alpha_shapes.proto).
FLOAT64, INT32, INT64 = 1, 2, 3
NONE, BYTE_SHUFFLE, DELTA_SHUFFLE, DELTA2_SHUFFLE = 1, 2, 3, 4
UNCOMPRESSED, ZSTD = 1, 2
TRANSFORMS = (NONE, BYTE_SHUFFLE, DELTA_SHUFFLE, DELTA2_SHUFFLE)

#: The ``encoding`` argument of ``Client.build``: "auto" (the smallest form per chunk) or "raw"
#: (packed doubles, what servers older than EncodedPointChunk accept).
ENCODINGS = ("auto", "raw")
#: Most points one EncodedPointChunk may state (the server's kMaxPointsPerEncodedChunk).
MAX_POINTS_PER_ENCODED_CHUNK = 1 << 18
#: zstd's level (3 is zstd's default and the C++ client's).
ZSTD_LEVEL = 3

_MAX_EXACT_INTEGER = float(1 << 53)
# 10^k (exact doubles for k <= 22) and the doubles nearest to 10^-k, as LAS writers store scales.
_POWERS_OF_TEN = [float(10**k) for k in range(23)]
_TENTH_POWERS = [float(f"1e-{k}") for k in range(23)]
_WORD = {FLOAT64: ("<u8", "<i8", 8), INT32: ("<u4", "<i4", 4), INT64: ("<u8", "<i8", 8)}
_AXIS_NAMES = ("x", "y", "w")


class _Scratch(threading.local):
    """Per-thread buffers reused from chunk to chunk. Every fresh array of a chunk's size is fresh
    pages for the kernel to fault in and zero: on the 2-core development VM an expression with two
    1 MiB temporaries took 5 ms instead of 0.05. So the hot paths write into these (``out=``)."""

    def __init__(self) -> None:
        self.buffers: dict = {}
        self.compressor: object = False  # zstd's (not thread-safe), made on first use

    def get(self, name: str, shape: Tuple[int, ...], dtype: object) -> np.ndarray:
        """A buffer of `shape` (contents undefined), valid until the next get(name) on this thread."""
        dt = np.dtype(dtype)
        size = int(np.prod(shape)) * dt.itemsize
        buf = self.buffers.get(name)
        if buf is None or buf.size < size:
            buf = self.buffers[name] = np.empty(max(size, 8), dtype=np.uint8)
        return buf[:size].view(dt).reshape(shape)


_scratch = _Scratch()


def check_encoding(encoding: object) -> str:
    """`encoding` if it is one of ENCODINGS; InvalidInput naming it otherwise."""
    if not isinstance(encoding, str) or encoding not in ENCODINGS:
        raise InvalidInput(f"unknown encoding {encoding!r} (expected 'auto' or 'raw')")
    return encoding


@dataclasses.dataclass(frozen=True)
class AxisScale:
    """An integer X of an axis decodes to ``offset + step * X`` or, with ``divide``,
    ``offset + X / step``: two IEEE-754 binary64 roundings, never fused."""

    step: float
    divide: bool = False
    offset: float = 0.0

    def values(self, x: np.ndarray) -> np.ndarray:
        """The doubles the server decodes integers `x` (int64 or float64 holding integers) to.
        NumPy's ufuncs round each operation on its own (there is no fused multiply-add)."""
        xd = x.astype(np.float64, copy=False)
        product = np.divide(xd, self.step) if self.divide else np.multiply(self.step, xd)
        return np.add(self.offset, product)


@dataclasses.dataclass(frozen=True)
class ChunkEncoding:
    """How to encode one chunk; x_scale and y_scale (and w_scale, weighted) for the integer value
    types only."""

    value_type: int = FLOAT64
    transform: int = NONE
    compression: int = UNCOMPRESSED
    x_scale: Optional[AxisScale] = None
    y_scale: Optional[AxisScale] = None
    w_scale: Optional[AxisScale] = None

    def scales(self, axes: int) -> Tuple[Optional[AxisScale], ...]:
        return (self.x_scale, self.y_scale, self.w_scale)[:axes]


@dataclasses.dataclass
class ScaledIntegers:
    """Per-axis scales under which every value is an integer, and the integers ((n, axes) int64)."""

    value_type: int  # INT32 when every integer fits, else INT64
    x_scale: AxisScale
    y_scale: AxisScale
    integers: np.ndarray
    w_scale: Optional[AxisScale] = None  # weighted points only

    def encoding(self, transform: int = NONE, compression: int = UNCOMPRESSED) -> ChunkEncoding:
        return ChunkEncoding(self.value_type, transform, compression, self.x_scale, self.y_scale, self.w_scale)


# ---- Scaled integers ---------------------------------------------------------------------------


def _bits_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.array_equal(a.view(np.uint64), b.view(np.uint64)))


def _estimate(values: np.ndarray, steps: np.ndarray, divide: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The integers nearest to what each scale says `values` are (broadcast over candidates): only
    candidates, the caller verifies them exactly."""
    with np.errstate(all="ignore"):
        shifted = values - offsets
        return np.rint(np.where(divide, shifted * steps, shifted / steps))


def _exact_integers(values: np.ndarray, scale: AxisScale, out: Optional[np.ndarray] = None) -> Optional[np.ndarray]:
    """The integers (as float64, in `out` when given) that `scale` maps to exactly `values`, bit for
    bit, each at most 2^53 in magnitude; None when some value has none."""
    n = len(values)
    x = np.empty(n) if out is None else out
    back = _scratch.get("back", (n,), np.float64)
    with np.errstate(all="ignore"):
        shifted = values
        if scale.offset != 0:
            shifted = np.subtract(values, scale.offset, out=back)
        if scale.divide:
            np.multiply(shifted, scale.step, out=x)
        else:
            np.divide(shifted, scale.step, out=x)
        np.rint(x, out=x)
        np.abs(x, out=back)
        if not back.max(initial=0.0) <= _MAX_EXACT_INTEGER:  # a NaN fails too
            return None
        # The server's arithmetic: the product (or quotient), then the sum, each rounded alone.
        if scale.divide:
            np.divide(x, scale.step, out=back)
        else:
            np.multiply(scale.step, x, out=back)
        np.add(scale.offset, back, out=back)
    return x if _bits_equal(back, values) else None


_SIGN = np.uint64(1 << 63)
_FRACTION = np.uint64((1 << 52) - 1)


def _power_of_two_scale(values: np.ndarray) -> Optional[AxisScale]:
    """2^-k for the smallest k under which every value is an integer (the C++ PowerOfTwoScale),
    read off the bit patterns: |v| = significand * 2^(e - 1075), so k = 1075 - e - (the
    significand's trailing zeros) at most."""
    n = len(values)
    bits = values.view(np.uint64)
    biased = _scratch.get("biased", (n,), np.uint64)
    np.right_shift(bits, np.uint64(52), out=biased)
    np.bitwise_and(biased, np.uint64(0x7FF), out=biased)
    if biased.max(initial=0) == 0x7FF:  # NaN or infinite
        return None
    significand = _scratch.get("significand", (n,), np.uint64)
    np.bitwise_and(bits, _FRACTION, out=significand)
    # The implicit leading 1 of normal numbers (subnormals have none: biased exponent 0).
    np.bitwise_or(significand, np.uint64(1 << 52), out=significand, where=biased != 0)
    lowest = _scratch.get("lowest", (n,), np.uint64)
    np.invert(significand, out=lowest)
    np.add(lowest, np.uint64(1), out=lowest)
    np.bitwise_and(lowest, significand, out=lowest)  # the lowest set bit: a power of two, exact as a double
    as_double = _scratch.get("as_double", (n,), np.float64)
    np.copyto(as_double, lowest, casting="unsafe")
    trailing = as_double.view(np.uint64)
    np.right_shift(trailing, np.uint64(52), out=trailing)  # its biased exponent: trailing zeros + 1023
    np.maximum(biased, np.uint64(1), out=biased)
    np.add(biased, trailing, out=biased)
    np.bitwise_and(bits, ~_SIGN, out=lowest)
    nonzero = lowest != 0
    if not nonzero.any():
        return AxisScale(1.0)
    # k_i = 1075 - max(e, 1) - trailing zeros = 2098 - (max(e, 1) + trailing zeros + 1023).
    k = max(0, 2098 - int(biased.min(where=nonzero, initial=1 << 62)))
    return None if k > 1000 else AxisScale(math.ldexp(1.0, -k))


def _axis_candidates(lowest: float) -> List[AxisScale]:
    """The C++ FindAxisScale's candidates, in its order, less the power of two."""
    out = []
    for k in range(23):
        out.append(AxisScale(_TENTH_POWERS[k]))
        out.append(AxisScale(_POWERS_OF_TEN[k], divide=True))
    seen = set()
    # LAS writers pick a round offset at or below the tile's corner (lidar_haystack_rock's y is
    # 200000 + 0.01 * Y).
    for k in range(10):
        for j in range(8):
            offset = math.floor(lowest / _POWERS_OF_TEN[j]) * _POWERS_OF_TEN[j]
            if offset != 0 and (k, offset) not in seen:
                seen.add((k, offset))
                out.append(AxisScale(_TENTH_POWERS[k], offset=offset))
    return out


# Candidates are first tried together on this many values (one broadcast); the survivors in order
# on the whole axis. Uniform doubles then reject ~130 candidates in one pass.
_PREFILTER = 64


def find_axis_scale(values: np.ndarray, out: Optional[np.ndarray] = None) -> Optional[Tuple[AxisScale, np.ndarray]]:
    """The first candidate scale (the C++ client's order) under which every value of one axis is an
    integer, with those integers (float64, in `out` when given); None when there is none (or a
    value is -0.0, NaN or infinite)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.size == 0:
        return None
    lowest = float(np.min(values))
    if not math.isfinite(lowest):
        return None
    candidates = _axis_candidates(lowest)
    head = values[:_PREFILTER]
    steps = np.array([c.step for c in candidates])[:, None]
    divide = np.array([c.divide for c in candidates])[:, None]
    offsets = np.array([c.offset for c in candidates])[:, None]
    x = _estimate(head[None, :], steps, divide, offsets)
    with np.errstate(all="ignore"):
        back = offsets + np.where(divide, x / steps, steps * x)  # two roundings, as AxisScale.values
    passing = np.all((back.view(np.uint64) == head.view(np.uint64)) & (np.abs(x) <= _MAX_EXACT_INTEGER), axis=1)
    for index in np.flatnonzero(passing):
        integers = _exact_integers(values, candidates[index], out)
        if integers is not None:
            return candidates[index], integers
    # 2^-k needs the largest k of any value, and a larger k only enlarges every |X|: when the
    # head's own k already leaves an |X| over 2^53 (uniform doubles), the whole axis fails too.
    head_power = _power_of_two_scale(head)
    if head_power is None or _exact_integers(head, head_power) is None:
        return None
    power = _power_of_two_scale(values)
    if power is not None:
        integers = _exact_integers(values, power, out)
        if integers is not None:
            return power, integers
    return None


def find_scaled_integers(points: np.ndarray, scratch: bool = False) -> Optional[ScaledIntegers]:
    """Per-axis scales under which every value of (n, 2) `points` (or weighted (n, 3) ones) is an
    integer, exactly. `scratch`: the integers live in this thread's scratch (valid until its next
    call)."""
    n, axes = points.shape
    if n == 0:
        return None
    column = _scratch.get("column", (n,), np.float64)
    found = []
    integers = _scratch.get("integers_f", (axes, n), np.float64) if scratch else np.empty((axes, n))
    for axis in range(axes):
        np.copyto(column, points[:, axis])
        axis_scale = find_axis_scale(column, integers[axis])
        if axis_scale is None:
            return None
        found.append(axis_scale[0])
    fits32 = bool(integers.min() >= -(2.0**31) and integers.max() < 2.0**31)
    words = _scratch.get("integers", (n, axes), np.int64) if scratch else np.empty((n, axes), np.int64)
    np.copyto(words, integers.T, casting="unsafe")
    return ScaledIntegers(INT32 if fits32 else INT64, found[0], found[1], words, found[2] if axes == 3 else None)


# ---- Transforms ----------------------------------------------------------------------------------


def _transformed(words: np.ndarray, transform: int) -> np.ndarray:
    """Interleaved (n, axes) unsigned words as the transform's bytes (the proto's PointTransform),
    a uint8 array in this thread's scratch."""
    if transform in (0, NONE):
        return np.ascontiguousarray(words).reshape(-1).view(np.uint8)
    n, axes = words.shape
    dtype = words.dtype
    width = dtype.itemsize
    planar = _scratch.get("planar", (axes, n), dtype)
    np.copyto(planar, words.T)  # all x words, then all y words (then all w words)
    if transform != BYTE_SHUFFLE:
        # Residuals modulo 2^W of the prediction (the previous word, or 2 w[i-1] - w[i-2]).
        residual = _scratch.get("residual", (axes, n), dtype)
        residual[:, :1] = planar[:, :1]
        np.subtract(planar[:, 1:], planar[:, :-1], out=residual[:, 1:])
        if transform == DELTA2_SHUFFLE:
            np.subtract(residual[:, 2:], planar[:, 1:-1], out=residual[:, 2:])
            np.add(residual[:, 2:], planar[:, :-2], out=residual[:, 2:])
            if n > 1:
                np.subtract(residual[:, 1], planar[:, 0], out=residual[:, 1])
        # zigzag: (d << 1) XOR (d >> (W - 1)), the shift right arithmetic; `planar` is free now.
        signed = dtype.str.replace("u", "i")
        np.right_shift(residual.view(signed), 8 * width - 1, out=planar.view(signed))
        np.left_shift(residual, dtype.type(1), out=residual)
        np.bitwise_xor(residual, planar, out=planar)
    # Byte planes: byte 0 of every word, then byte 1, ...
    planes = _scratch.get("planes", (width, axes * n), np.uint8)
    np.copyto(planes, planar.reshape(-1).view(np.uint8).reshape(-1, width).T)
    return planes.reshape(-1)


def transform_words(words: np.ndarray, transform: int) -> bytes:
    """Interleaved (n, axes) unsigned words to the transform's bytes (the proto's PointTransform)."""
    return _transformed(words, transform).tobytes()


def untransform_words(data: bytes, n: int, transform: int, word: str, axes: int = 2) -> np.ndarray:
    """The inverse of transform_words: (n, axes) words of dtype `word`."""
    dtype = np.dtype(word)
    if transform in (0, NONE):
        return np.frombuffer(data, dtype=dtype).reshape(n, axes)
    width = dtype.itemsize
    planar = (
        np.ascontiguousarray(np.frombuffer(data, dtype=np.uint8).reshape(width, axes * n).T).view(dtype).reshape(axes, n)
    )
    if transform != BYTE_SHUFFLE:
        one = dtype.type(1)
        residual = (planar >> one) ^ (dtype.type(0) - (planar & one))
        # w[i] = r[i] + w[i-1]; and with r[i] = w[i] - 2 w[i-1] + w[i-2], the first difference of
        # w is the running sum of r: two running sums (modulo 2^W) undo the linear prediction.
        planar = np.cumsum(residual, axis=1, dtype=dtype)
        if transform == DELTA2_SHUFFLE:
            planar = np.cumsum(planar, axis=1, dtype=dtype)
    return np.ascontiguousarray(planar.T)


# ---- Messages ------------------------------------------------------------------------------------


def _zstd() -> Optional[object]:
    """This thread's zstd compressor (a ZstdCompressor is not thread-safe); None without the
    zstandard package (then nothing is compressed)."""
    if _scratch.compressor is False:
        try:
            import zstandard
        except ImportError:
            _scratch.compressor = None
        else:
            _scratch.compressor = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
    return _scratch.compressor  # type: ignore[return-value]


def _double_field(number: int, value: float) -> bytes:
    return _wire._varint((number << 3) | _wire._I64) + struct.pack("<d", value)


def _varint_field(number: int, value: int) -> bytes:
    return _wire._varint((number << 3) | _wire._VARINT) + _wire._varint(value)


def _axis_scale_message(scale: AxisScale) -> bytes:
    out = _double_field(2 if scale.divide else 1, scale.step)
    if scale.offset != 0:  # proto3: a zero offset is not sent (the client never sends -0.0)
        out += _double_field(3, scale.offset)
    return out


def _words(points: np.ndarray, encoding: ChunkEncoding, integers: Optional[np.ndarray]) -> np.ndarray:
    if encoding.value_type == FLOAT64:
        return np.ascontiguousarray(points, dtype="<f8").view("<u8")
    assert integers is not None
    if encoding.value_type == INT32:
        narrow = _scratch.get("narrow", integers.shape, "<i4")
        np.copyto(narrow, integers, casting="unsafe")
        return narrow.view("<u4")
    return integers.astype("<i8", copy=False).view("<u8")


def _chunk_data(points: np.ndarray, encoding: ChunkEncoding, integers: Optional[np.ndarray]) -> bytes:
    data = _transformed(_words(points, encoding, integers), encoding.transform)
    if encoding.compression == ZSTD:
        compressor = _zstd()
        if compressor is None:
            raise RuntimeError("zstd compression needs the zstandard package")
        return compressor.compress(data)  # type: ignore[attr-defined]
    return data.tobytes()


def scaled_integers(points: np.ndarray, encoding: ChunkEncoding) -> np.ndarray:
    """The (n, axes) int64 integers of `points` under the encoding's scales; InvalidInput naming
    the first value they do not reproduce bit for bit or that does not fit the value type."""
    out = np.empty(points.shape, dtype=np.int64)
    for axis, scale in enumerate(encoding.scales(points.shape[1])):
        if scale is None:
            raise InvalidInput(f"an integer encoding needs a {_AXIS_NAMES[axis]}_scale")
        values = np.ascontiguousarray(points[:, axis], dtype=np.float64)
        x = _estimate(values, np.float64(scale.step), np.bool_(scale.divide), np.float64(scale.offset))
        with np.errstate(all="ignore"):
            good = (np.abs(x) <= _MAX_EXACT_INTEGER) & (scale.values(x).view(np.uint64) == values.view(np.uint64))
            if encoding.value_type == INT32:
                good &= (x >= -(2.0**31)) & (x < 2.0**31)
        if not np.all(good):
            i = int(np.argmin(good))
            raise InvalidInput(f"point {i}'s {_AXIS_NAMES[axis]} ({values[i]!r}) is not an integer under {scale}")
        out[:, axis] = x.astype(np.int64)
    return out


def encode_chunk(points: np.ndarray, encoding: ChunkEncoding, integers: Optional[np.ndarray] = None) -> bytes:
    """The EncodedPointChunk message of (n, 2) float64 `points` (weighted: (n, 3)), 1 to 262,144
    of them, as `encoding` says.
    `integers`: the points' integers under the encoding's scales, when the caller has them (else
    computed and verified here)."""
    n = len(points)
    if not 1 <= n <= MAX_POINTS_PER_ENCODED_CHUNK:
        raise InvalidInput(f"an encoded chunk holds 1 to {MAX_POINTS_PER_ENCODED_CHUNK} points, not {n}")
    if encoding.value_type != FLOAT64 and integers is None:
        integers = scaled_integers(points, encoding)
    return _chunk_message(n, encoding, _chunk_data(points, encoding, integers), points.shape[1])


def _chunk_message(n: int, encoding: ChunkEncoding, data: bytes, axes: int = 2) -> bytes:
    head = _varint_field(1, n) + _varint_field(2, encoding.value_type)
    if encoding.value_type != FLOAT64:
        assert encoding.x_scale is not None and encoding.y_scale is not None
        head += _wire._len_field(3, _axis_scale_message(encoding.x_scale))
        head += _wire._len_field(4, _axis_scale_message(encoding.y_scale))
    head += _varint_field(5, encoding.transform) + _varint_field(6, encoding.compression)
    head += _wire._varint((7 << 3) | _wire._LEN) + _wire._varint(len(data)) + data
    if encoding.value_type != FLOAT64 and axes == 3:
        assert encoding.w_scale is not None
        head += _wire._len_field(8, _axis_scale_message(encoding.w_scale))
    return head


def encoded_request(chunk_message: bytes) -> bytes:
    """BuildRequest{encoded_points: chunk}."""
    return _wire._len_field(3, chunk_message)


def _sample(n: int) -> int:
    """Points of a chunk its form is chosen on: all up to 16,384 (the choice is then exact), else
    the first 8,192 (the eight trial compressions then cost about one of the whole chunk)."""
    return n if n <= 16384 else 8192


def _best_transform(points: np.ndarray, encoding: ChunkEncoding, integers: Optional[np.ndarray]) -> Tuple[ChunkEncoding, int]:
    best, best_size = encoding, -1
    for transform in TRANSFORMS:
        trial = dataclasses.replace(encoding, transform=transform, compression=ZSTD)
        size = len(_chunk_data(points, trial, integers))
        if best_size < 0 or size < best_size:
            best, best_size = trial, size
    return best, best_size


def choose_encoding(points: np.ndarray) -> Tuple[Optional[ChunkEncoding], Optional[np.ndarray]]:
    """The smallest form for `points` on its sample (float64 and, where the data has them, scaled
    integers, each with its best transform under zstd), and the integers when they win; (None,
    None) when zstd is unavailable and the data has no integers (then raw doubles are smallest)."""
    m = _sample(len(points))
    scaled = find_scaled_integers(points, scratch=True)
    if _zstd() is None:
        if scaled is None:
            return None, None
        return scaled.encoding(), scaled.integers
    chosen, size = _best_transform(points[:m], ChunkEncoding(FLOAT64), None)
    if scaled is not None:
        # Integers usually win by far; power-of-two steps of full-precision doubles (lon/lat in one
        # binade) are the same bits and can lose by a few bytes.
        as_integers = scaled.encoding()
        trial, trial_size = _best_transform(points[:m], as_integers, scaled.integers[:m])
        if trial_size <= size:
            return trial, scaled.integers
    return chosen, None


def encode_smallest(points: np.ndarray) -> bytes:
    """The BuildRequest of one chunk of (n, 2) float64 `points` (weighted: (n, 3)) in its smallest
    form: an EncodedPointChunk, or a raw PointChunk when no encoding beats 8 bytes a value."""
    n, axes = points.shape
    if n == 0 or n > MAX_POINTS_PER_ENCODED_CHUNK:
        return _wire.encode_point_chunk_request(points)
    encoding, integers = choose_encoding(points)
    if encoding is None:
        return _wire.encode_point_chunk_request(points)
    data = _chunk_data(points, encoding, integers)
    width = _WORD[encoding.value_type][2]
    if len(data) >= axes * n * width and encoding.compression == ZSTD:
        if encoding.value_type == FLOAT64:
            return _wire.encode_point_chunk_request(points)
        encoding = dataclasses.replace(encoding, transform=NONE, compression=UNCOMPRESSED)
        data = _chunk_data(points, encoding, integers)
    message = _chunk_message(n, encoding, data, axes)
    # A raw chunk is 8 bytes a value plus a few of framing: the encoded one must beat that.
    if len(message) >= 8 * axes * n:
        return _wire.encode_point_chunk_request(points)
    return encoded_request(message)


# ---- Decoding (the executable spec; the server's decoder is the C++ PointChunkDecoder) ------------


def _decode_axis_scale(payload: memoryview) -> AxisScale:
    step, divide, offset = math.nan, False, 0.0
    for number, _, value in _wire.fields(bytes(payload)):
        as_double = struct.unpack("<d", int(value).to_bytes(8, "little"))[0]  # type: ignore[arg-type]
        if number in (1, 2):
            step, divide = as_double, number == 2
        elif number == 3:
            offset = as_double
    return AxisScale(step, divide, offset)


def decode_chunk(message: bytes, axes: int = 2) -> np.ndarray:
    """The (n, 2) float64 points of an EncodedPointChunk message (a weighted stream's: (n, 3), with
    `axes` 3); ValueError for what the server refuses (a malformed chunk, a size mismatch, an INT64
    integer over 2^53)."""
    n = value_type = transform = compression = 0
    scales: List[Optional[AxisScale]] = [None, None, None]
    data = b""
    for number, _, value in _wire.fields(message):
        if number == 1:
            n = int(value)  # type: ignore[arg-type]
        elif number == 2:
            value_type = int(value)  # type: ignore[arg-type]
        elif number in (3, 4):
            scales[number - 3] = _decode_axis_scale(value)  # type: ignore[arg-type]
        elif number == 5:
            transform = int(value)  # type: ignore[arg-type]
        elif number == 6:
            compression = int(value)  # type: ignore[arg-type]
        elif number == 7:
            data = bytes(value)  # type: ignore[arg-type]
        elif number == 8:
            if axes != 3:
                raise ValueError("a w_scale in an unweighted stream")
            scales[2] = _decode_axis_scale(value)  # type: ignore[arg-type]
    if not 1 <= n <= MAX_POINTS_PER_ENCODED_CHUNK or value_type not in _WORD:
        raise ValueError(f"bad point_count {n} or value_type {value_type}")
    word, signed, width = _WORD[value_type]
    expected = axes * n * width
    if compression == ZSTD:
        import zstandard

        data = zstandard.ZstdDecompressor().decompress(data, max_output_size=expected)
    if len(data) != expected:
        raise ValueError(f"the data is {len(data)} bytes; {n} points of {width}-byte words are {expected}")
    words = untransform_words(data, n, transform, word, axes)
    if value_type == FLOAT64:
        return words.view("<f8").astype(np.float64)
    integers = words.view(signed).astype(np.int64)
    if np.any(np.abs(integers) > (1 << 53)):
        raise ValueError("an INT64 value is over 2^53 in magnitude")
    out = np.empty((n, axes), dtype=np.float64)
    for axis in range(axes):
        scale = scales[axis]
        if scale is None:
            raise ValueError(f"an integer chunk needs {_AXIS_NAMES[axis]}_scale")
        with np.errstate(all="ignore"):
            out[:, axis] = scale.values(integers[:, axis])
    return out


def decode_request(request: bytes, axes: int = 2) -> np.ndarray:
    """The points of one BuildRequest carrying points (raw or encoded); `axes` 3 for a weighted
    stream's (x, y, w)."""
    number, payload = _wire.split_oneof(request)
    if number == 2:
        for field, wire, value in _wire.fields(bytes(payload)):
            if field == 1:
                return _wire._packed(value, wire, "<f8").reshape(-1, axes).astype(np.float64)
        return np.empty((0, axes))
    if number == 3:
        return decode_chunk(bytes(payload), axes)
    raise ValueError(f"BuildRequest field {number} carries no points")
