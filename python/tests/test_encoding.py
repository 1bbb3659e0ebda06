"""The compact point encodings of the Build stream (galpha._encoding): the decoder inverts the
encoder bit for bit in every form, the scale search finds what the C++ client finds and nothing
inexact, the server decodes every form to the same handle, and encoding="auto" sends each data set
in no more than 2% over the C++ client's bytes per point (docs/design.md, "Wire encodings of
points") with the answers of encoding="raw"."""

from __future__ import annotations

import asyncio
import dataclasses
import itertools
import math

import numpy as np
import pytest
from conftest import DATA_SETS, read_bin

import galpha
import galpha.aio
from galpha import _encoding as E
from galpha import _network
from galpha.v1 import alpha_shapes_pb2 as pb

#: Bytes per point of the C++ client's encoding (PointEncoding::kAuto, zstd 3), docs/design.md
#: "What reaches the wire" and bench/README.md.
CPP_BYTES_PER_POINT = {
    "lidar_autzen": 1.95,
    "gps_tracks_slovenia_croatia": 5.03,
    "lidar_autzen_ground": 2.93,
    "lidar_autzen_ground_lonlat": 8.44,
    "lidar_haystack_rock": 3.78,
    "ourairports_medium_large": 12.40,
    "pdb_2xhe_proj": 3.52,
}


def bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def awkward() -> np.ndarray:
    """-0.0, subnormals, the extremes of the doubles, ties and neighbours."""
    tiny = np.nextafter(0.0, 1.0)
    values = [-0.0, 0.0, tiny, -tiny, 2.2250738585072014e-308, 1e-310, 1.7976931348623157e308, -1.7976931348623157e308,
              1e300, -1e-300, 0.1, 0.30000000000000004, 1.0, np.nextafter(1.0, 2.0), 2.0**53, -(2.0**53) - 2, 123456.789]
    rng = np.random.default_rng(5)
    return np.array(values + list(rng.permutation(values))).reshape(-1, 2)


def decimal() -> np.ndarray:
    rng = np.random.default_rng(6)
    return np.round(rng.uniform(-180, 180, (3000, 2)), 6)  # as decimal text parses: X / 10^6


def las_like() -> np.ndarray:
    """A LAS tile: offset + 0.01 * X with round offsets, a scan line's smooth walk."""
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.integers(-40, 60, 5000))
    y = np.cumsum(rng.integers(-5, 5, 5000)) + 10_000
    return np.stack([637000.0 + 0.01 * x, 200000.0 + 0.01 * y], axis=1)


def wide_integers() -> np.ndarray:
    """Lon/lat in units of 10^-9 degree: integers past 2^31 (INT64)."""
    rng = np.random.default_rng(8)
    x = rng.integers(14_000_000_000, 16_000_000_000, 2000)
    y = rng.integers(45_000_000_000, 46_000_000_000, 2000)
    return np.stack([x, y], axis=1) / 1e9


FLOAT_ARRAYS = {
    "awkward": awkward,
    "decimal": decimal,
    "las_like": las_like,
    "wide_integers": wide_integers,
    "uniform": lambda: np.random.default_rng(9).random((4000, 2)),
    "one_point": lambda: np.array([[3.5, -2.25]]),
    "two_points": lambda: np.array([[3.5, -2.25], [-1e300, 7.0]]),
}
INTEGER_ARRAYS = {"decimal": decimal, "las_like": las_like, "wide_integers": wide_integers}
FORMS = list(itertools.product(E.TRANSFORMS + (0,), (E.UNCOMPRESSED, E.ZSTD, 0)))


@pytest.mark.parametrize("name", sorted(FLOAT_ARRAYS))
@pytest.mark.parametrize("transform,compression", FORMS)
def test_float64_round_trips_bit_for_bit(name: str, transform: int, compression: int) -> None:
    points = FLOAT_ARRAYS[name]()
    message = E.encode_chunk(points, E.ChunkEncoding(E.FLOAT64, transform, compression))
    np.testing.assert_array_equal(bits(E.decode_chunk(message)), bits(points))


@pytest.mark.parametrize("name", sorted(INTEGER_ARRAYS))
@pytest.mark.parametrize("value_type", [E.INT32, E.INT64])
@pytest.mark.parametrize("transform,compression", FORMS)
def test_scaled_integers_round_trip_bit_for_bit(name: str, value_type: int, transform: int, compression: int) -> None:
    points = INTEGER_ARRAYS[name]()
    scaled = E.find_scaled_integers(points)
    assert scaled is not None
    encoding = E.ChunkEncoding(value_type, transform, compression, scaled.x_scale, scaled.y_scale)
    if value_type == E.INT32 and scaled.value_type == E.INT64:
        with pytest.raises(galpha.InvalidInput, match="not an integer"):
            E.encode_chunk(points, encoding)
        return
    message = E.encode_chunk(points, encoding)
    np.testing.assert_array_equal(bits(E.decode_chunk(message)), bits(points))
    # The hand-made bytes are the protobuf message the generated classes read.
    parsed = pb.EncodedPointChunk.FromString(message)
    assert parsed.point_count == len(points) and parsed.value_type == value_type
    assert parsed.transform == transform and parsed.compression == compression
    assert parsed.x_scale.WhichOneof("step") == ("divisor" if scaled.x_scale.divide else "scale")
    assert parsed.x_scale.offset == scaled.x_scale.offset and parsed.y_scale.offset == scaled.y_scale.offset


