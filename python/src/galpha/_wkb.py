"""Shapes as shapely geometry, made through well-known binary (WKB) in one GEOS call.

shapely 1.8 (Debian 12's) builds a MultiPoint or MultiLineString from NumPy one Python object per
member: 0.6 s for the 228K isolated points of a 110K-point LiDAR shape, most of ``Family.shape``'s
time. Here the whole geometry is written as little-endian WKB with NumPy (one record array per
member kind, rings by slices of the input doubles) and read by GEOS at once. The coordinates are
the input doubles themselves, in the same order; rings are closed by repeating their first vertex,
as shapely's constructors close them.
"""

from __future__ import annotations

import struct
from typing import Any, List

import numpy as np

_LITTLE_ENDIAN = 1
_POINT, _LINESTRING, _POLYGON, _MULTIPOINT, _MULTILINESTRING, _MULTIPOLYGON, _COLLECTION = range(1, 8)

# A member's header and fixed-size body, packed as WKB lays them out (no alignment padding).
_POINT_RECORD = np.dtype([("order", "u1"), ("type", "<u4"), ("xy", "<f8", (2,))])
_SEGMENT_RECORD = np.dtype([("order", "u1"), ("type", "<u4"), ("count", "<u4"), ("xy", "<f8", (2, 2))])


def _header(geometry_type: int, count: int) -> bytes:
    """Byte order, geometry type and member (or ring) count."""
    return struct.pack("<BII", _LITTLE_ENDIAN, geometry_type, count)


def _ring(points: np.ndarray, ring: np.ndarray) -> bytes:
    """A ring's vertex count and doubles, closed (an open ring of n vertices has n + 1)."""
    closed = np.empty(len(ring) + 1, dtype=np.int64)
    closed[:-1] = ring
    closed[-1] = ring[0]
    return struct.pack("<I", len(closed)) + np.ascontiguousarray(points[closed], dtype="<f8").tobytes()


def polygon_wkb(points: np.ndarray, outer: np.ndarray, holes: List[np.ndarray]) -> bytes:
    return b"".join([_header(_POLYGON, 1 + len(holes)), _ring(points, outer), *(_ring(points, h) for h in holes)])


def multipolygon_wkb(points: np.ndarray, polygons: List[Any]) -> bytes:
    """``polygons``: ShapePolygon-like objects with ``outer`` and ``holes`` index arrays."""
    return b"".join([_header(_MULTIPOLYGON, len(polygons)), *(polygon_wkb(points, p.outer, p.holes) for p in polygons)])


def multilinestring_wkb(points: np.ndarray, edges: np.ndarray) -> bytes:
    """One two-vertex LineString per row of ``edges`` ((k, 2) indices)."""
    records = np.empty(len(edges), dtype=_SEGMENT_RECORD)
    records["order"] = _LITTLE_ENDIAN
    records["type"] = _LINESTRING
    records["count"] = 2
    records["xy"] = points[np.asarray(edges, dtype=np.int64)]
    return _header(_MULTILINESTRING, len(edges)) + records.tobytes()


def multipoint_wkb(points: np.ndarray, indices: np.ndarray) -> bytes:
    records = np.empty(len(indices), dtype=_POINT_RECORD)
    records["order"] = _LITTLE_ENDIAN
    records["type"] = _POINT
    records["xy"] = points[np.asarray(indices, dtype=np.int64)]
    return _header(_MULTIPOINT, len(indices)) + records.tobytes()


def collection_wkb(members: List[bytes]) -> bytes:
    return b"".join([_header(_COLLECTION, len(members)), *members])


def load(wkb: bytes) -> Any:
    import shapely.wkb

    return shapely.wkb.loads(wkb)
