"""Holes of the shape from Python: Family.holes (each hole of the regularized shape with its area,
largest first) and shape(min_hole_area=...) (holes below an area filled), on both clients and
galpha.aio, against `alphactl holes` (the C++ command line: core's ListHoles and RingArea, an
independent path from the package's network-side measurement).

The fixture is the 12 x 12 integer grid without the 3 x 3 block i, j in 4..6: at alpha_sq 0.5 (the
unit squares' circumradius squared) its regularized shape is the grid's square with one octagonal
hole (the block and its 12 boundary points' squares: 5 x 5 less the 4 corner half-squares = 14).
"""

from __future__ import annotations

import asyncio
import functools
import pathlib
import subprocess
from fractions import Fraction
from typing import List, Tuple

import numpy as np
import pytest
from conftest import REPO, read_bin

import galpha
import galpha.aio
from galpha import _local, _network
from galpha._family import exact_ring_area, ring_area
from galpha._types import Threshold

AUTZEN = REPO / "data" / "lidar_autzen_ground.bin"
AUTZEN_RANK = 20000


def grid_with_hole() -> np.ndarray:
    cells = [(i, j) for i in range(12) for j in range(12) if not (4 <= i <= 6 and 4 <= j <= 6)]
    return np.array(cells, dtype=np.float64)


def write_bin(path: pathlib.Path, points: np.ndarray) -> pathlib.Path:
    """A data/*.bin file (little-endian uint64 N, then the float64 pairs), as alphactl reads it."""
    header = np.array([len(points)], dtype="<u8").tobytes()
    path.write_bytes(header + np.ascontiguousarray(points, dtype="<f8").tobytes())
    return path


#: A hole as `alphactl holes` prints it: area, polygon index, the closed ring's coordinates.
Row = Tuple[float, int, List[Tuple[float, float]]]


@functools.lru_cache(maxsize=None)
def alphactl_holes(alphactl: str, *args: str) -> List[Row]:
    """`alphactl holes` text lines as (area, polygon, closed ring coordinates), numbers parsed."""
    command = [alphactl, "holes", *args, "--backend=cpu"]
    text = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    rows = []
    for line in text.splitlines():
        area, polygon, rest = line.split(" ", 2)
        assert rest.startswith("POLYGON ((") and rest.endswith("))"), line
        ring = [tuple(float(v) for v in pair.split(" ")) for pair in rest[len("POLYGON ((") : -2].split(", ")]
        rows.append((float(area), int(polygon), ring))
    return rows


def as_alphactl_rows(holes: List[galpha.Hole], points: np.ndarray) -> List[Row]:
    """The package's holes as alphactl prints them: the ring closed, by coordinates."""
    rows = []
    for h in holes:
        closed = np.concatenate([h.ring, h.ring[:1]])
        rows.append((h.area, h.polygon, [tuple(p) for p in points[closed].tolist()]))
    return rows


def assert_same_holes(a: List[galpha.Hole], b: List[galpha.Hole]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.polygon == y.polygon
        assert x.area == y.area  # the same double, not close
        assert x.ring.dtype == y.ring.dtype == np.uint32
        np.testing.assert_array_equal(x.ring, y.ring)


@pytest.fixture(scope="module")
def clients(server) -> Tuple[galpha.NetworkClient, galpha.LocalClient]:
    with galpha.connect(server.address, timeout=120) as network, galpha.local("cpu") as local:
        yield network, local


@pytest.fixture(scope="module")
def grid_file(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    return write_bin(tmp_path_factory.mktemp("holes") / "grid_with_hole.bin", grid_with_hole())


# ---- (a) the grid's one hole ---------------------------------------------------------------------


def test_grid_has_one_octagonal_hole_on_both_clients_as_alphactl(clients, alphactl: str, grid_file) -> None:
    points = grid_with_hole()
    answers = [client.build(points).holes(alpha_sq=0.5) for client in clients]
    for holes in answers:
        assert len(holes) == 1
        (hole,) = holes
        assert hole.area == 14.0 and isinstance(hole.area, float)
        assert hole.polygon == 0
        assert len(hole.ring) == 12 and len(set(hole.ring.tolist())) == 12
        ring = points[hole.ring]
        # Counter-clockwise (positive signed area), around the removed block's 4..6 square.
        signed = 0.5 * np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1])
        assert signed == 14.0
        assert ring.min() == 3.0 and ring.max() == 7.0
    assert_same_holes(answers[0], answers[1])
    assert as_alphactl_rows(answers[1], points) == alphactl_holes(alphactl, str(grid_file), "--alpha-sq=0.5")
    # The hole is the shape's one interior ring, the same vertices the other way round.
    rings = clients[1].build(points).shape_rings(alpha_sq=0.5)
    np.testing.assert_array_equal(rings.polygons[0].holes[0][::-1], answers[1][0].ring)
    # The other threshold keywords resolve to the same complex.
    family = clients[0].build(points)
    assert_same_holes(family.holes(alpha=0.5**0.5 + 1e-9), answers[1])
    k = family.spectrum_size
    assert_same_holes(family.holes(rank=family.rank_lower_bound(0.5)), answers[1])
    assert family.holes(rank=k) == [] and family.holes(rank=0) == []