def test_the_scale_search_finds_exact_steps_only() -> None:
    found = E.find_scaled_integers(decimal())
    assert found is not None and found.value_type == E.INT32
    # X / 10^6 reproduces decimal text; fl(10^-6) * X does not always (0.1 * 3 != 0.3).
    assert (found.x_scale.divide, found.x_scale.step) == (True, 1e6)
    # lidar_haystack_rock's y is 200000 + fl(0.01) * Y (without the offset 42% of them miss).
    las = E.find_scaled_integers(read_bin(next(p for p in DATA_SETS if p.stem == "lidar_haystack_rock")))
    assert las is not None and las.y_scale == E.AxisScale(0.01, offset=200000.0)
    wide = E.find_scaled_integers(wide_integers())
    assert wide is not None and wide.value_type == E.INT64 and wide.x_scale == E.AxisScale(1e9, divide=True)
    # -0.0 decodes from no integer (0 + 0 * X is +0.0); NaN, infinities and uniform data have none.
    assert E.find_scaled_integers(np.array([[-0.0, 1.0], [2.0, 3.0]])) is None
    assert E.find_scaled_integers(np.array([[np.nan, 1.0]])) is None
    assert E.find_scaled_integers(np.array([[np.inf, 1.0]])) is None
    assert E.find_scaled_integers(awkward()) is None
    # A power of two: doubles of one binade share a step (NumPy's random() gives k * 2^-53).
    uniform = E.find_scaled_integers(np.random.default_rng(1).random((1000, 2)))
    assert uniform is not None and uniform.x_scale == E.AxisScale(2.0**-53) and uniform.value_type == E.INT64


def test_every_found_scale_reproduces_each_value_with_separate_roundings() -> None:
    for make in INTEGER_ARRAYS.values():
        points = make()
        found = E.find_scaled_integers(points)
        assert found is not None
        for axis, scale in enumerate((found.x_scale, found.y_scale)):
            for i in range(0, len(points), 97):  # Python floats: one rounding per operation
                x = float(found.integers[i, axis])
                value = scale.offset + (x / scale.step if scale.divide else scale.step * x)
                assert value.hex() == float(points[i, axis]).hex()


def test_an_integer_encoding_refuses_an_inexact_value() -> None:
    with pytest.raises(galpha.InvalidInput, match=r"point 1's x"):
        quarters = E.ChunkEncoding(E.INT32, x_scale=E.AxisScale(0.25), y_scale=E.AxisScale(1.0))
        E.encode_chunk(np.array([[0.25, 1.0], [0.3, 2.0]]), quarters)


def test_the_smallest_form_is_raw_when_nothing_beats_16_bytes_a_point() -> None:
    one = np.random.default_rng(2).random((1, 2)) * math.pi
    assert _network._wire.split_oneof(E.encode_smallest(one))[0] == 2  # PointChunk
    request = pb.BuildRequest.FromString(E.encode_smallest(las_like()))
    assert request.WhichOneof("part") == "encoded_points"
    assert request.encoded_points.value_type == E.INT32 and request.encoded_points.compression == E.ZSTD
    for make in FLOAT_ARRAYS.values():
        points = make()
        np.testing.assert_array_equal(bits(E.decode_request(E.encode_smallest(points))), bits(points))


def test_encoding_is_checked(server) -> None:
    points = np.array([[0, 0], [1, 0], [0, 1.0]])
    with galpha.connect(server.address, timeout=60) as c:
        with pytest.raises(galpha.InvalidInput, match="unknown encoding 'nope'"):
            c.build(points, encoding="nope")
    with galpha.local("cpu") as c:
        with pytest.raises(galpha.InvalidInput, match="unknown encoding"):
            c.build(points, encoding="nope")
        assert c.build(points, encoding="raw").summary.upload_bytes == 0

    async def run() -> None:
        async with galpha.aio.connect(server.address, timeout=60) as c:
            await c.build(points, encoding=None)  # type: ignore[arg-type]

    with pytest.raises(galpha.InvalidInput, match="unknown encoding None"):
        asyncio.run(run())


