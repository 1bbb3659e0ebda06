"""Turning what users hold into the (N, 2) float64 array the engine and the wire take.

Accepted: NumPy arrays and array-likes of shape (N, 2); a shapely MultiPoint or a sequence of
shapely Points; a GeoSeries or GeoDataFrame of points (whose CRS the family keeps); a
:class:`galpha.PointFile` from :func:`galpha.read_points` (with the CRS its file states). Anything else,
or a geometry that is not a point, is an :class:`~galpha.InvalidInput` naming what was found.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ._errors import InvalidInput


def _geopandas_points(obj: Any) -> Optional[Tuple[np.ndarray, Any]]:
    """(points, crs) of a GeoSeries or GeoDataFrame; None for anything else."""
    geo_series = getattr(obj, "geometry", None) if type(obj).__name__ == "GeoDataFrame" else obj
    if type(geo_series).__name__ != "GeoSeries":
        return None
    kinds = set(geo_series.geom_type.dropna().unique())
    if geo_series.isna().any() or kinds - {"Point"}:
        bad = next((i for i, g in enumerate(geo_series) if g is None or g.geom_type != "Point"), 0)
        found = "a missing geometry" if geo_series.iloc[bad] is None else geo_series.iloc[bad].geom_type
        raise InvalidInput(f"row {bad} of the GeoSeries holds {found}; galpha takes points only")
    coords = np.column_stack([geo_series.x.to_numpy(dtype=np.float64), geo_series.y.to_numpy(dtype=np.float64)])
    return coords, geo_series.crs


def _shapely_points(obj: Any) -> Optional[np.ndarray]:
    """Coordinates of a shapely MultiPoint or a sequence of shapely Points; None otherwise."""
    module = type(obj).__module__
    if module.startswith("shapely"):
        if type(obj).__name__ == "MultiPoint":
            return np.array([(p.x, p.y) for p in obj.geoms], dtype=np.float64).reshape(-1, 2)
        if type(obj).__name__ == "Point":
            return np.array([(obj.x, obj.y)], dtype=np.float64)
        raise InvalidInput(f"a shapely {type(obj).__name__} is not a point set; pass a MultiPoint or points")
    if isinstance(obj, (list, tuple)) and obj and type(obj[0]).__module__.startswith("shapely"):
        out = np.empty((len(obj), 2), dtype=np.float64)
        for i, p in enumerate(obj):
            if type(p).__name__ != "Point":
                raise InvalidInput(f"item {i} is a shapely {type(p).__name__}; galpha takes points only")
            out[i] = (p.x, p.y)
        return out
    return None


def as_points(obj: Any) -> Tuple[np.ndarray, Any]:
    """(an (N, 2) C-contiguous float64 array, the CRS or None). An input array that already has
    that layout is returned as is (no copy)."""
    geo = _geopandas_points(obj)
    if geo is not None:
        return geo
    if type(obj).__name__ == "PointFile" and type(obj).__module__ == "galpha._files":
        return obj.points, obj.crs
    shapely_coords = _shapely_points(obj)
    if shapely_coords is not None:
        return shapely_coords, None
    try:
        array = np.asarray(obj, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidInput(f"points must be an (N, 2) array of numbers: {e}") from None
    if array.ndim != 2 or array.shape[1] != 2:
        if array.size == 0:
            return np.empty((0, 2), dtype=np.float64), None
        raise InvalidInput(f"points must have shape (N, 2); got an array of shape {array.shape}")
    return np.ascontiguousarray(array), None
