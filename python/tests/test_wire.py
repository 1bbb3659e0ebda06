"""The decoders of compact Classify chunks (galpha._wire.decode_encoded_simplex_chunk: NumPy, and
the compiled module's C++ reader) on chunks written by hand from the proto's text and by this
file's own encoder of that text, and every refusal the proto lists, named by chunk, with the same
message from both. That they decode the server's chunks to the raw answer is test_network.py's
test_every_answer_encoding_gives_the_raw_answer."""

from __future__ import annotations

from typing import Callable, List, Tuple

import numpy as np
import pytest
import zstandard

from galpha import _wire


@pytest.fixture(params=["numpy", "native"])
def decode(request: pytest.FixtureRequest) -> Callable[[memoryview, int], Tuple[int, np.ndarray, np.ndarray]]:
    """decode_encoded_simplex_chunk with NumPy, or with the C++ reader of galpha._engine."""
    reader = None
    if request.param == "native":
        reader = _wire.native_section_reader()
        assert reader is not None, "galpha._engine is built with the package (python/engine)"
    return lambda message, index: _wire.decode_encoded_simplex_chunk(message, index, reader)


def _varint(value: int) -> bytes:
    return _wire._varint(value)


def chunk(kind: int, count: int, data: bytes, encoding: int = 2) -> memoryview:
    """An EncodedSimplexChunk message: kind (1), simplex_count (2), encoding (3), data (4)."""
    out = b""
    for number, value in ((1, kind), (2, count), (3, encoding)):
        if value:
            out += _varint(number << 3) + _varint(value)
    out += _wire._len_field(4, data)
    return memoryview(out)


def test_decodes_the_layout_the_proto_documents(decode) -> None:
    # Edges (3, 7), (3, 9), (4, 5), classes EXTERIOR, SINGULAR, INTERIOR (the C++ codec test's).
    kind, indices, classes = decode(chunk(2, 3, bytes([0x34, 3, 3, 0, 1, 1, 0])), 0)
    assert kind == 2
    assert indices.dtype == np.uint32 and indices.tolist() == [3, 7, 3, 9, 4, 5]
    assert classes.dtype == np.uint8 and classes.tolist() == [1, 2, 4]
    # Vertices 1 and 300 (a two-byte varint), classes REGULAR then SINGULAR.
    _, indices, classes = decode(chunk(1, 2, bytes([0x06, 1, 0xAA, 2])), 0)
    assert indices.tolist() == [1, 300] and classes.tolist() == [3, 2]
    # Triangles (1, 2, 5), (1, 2, 6), (1, 3, 4), (2, 3, 4): every prefix rule.
    data = bytes([0x00, 1, 0, 2, 0, 0, 0, 0, 1, 0, 1, 0, 0])
    # (1,2,5): 1, 2-1-1=0, 5-2-1=2; (1,2,6): 0, 0, 6-5-1=0; (1,3,4): 0, 3-2=1, 4-3-1=0; (2,3,4): 1, 0, 0.
    _, indices, _ = decode(chunk(3, 4, data), 0)
    assert indices.reshape(-1, 3).tolist() == [[1, 2, 5], [1, 2, 6], [1, 3, 4], [2, 3, 4]]
    # The same bytes in a zstd frame.
    framed = zstandard.ZstdCompressor().compress(data)
    _, again, _ = decode(chunk(3, 4, framed, encoding=3), 0)
    np.testing.assert_array_equal(again, indices)


@pytest.mark.parametrize(
    "message, match",
    [
        (chunk(0, 1, b"\x00\x05"), "not a simplex kind"),
        (chunk(1, 1, b"\x00\x05", encoding=1), "not DELTA"),
        (chunk(1, 0, b""), "states 0 simplices"),
        (chunk(1, (1 << 20) + 1, b"\x00\x05"), "a chunk holds 1 to"),
        (chunk(1, 1, b""), "before its 1 bytes of classes"),
        (chunk(1, 1, b"\x04\x05"), "unused bits"),
        (chunk(2, 1, b"\x00\x05"), "truncated"),
        (chunk(1, 1, b"\x00\x85"), "truncated"),
        (chunk(2, 1, b"\x00\x80\x80\x80\x80\x80\x00"), "longer than 5 bytes"),
        (chunk(1, 1, b"\x00\x80\x80\x80\x80\x10"), "over 2\\^32 - 1"),
        (chunk(2, 1, b"\x00\xff\xff\xff\xff\x0f\x00"), "over 2\\^32 - 1"),
        (chunk(1, 1, b"\x00\x05\x00"), "bytes after"),
        (chunk(1, 1, b"\x00" * 7), "more than"),
        (chunk(1, 1, b"\x00\x05", encoding=3), "not a zstd frame"),
        (chunk(1, 1, zstandard.ZstdCompressor().compress(b"\x00\x05") + b"x", encoding=3), "after its zstd frame"),
        (chunk(1, 1, zstandard.ZstdCompressor().compress(b"\x00" * 10_000_000), encoding=3), "decompresses to more than"),
    ],
)
def test_malformed_chunks_are_refused_naming_the_chunk(decode, message: memoryview, match: str) -> None:
    with pytest.raises(_wire.EncodedChunkError, match="^encoded simplex chunk 17: .*" + match):
        decode(message, 17)