def test_holes_as_geodataframe(clients) -> None:
    geopandas = pytest.importorskip("geopandas")
    points = grid_with_hole()
    frames = []
    for client in clients:
        series = geopandas.GeoSeries(geopandas.points_from_xy(points[:, 0], points[:, 1]), crs="EPSG:32610")
        family = client.build(series)
        frame = family.holes(alpha_sq=0.5, as_geodataframe=True)
        assert list(frame.columns) == ["polygon", "area", "geometry"]
        assert frame.crs == family.crs and frame.crs.to_epsg() == 32610
        assert len(frame) == 1 and frame["polygon"].tolist() == [0] and frame["area"].tolist() == [14.0]
        polygon = frame.geometry.iloc[0]
        assert polygon.geom_type == "Polygon" and polygon.is_valid and polygon.area == 14.0
        assert polygon.exterior.is_ccw
        # It is the shape's interior ring.
        shape = family.shape(alpha_sq=0.5)
        assert polygon.equals(type(polygon)(shape.geoms[0].interiors[0]))
        empty = family.holes(alpha_sq=0.5, min_area=15, as_geodataframe=True)
        assert len(empty) == 0 and list(empty.columns) == ["polygon", "area", "geometry"] and empty.crs == family.crs
        frames.append(frame)
    assert frames[0].geometry.iloc[0].equals_exact(frames[1].geometry.iloc[0], 0.0)


# ---- (b) min_area --------------------------------------------------------------------------------


def test_min_area_keeps_holes_at_least_that_large(any_client) -> None:
    family = any_client.build(grid_with_hole())
    assert [h.area for h in family.holes(alpha_sq=0.5, min_area=14)] == [14.0]
    assert [h.area for h in family.holes(alpha_sq=0.5, min_area=14.0)] == [14.0]
    assert family.holes(alpha_sq=0.5, min_area=14.5) == []
    assert [h.area for h in family.holes(alpha_sq=0.5, min_area=np.float32(1))] == [14.0]


# ---- (c) shape(min_hole_area) ----------------------------------------------------------------------


def test_min_hole_area_fills_smaller_holes(any_client) -> None:
    family = any_client.build(grid_with_hole())
    kept = family.shape_rings(alpha_sq=0.5)
    assert len(kept.polygons) == 1 and len(kept.polygons[0].holes) == 1
    assert kept.area == 121.0 - 14.0
    filled = family.shape_rings(alpha_sq=0.5, min_hole_area=20)
    assert len(filled.polygons) == 1 and filled.polygons[0].holes == []
    assert filled.area == kept.area + 14.0
    np.testing.assert_array_equal(filled.polygons[0].outer, kept.polygons[0].outer)
    # Not below the bound: kept.
    same = family.shape_rings(alpha_sq=0.5, min_hole_area=14)
    assert len(same.polygons[0].holes) == 1 and same.area == kept.area
    shape = family.shape(alpha_sq=0.5, min_hole_area=20)
    assert shape.is_valid and len(shape.geoms) == 1 and len(shape.geoms[0].interiors) == 0
    assert shape.area == family.shape(alpha_sq=0.5).area + 14.0
    assert len(family.shape(alpha_sq=0.5, min_hole_area=14).geoms[0].interiors) == 1
    frame = family.shape(alpha_sq=0.5, min_hole_area=20, as_geodataframe=True)
    assert frame["area"].tolist() == [121.0]
    # The general mode fills the same way.
    general = family.shape(alpha_sq=0.5, mode="general", min_hole_area=20)
    assert general.geoms[0].area == 121.0


