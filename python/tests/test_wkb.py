"""Shapes made through well-known binary (galpha/_wkb.py) against the same geometry built with
shapely's own constructors, member by member (the independent path): byte-identical WKB, valid,
and the empty cases typed as before."""

from __future__ import annotations

import numpy as np
import pytest
import shapely.wkt
from shapely.geometry import GeometryCollection, MultiLineString, MultiPoint, MultiPolygon, Polygon

from galpha._family import rings_to_shapely
from galpha._types import Mode, ShapePolygon, ShapeRings

# A 4 x 4 square with a square hole, a triangle beside it, two loose edges and two points.
POINTS = np.array(
    [[0, 0], [4, 0], [4, 4], [0, 4], [1, 1], [1, 3], [3, 3], [3, 1], [5, 0], [6, 0], [5, 1], [7, 7], [8, 8], [9, 9],
     [10, 10]],
    dtype=np.float64,
)


def u32(*values: int) -> np.ndarray:
    return np.array(values, dtype=np.uint32)


def rings(polygons=(), edges=(), points=()) -> ShapeRings:
    return ShapeRings(
        polygons=list(polygons),
        singular_edges=np.array(edges, dtype=np.uint32).reshape(-1, 2),
        isolated_points=np.array(points, dtype=np.uint32),
        area=0.0,
    )


SQUARE = ShapePolygon(outer=u32(0, 1, 2, 3), holes=[u32(4, 5, 6, 7)])
TRIANGLE = ShapePolygon(outer=u32(8, 9, 10), holes=[])


def by_constructors(r: ShapeRings, mode: Mode):
    # shapely 1.8 turns MultiPolygon([]) into a GeometryCollection: the typed empty one from WKT.
    multipolygon = (
        MultiPolygon([Polygon(POINTS[p.outer], [POINTS[h] for h in p.holes]) for p in r.polygons])
        if r.polygons
        else shapely.wkt.loads("MULTIPOLYGON EMPTY")
    )
    if mode == Mode.REGULARIZED:
        return multipolygon
    parts = [multipolygon] if r.polygons else []
    if len(r.singular_edges):
        parts.append(MultiLineString([POINTS[e] for e in r.singular_edges]))
    if len(r.isolated_points):
        parts.append(MultiPoint(POINTS[r.isolated_points]))
    return GeometryCollection(parts)


@pytest.mark.parametrize(
    "shape",
    [
        rings([SQUARE, TRIANGLE], [(11, 12), (12, 13)], [14]),
        rings([SQUARE]),
        rings([], [(11, 12)]),
        rings([], [], [14]),
    ],
    ids=["everything", "one_polygon_with_a_hole", "edges_only", "points_only"],
)
@pytest.mark.parametrize("mode", [Mode.REGULARIZED, Mode.GENERAL])
def test_the_same_geometry_as_shapely_builds(shape: ShapeRings, mode: Mode) -> None:
    got = rings_to_shapely(shape, POINTS, mode)
    expected = by_constructors(shape, mode)
    assert got.is_valid
    assert got.geom_type == expected.geom_type
    assert got.wkb == expected.wkb
    if shape.polygons:
        assert got.area == pytest.approx(16.0 - 4.0 + (0.5 if len(shape.polygons) == 2 else 0.0))


def test_empty_shapes_are_typed() -> None:
    regularized = rings_to_shapely(rings(), POINTS, Mode.REGULARIZED)
    assert regularized.geom_type == "MultiPolygon" and regularized.is_empty
    general = rings_to_shapely(rings(), POINTS, Mode.GENERAL)
    assert general.geom_type == "GeometryCollection" and general.is_empty


def test_points_of_another_dtype_or_layout_give_the_same_doubles() -> None:
    shape = rings([SQUARE, TRIANGLE], [(11, 12)], [14])
    expected = rings_to_shapely(shape, POINTS, Mode.GENERAL).wkb
    assert rings_to_shapely(shape, np.asfortranarray(POINTS), Mode.GENERAL).wkb == expected
    assert rings_to_shapely(shape, POINTS.astype(np.float32), Mode.GENERAL).wkb == expected
