"""GeoPandas and shapely in, GeoPandas and shapely out, on both clients: the CRS of a GeoDataFrame
of points stays on the family and on every geometry answer, in a projected CRS (the Autzen ground
points, Oregon GIC Lambert in feet) and a geographic one (the same points in degrees, computed in
metres); the polygons' vertices are exactly the input points; GeoJSON written and read back is the
same."""

from __future__ import annotations

import json

import geopandas
import numpy as np
import pytest
import shapely.geometry
from conftest import REPO, read_bin

import galpha

CASES = [("lidar_autzen_ground.bin", "EPSG:2994"), ("lidar_autzen_ground_lonlat.bin", "EPSG:4326")]


@pytest.mark.parametrize("file,crs", CASES, ids=["projected", "geographic"])
def test_geodataframe_round_trip(any_client, file: str, crs: str) -> None:
    points = read_bin(REPO / "data" / file)
    frame = geopandas.GeoDataFrame(
        {"id": np.arange(len(points))}, geometry=geopandas.points_from_xy(points[:, 0], points[:, 1]), crs=crs
    )
    family = any_client.build(frame)
    assert family.crs == frame.crs
    np.testing.assert_array_equal(family.points, points)
    if crs == "EPSG:4326":
        # Longitude/latitude is computed in metres: the family (and its handle) is the local
        # projection's, the same as from the bare array with crs= (docs/design.md, "Coordinate
        # reference systems").
        assert family.projection is not None
        assert family.handle != galpha.point_set_handle(points)
        assert family.handle == any_client.build(points, crs=crs).handle
    else:
        # A projected CRS is computed as given: the same family as from the bare array.
        assert family.projection is None
        assert family.handle == galpha.point_set_handle(points)
    optimal = family.optimal(components=1).regularized
    assert optimal is not None
    shape = family.shape(rank=optimal.rank, as_geodataframe=True)
    assert shape.crs == frame.crs
    assert list(shape["kind"].unique()) == ["polygon"]
    assert shape.geometry.is_valid.all()
    assert shape["area"].sum() == pytest.approx(family.shape_rings(rank=optimal.rank).area, rel=1e-9)
    # Every vertex is an input point, bit for bit.
    vertices = np.vstack([np.asarray(p.exterior.coords) for p in shape.geometry])
    known = {tuple(p) for p in points.tolist()}
    assert all(tuple(v) in known for v in vertices.tolist())
    # GeoJSON out and back in: the same geometries, the CRS carried by the caller.
    back = geopandas.GeoDataFrame.from_features(json.loads(shape.to_json()), crs=shape.crs)
    assert back.crs == frame.crs
    assert all(a.equals(b) for a, b in zip(back.geometry, shape.geometry))
    # The general shape also has its singular parts as rows, in the same CRS.
    rank = max(1, optimal.rank // 2)
    general = family.shape(rank=rank, mode="general", as_geodataframe=True)
    assert general.crs == frame.crs and general.geometry.is_valid.all()
    # One row a polygon, then one for the singular edges and one for the isolated points: the
    # members of the shape itself, in its order.
    rings = family.shape_rings(rank=rank, mode="general")
    kinds = ["polygon"] * len(rings.polygons)
    kinds += ["singular_edges"] * bool(len(rings.singular_edges)) + ["isolated_points"] * bool(len(rings.isolated_points))
    assert list(general["kind"]) == kinds
    whole = list(family.shape(rank=rank, mode="general").geoms)
    members = (list(whole.pop(0).geoms) if rings.polygons else []) + whole
    assert [g.wkb for g in general.geometry] == [g.wkb for g in members]


def test_shapely_inputs(any_client) -> None:
    coords = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (1.0, 1.0)]
    from_multipoint = any_client.build(shapely.geometry.MultiPoint(coords))
    from_points = any_client.build([shapely.geometry.Point(c) for c in coords])
    assert from_multipoint.handle == from_points.handle == galpha.point_set_handle(np.array(coords))
    assert from_multipoint.crs is None
    with pytest.raises(galpha.InvalidInput, match="LineString"):
        any_client.build([shapely.geometry.Point(0, 0), shapely.geometry.LineString([(0, 0), (1, 1)])])
    frame = geopandas.GeoDataFrame(geometry=[shapely.geometry.Point(0, 0), shapely.geometry.box(0, 0, 1, 1)])
    with pytest.raises(galpha.InvalidInput, match="row 1 .*Polygon"):
        any_client.build(frame)


def test_alphashape_convention() -> None:
    assert galpha.radius_from_alphashape(0.5) == 2.0
    assert galpha.radius_from_alphashape(0) == float("inf")
    with pytest.raises(galpha.InvalidInput):
        galpha.radius_from_alphashape(-1)