def test_fields_of_the_wrong_wire_type_are_refused(decode) -> None:
    # Field 4 (data) as a varint of a huge value: refused before anything is allocated for it.
    message = memoryview(_varint(1 << 3) + _varint(1) + _varint(2 << 3) + _varint(1) + _varint(3 << 3) + _varint(2) + _varint(4 << 3) + _varint(1 << 40))
    with pytest.raises(_wire.EncodedChunkError, match="field 4\\) has wire type 0"):
        decode(message, 3)
    # The count as bytes.
    message = memoryview(_varint(1 << 3) + _varint(1) + _wire._len_field(2, b"\x01"))
    with pytest.raises(_wire.EncodedChunkError, match="field 2 has wire type 2"):
        decode(message, 3)


def test_a_frame_that_declares_a_small_size_is_bounded_by_its_output(decode) -> None:
    # A frame whose header declares the chunk's bound but whose blocks hold far more: refused after
    # at most bound + 1 bytes of output. Built by rewriting the content size of a real frame: zstd
    # checks it only at the frame's end.
    plain = b"\x00" * 5_000_000
    frame = bytearray(zstandard.ZstdCompressor(write_content_size=False, write_checksum=False).compress(plain))
    # Frame header descriptor: Frame_Content_Size_flag = 2 (a 4-byte size after the window byte).
    magic, descriptor = bytes(frame[:4]), frame[4]
    assert descriptor & 0xC0 == 0 and descriptor & 0x20 == 0  # no size, not single-segment: a window byte follows
    header = magic + bytes([descriptor | 0x80]) + bytes(frame[5:6]) + (6).to_bytes(4, "little")
    lying = header + bytes(frame[6:])
    assert zstandard.frame_content_size(lying) == 6
    with pytest.raises(_wire.EncodedChunkError, match="decompresses to more than the 6 bytes|corrupt"):
        decode(chunk(1, 1, lying, encoding=3), 0)


def test_a_frame_without_its_size_is_bounded_too(decode) -> None:
    # zstd's streaming compressor leaves the content size out of the frame header.
    stream = zstandard.ZstdCompressor(write_content_size=False).compressobj()
    bomb = stream.compress(b"\x00" * 1_000_000) + stream.flush()
    assert zstandard.frame_content_size(bomb) == -1
    with pytest.raises(_wire.EncodedChunkError, match="decompresses to more than the 6 bytes"):
        decode(chunk(1, 1, bomb, encoding=3), 0)


def encode_sections(simplices: List[Tuple[int, ...]], classes: List[int]) -> bytes:
    """The data of a DELTA chunk, written from the proto's text: classes 2 bits each from the low
    bits, then each index as a varint of its difference from the index before it."""
    packed = bytearray((len(classes) + 3) // 4)
    for i, c in enumerate(classes):
        packed[i // 4] |= (c - 1) << (2 * (i % 4))
    out = bytes(packed)
    previous: Tuple[int, ...] = ()
    for simplex in simplices:
        same = bool(previous)  # the prefix before position k equals the previous simplex's
        for k, index in enumerate(simplex):
            if same:
                value = index - previous[k] - (1 if k == len(simplex) - 1 else 0)
                same = index == previous[k]
            elif k == 0:
                value = index
            else:
                value = index - simplex[k - 1] - 1
            out += _varint(value)
        previous = simplex
    return out


@pytest.mark.parametrize("arity, zstd", [(1, False), (2, False), (3, False), (3, True)])
def test_random_chunks_decode_to_what_was_encoded(decode, arity: int, zstd: bool) -> None:
    rng = np.random.default_rng(arity * 10 + zstd)
    for trial in range(20):
        count = int(rng.integers(1, 3000))
        # Distinct sorted simplices with sorted vertices, some near 2^32 - 1 and some sharing prefixes.
        top = int(rng.choice([50, 100_000, 2**32 - 1]))
        rows = {tuple(sorted(int(v) for v in rng.choice(top + 1, size=arity, replace=False))) for _ in range(count)}
        simplices = sorted(rows)
        classes = [int(c) for c in rng.integers(1, 5, size=len(simplices))]
        data = encode_sections(simplices, classes)
        if zstd:
            data = zstandard.ZstdCompressor().compress(data)
        kind, indices, got = decode(chunk(arity, len(simplices), data, encoding=3 if zstd else 2), trial)
        assert kind == arity
        assert indices.reshape(-1, arity).tolist() == [list(s) for s in simplices]
        assert got.tolist() == classes