def test_min_hole_area_answers_equal_on_both_clients(clients) -> None:
    network, local = clients
    points = read_bin(AUTZEN)
    net, loc = network.build(points), local.build(points)
    holes = loc.holes(rank=AUTZEN_RANK)
    assert len(holes) >= 2
    between = (holes[-1].area + holes[-2].area) / 2  # fills the smallest, keeps the others
    for bound in (0.0, between, holes[0].area, holes[0].area * 2):
        a = net.shape_rings(rank=AUTZEN_RANK, min_hole_area=bound)
        b = loc.shape_rings(rank=AUTZEN_RANK, min_hole_area=bound)
        assert a.area == b.area
        assert len(a.polygons) == len(b.polygons)
        for p, q in zip(a.polygons, b.polygons):
            np.testing.assert_array_equal(p.outer, q.outer)
            assert len(p.holes) == len(q.holes)
            for x, y in zip(p.holes, q.holes):
                np.testing.assert_array_equal(x, y)
        left = sum(len(p.holes) for p in b.polygons)
        # The bound is compared with the exact areas (a reported area is the exact one's nearest
        # double, which may lie just above it).
        exact = [exact_ring_area(h.ring, points) for h in holes]
        assert left == sum(area >= Fraction(bound) for area in exact)


# ---- (d) bad values ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, match",
    [
        (
            lambda f: f.shape(alpha_sq=0.5, min_hole_area=-1),
            "min_hole_area -1 is not an area: give 0 \\(keep every hole\\) or more",
        ),
        (lambda f: f.shape(alpha_sq=0.5, min_hole_area=-0.5), "min_hole_area -0.5 is not an area"),
        (lambda f: f.shape(alpha_sq=0.5, min_hole_area=float("nan")), "min_hole_area nan is not an area"),
        (lambda f: f.shape_rings(alpha_sq=0.5, min_hole_area=-1e-300), "min_hole_area -1e-300 is not an area"),
        (lambda f: f.shape(alpha_sq=0.5, min_hole_area="big"), "min_hole_area must be a number"),
        (lambda f: f.shape(alpha_sq=0.5, min_hole_area=None), "min_hole_area must be a number"),
        (lambda f: f.shape(alpha_sq=0.5, min_hole_area=True), "min_hole_area must be a number"),
        (lambda f: f.holes(alpha_sq=0.5, min_area=-2), "min_area -2 is not an area: give 0 \\(every hole\\) or more"),
        (lambda f: f.holes(alpha_sq=0.5, min_area=float("nan")), "min_area nan is not an area"),
        (lambda f: f.holes(alpha_sq=0.5, min_area="x"), "min_area must be a number"),
        (lambda f: f.holes(), "give exactly one of"),
        (lambda f: f.holes(alpha=1.0, rank=2), "give exactly one of"),
        (lambda f: f.holes(rank=1.5), "rank must be an integer"),
    ],
)
def test_bad_values_raise_invalid_input_on_both_clients(any_client, call, match: str) -> None:
    family = any_client.build(grid_with_hole())
    with pytest.raises(galpha.InvalidInput, match=match):
        call(family)


def test_backends_refuse_bad_bounds_with_the_servers_message(clients) -> None:
    """Past the package's checks, the engine module and the server refuse min_hole_area with the
    same code and message (the package writes that message too); the module checks min_area."""
    network, local = clients
    points = grid_with_hole()
    net, loc = network.build(points)._backend, local.build(points)._backend
    assert isinstance(net, _network.NetworkFamilyBackend) and isinstance(loc, _local.LocalFamilyBackend)
    threshold = Threshold("alpha_sq", 0.5)
    for bound in (-1.0, -0.5, float("nan"), -1e-300, -123456789.0):
        messages = []
        for backend in (net, loc):
            with pytest.raises(galpha.InvalidInput) as caught:
                backend.shape_rings(threshold, galpha.Mode.REGULARIZED, bound)
            messages.append(caught.value.message)
        assert messages[0] == messages[1]
        with pytest.raises(galpha.InvalidInput) as caught:
            local.build(points).shape(alpha_sq=0.5, min_hole_area=bound)
        assert caught.value.message == messages[1]
    with pytest.raises(galpha.InvalidInput, match="min_area -1 is not an area"):
        loc.holes(threshold, -1.0, points)


