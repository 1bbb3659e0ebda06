"""Coordinate reference systems from Python: a GeoDataFrame of longitudes and latitudes (or
``crs=``) is computed in metres in galpha's local projection, on both clients and galpha.aio, with
the same spectrum as ``alphactl --crs`` (one C++ projection for all); shapes keep the input's
coordinates and CRS. Oracles: pyproj's geodesic areas (GeographicLib) for the hull, alphactl for
the spectrum, the planar build for projected input.
"""

from __future__ import annotations

import asyncio
import subprocess

import geopandas
import numpy as np
import pyproj
import pytest
import shapely.geometry
from conftest import REPO, read_bin

import galpha
import galpha.aio
from galpha import InvalidInput

GPS = REPO / "data" / "gps_tracks_slovenia_croatia.bin"


@pytest.fixture(scope="module")
def lonlat() -> np.ndarray:
    return read_bin(GPS)


@pytest.fixture(scope="module")
def clients(server):
    with galpha.connect(server.address, timeout=120) as network, galpha.local("cpu") as local:
        yield network, local


def geodesic_hull_area(points: np.ndarray) -> float:
    hull = shapely.geometry.MultiPoint(points).convex_hull
    area, _ = pyproj.Geod(ellps="WGS84").geometry_area_perimeter(hull)
    return abs(area)


@pytest.mark.parametrize("which", [0, 1], ids=["network", "local"])
def test_lonlat_geodataframe_is_computed_in_metres(clients, lonlat: np.ndarray, alphactl: str, which: int) -> None:
    frame = geopandas.GeoDataFrame(geometry=geopandas.points_from_xy(lonlat[:, 0], lonlat[:, 1]), crs="EPSG:4326")
    family = clients[which].build(frame)
    assert family.crs == frame.crs
    assert family.projection is not None and family.projection.startswith("+proj=aeqd")
    # The hull in square metres: the geodesic area within the local projection's distortion.
    hull = family.classify(ratio=1.0, summary_only=True).hull_area
    assert hull == pytest.approx(geodesic_hull_area(lonlat), rel=1e-4)
    # The spectrum is alphactl's under --crs EPSG:4326, value for value.
    text = subprocess.run(
        [alphactl, "spectrum", str(GPS), "--crs", "EPSG:4326", "--backend=cpu"], check=True, capture_output=True, text=True
    ).stdout
    np.testing.assert_array_equal(family.spectrum(), np.array([float(v) for v in text.split()]))
    # Shapes are in the input's coordinates and CRS; their areas in square metres.
    shape = family.shape(ratio=0.5)
    assert shape.is_valid
    xmin, ymin, xmax, ymax = shape.bounds
    assert lonlat[:, 0].min() <= xmin and xmax <= lonlat[:, 0].max()
    assert lonlat[:, 1].min() <= ymin and ymax <= lonlat[:, 1].max()
    table = family.shape(ratio=0.5, as_geodataframe=True)
    assert table.crs == frame.crs
    rings = family.shape_rings(ratio=0.5)
    assert table["area"].sum() == pytest.approx(rings.area, rel=1e-9)
    assert rings.area >= 0.5 * hull * (1 - 1e-12)
    # Holes: areas in square metres, the same on both clients (checked below), rings of input points.
    for hole in family.holes(ratio=0.9):
        assert hole.area > 0


def test_both_clients_and_aio_agree_under_a_crs(clients, lonlat: np.ndarray, server) -> None:
    network, local = (c.build(lonlat, crs="EPSG:4326") for c in clients)
    assert network.handle == local.handle
    np.testing.assert_array_equal(network.spectrum(), local.spectrum())
    assert [h.area for h in network.holes(rank=3500)] == [h.area for h in local.holes(rank=3500)]

    async def aio_spectrum_size():
        async with galpha.aio.connect(server.address, timeout=120) as client:
            family = await client.build(lonlat, crs=4326)
            assert family.projection == network.projection
            return family.summary.spectrum_size, [h.area for h in await family.holes(rank=3500)]

    size, areas = asyncio.run(aio_spectrum_size())
    assert size == len(network.spectrum())
    assert areas == [h.area for h in network.holes(rank=3500)]
    # The handle names the computed points: family() finds the family under the same CRS.
    assert clients[0].family(network.handle, lonlat, crs="EPSG:4326").handle == network.handle


@pytest.mark.parametrize("which", [0, 1], ids=["network", "local"])
def test_projected_and_planar_input_stay_as_given(clients, lonlat: np.ndarray, which: int) -> None:
    utm = np.column_stack([500000 + 1000 * lonlat[:300, 0], 5000000 + 1000 * lonlat[:300, 1]])
    planar = clients[which].build(utm)
    projected = clients[which].build(utm, crs=pyproj.CRS("EPSG:32633"))
    assert projected.projection is None
    np.testing.assert_array_equal(projected.spectrum(), planar.spectrum())
    frame = geopandas.GeoDataFrame(geometry=geopandas.points_from_xy(lonlat[:, 0], lonlat[:, 1]), crs="EPSG:4326")
    as_planar = clients[which].build(frame, crs="none")
    assert as_planar.crs is None and as_planar.projection is None
    np.testing.assert_array_equal(as_planar.spectrum(), clients[which].build(lonlat).spectrum())


@pytest.mark.parametrize("which", [0, 1], ids=["network", "local"])
def test_wrong_crs_is_refused(clients, which: int) -> None:
    with pytest.raises(InvalidInput, match="is not a longitude and latitude"):
        clients[which].build(np.array([[500000.0, 4000000.0], [500100.0, 4000000.0], [500000.0, 4000100.0]]), crs="EPSG:4326")
    with pytest.raises(InvalidInput, match="not understood by PROJ"):
        clients[which].build(np.zeros((3, 2)), crs="no such crs")
    with pytest.raises(InvalidInput, match="crs must be"):
        clients[which].build(np.zeros((3, 2)), crs=4.5)