@pytest.mark.parametrize("value_type", [E.FLOAT64, E.INT32, E.INT64])
@pytest.mark.parametrize("transform,compression", FORMS)
def test_weighted_points_round_trip_bit_for_bit_with_their_weights(value_type: int, transform: int, compression: int) -> None:
    """(x, y, w) chunks of a weighted stream: the weight is a third axis with its own scale."""
    points = las_like()
    radii = np.random.default_rng(8).integers(120, 201, len(points))  # 1.20 to 2.00 A, squared: X / 10^4
    weighted = np.column_stack((points, (radii * radii) / 1e4))
    scaled = E.find_scaled_integers(weighted)
    assert scaled is not None and scaled.w_scale is not None
    encoding = E.ChunkEncoding(value_type, transform, compression) if value_type == E.FLOAT64 else dataclasses.replace(
        scaled.encoding(transform, compression), value_type=value_type
    )
    message = E.encode_chunk(weighted, encoding)
    np.testing.assert_array_equal(bits(E.decode_chunk(message, axes=3)), bits(weighted))
    parsed = pb.EncodedPointChunk.FromString(message)
    assert parsed.HasField("w_scale") == (value_type != E.FLOAT64)
    with pytest.raises(ValueError):
        E.decode_chunk(message)  # as two axes: the sizes disagree (or a w_scale in an unweighted stream)


def test_the_server_decodes_every_form_to_the_same_points(client) -> None:
    """Each value type x transform x compression in one Build stream per form: the server's
    handle is the hash of what it decoded, so an equal handle is an equal decoding."""
    points = las_like()
    handle = galpha.point_set_handle(points)
    scaled = E.find_scaled_integers(points)
    assert scaled is not None and scaled.value_type == E.INT32
    for value_type, (transform, compression) in itertools.product((E.FLOAT64, E.INT32, E.INT64), FORMS):
        scales = (None, None) if value_type == E.FLOAT64 else (scaled.x_scale, scaled.y_scale)
        encoding = E.ChunkEncoding(value_type, transform, compression, *scales)
        messages = [_network.header_message("", points)] + [
            E.encoded_request(E.encode_chunk(points[b:e], encoding)) for b, e in [(0, 1), (1, 2), (2, 2500), (2500, 5000)]
        ]
        answer = client._calls.build(iter(messages), timeout=60, metadata=client._calls.metadata(handle))
        assert answer.handle == handle, encoding


@pytest.mark.parametrize("path", DATA_SETS, ids=[p.stem for p in DATA_SETS])
def test_auto_and_raw_build_the_same_family(client, path) -> None:
    points = read_bin(path)
    handle = galpha.point_set_handle(points)
    try:
        client.family(handle, points).release()
    except galpha.NotFound:
        pass
    auto = client.build(points, encoding="auto")
    raw = client.build(points, encoding="raw")
    assert auto.handle == raw.handle == handle
    assert auto.summary.cached is False and raw.summary.cached is True
    # Cached: nothing uploaded; a fresh upload in raw doubles is 16 bytes a point plus framing.
    assert raw.summary.upload_bytes == 0
    per_point = auto.summary.upload_bytes / len(points)
    cpp = CPP_BYTES_PER_POINT[path.stem]
    print(f"{path.stem}: {per_point:.2f} bytes a point (C++ client {cpp:.2f})")
    assert 0 < per_point <= 1.02 * cpp  # the same choices as the C++ encoder: equal sizes with the same zstd
    raw.release()
    fresh_raw = client.build(points, encoding="raw")
    assert fresh_raw.summary.cached is False and 16 * len(points) < fresh_raw.summary.upload_bytes < 16.01 * len(points) + 64
    k = auto.summary.spectrum_size
    a, b = auto.classify(rank=k // 2), fresh_raw.classify(rank=k // 2)
    for field in ("vertices", "vertex_classes", "edges", "edge_classes", "triangles", "triangle_classes"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert a.vertex_counts == b.vertex_counts and a.components == b.components


def test_many_chunks_arrive_in_order_with_progress(client) -> None:
    """11 chunks encoded on the pool: order, progress and bytes as for one thread."""
    rng = np.random.default_rng(13)
    points = np.round(rng.uniform(0, 1000, (11 * 65536 - 7, 2)), 2)
    reports = []
    family = client.build(points, progress=lambda stage, f: reports.append((stage, f)))
    assert family.handle == galpha.point_set_handle(points)
    seen = [f for stage, f in reports if stage == "upload"]
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) == 11
    assert reports[-1] == ("build", 1.0)  # then the wait for the server's build
    expected = sum(len(E.encode_smallest(points[b:e])) for b, e in _network.chunk_bounds(points))
    assert family.summary.upload_bytes == expected
    family.release()

    async def run() -> int:
        async with galpha.aio.connect(client.target, timeout=120) as c:
            f = await c.build(points)
            assert f.handle == family.handle and f.summary.cached is False
            return f.summary.upload_bytes

    assert asyncio.run(run()) == expected


def test_without_zstd_auto_sends_plain_integers_or_raw_doubles() -> None:
    saved = E._scratch.compressor
    E._scratch.compressor = None  # as if the zstandard package were missing
    try:
        request = pb.BuildRequest.FromString(E.encode_smallest(las_like()))
        assert request.encoded_points.value_type == E.INT32 and request.encoded_points.compression == E.UNCOMPRESSED
        assert pb.BuildRequest.FromString(E.encode_smallest(awkward())).WhichOneof("part") == "points"
        np.testing.assert_array_equal(bits(E.decode_request(request.SerializeToString())), bits(las_like()))
    finally:
        E._scratch.compressor = saved