def test_network_client_validates_before_calling(server, monkeypatch: pytest.MonkeyPatch) -> None:
    with galpha.connect(server.address, timeout=120) as client:
        family = client.build(grid_with_hole())

        def refuse(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            raise AssertionError("an RPC was made for arguments the package refuses")

        monkeypatch.setattr(family._backend._calls, "shape", refuse)
        for call in (
            lambda: family.shape(alpha_sq=0.5, min_hole_area=-1),
            lambda: family.shape_rings(alpha_sq=0.5, min_hole_area=float("nan")),
            lambda: family.holes(alpha_sq=0.5, min_area=-1),
            lambda: family.holes(alpha_sq=0.5, min_area="x"),
        ):
            with pytest.raises(galpha.InvalidInput):
                call()


# ---- (e) a real data set -------------------------------------------------------------------------


def test_autzen_holes_on_both_clients_as_alphactl(clients, alphactl: str) -> None:
    points = read_bin(AUTZEN)
    network, local = clients
    answers = [client.build(points).holes(rank=AUTZEN_RANK) for client in clients]
    assert len(answers[1]) >= 2
    assert_same_holes(answers[0], answers[1])
    assert as_alphactl_rows(answers[1], points) == alphactl_holes(alphactl, str(AUTZEN), f"--rank={AUTZEN_RANK}")
    areas = [h.area for h in answers[1]]
    assert areas == sorted(areas, reverse=True)
    for h in answers[1]:
        # The package's own measurement (on the clockwise ring, as core measures it) is core's.
        assert ring_area(h.ring[::-1], points) == h.area
        assert len(h.ring) >= 3 and len(set(h.ring.tolist())) == len(h.ring)
    # min_area at the second largest keeps the two largest, as alphactl --min-area.
    cut = answers[1][1].area
    kept = network.build(points).holes(rank=AUTZEN_RANK, min_area=cut)
    assert_same_holes(kept, answers[1][:2])
    assert as_alphactl_rows(kept, points) == alphactl_holes(
        alphactl, str(AUTZEN), f"--rank={AUTZEN_RANK}", f"--min-area={cut!r}"
    )


def test_holes_at_many_ranks_equal_on_both_clients(clients) -> None:
    network, local = clients
    points = read_bin(AUTZEN)
    net, loc = network.build(points), local.build(points)
    k = loc.spectrum_size
    for rank in sorted({1, k // 50, k // 10, k // 4, AUTZEN_RANK, k // 2, k}):
        assert_same_holes(net.holes(rank=rank), loc.holes(rank=rank))


def test_aio_holes_and_min_hole_area(server) -> None:
    points = grid_with_hole()

    async def main() -> None:
        async with galpha.aio.connect(server.address, timeout=120) as client:
            family = await client.build(points)
            holes = await family.holes(alpha_sq=0.5)
            with galpha.local("cpu") as local:
                assert_same_holes(holes, local.build(points).holes(alpha_sq=0.5))
            assert await family.holes(alpha_sq=0.5, min_area=14.5) == []
            frame = await family.holes(alpha_sq=0.5, as_geodataframe=True)
            assert frame["area"].tolist() == [14.0]
            shape = await family.shape(alpha_sq=0.5, min_hole_area=20)
            assert len(shape.geoms[0].interiors) == 0 and shape.area == 121.0
            rings = await family.shape_rings(alpha_sq=0.5, min_hole_area=14)
            assert len(rings.polygons[0].holes) == 1 and rings.area == 107.0
            with pytest.raises(galpha.InvalidInput, match="min_hole_area -1 is not an area"):
                await family.shape(alpha_sq=0.5, min_hole_area=-1)
            with pytest.raises(galpha.InvalidInput, match="min_area nan is not an area"):
                await family.holes(alpha_sq=0.5, min_area=float("nan"))

    asyncio.run(main())
