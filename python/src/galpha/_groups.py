"""One shape per group of points (``galpha.shapes_by_group``): what GIS users make with
``ST_ConcaveHull`` per feature class or cluster, and ``alphactl shape --group-by`` on files."""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from ._errors import InvalidInput
from ._family import rings_to_shapely
from ._points import as_points
from ._types import Mode


def _labels(data: Any, by: Union[str, Sequence[Any]], n: int) -> List[Any]:
    """One label per point: a GeoDataFrame's column, or the labels given."""
    if isinstance(by, str):
        if type(data).__name__ != "GeoDataFrame":
            raise InvalidInput("by= names a column: give a GeoDataFrame, or the labels themselves")
        if by not in data.columns:
            raise InvalidInput(f"by={by!r} names no column of the GeoDataFrame (its columns: {list(data.columns)})")
        return list(data[by])
    labels = list(by)
    if len(labels) != n:
        raise InvalidInput(f"by= has {len(labels)} labels for {n} points")
    return labels


def _missing(label: Any) -> bool:
    return label is None or (isinstance(label, float) and label != label)


def shapes_by_group(
    client: Any,
    data: Any,
    by: Union[str, Sequence[Any]],
    *,
    alpha: Optional[float] = None,
    alpha_sq: Optional[float] = None,
    rank: Optional[int] = None,
    ratio: Optional[float] = None,
    min_hole_area: float = 0.0,
    crs: Any = None,
) -> Any:
    """The regularized shape of each group of points as a GeoDataFrame (columns ``group``,
    ``points``, ``level``, ``area``, ``geometry``, in the data's CRS), the groups in the order they
    first appear.

    ``data`` is anything ``client.build`` takes; ``by`` a column of a GeoDataFrame or one label per
    point (None or NaN labels form one group, labelled None). The groups are built together with
    ``client.build_batch`` (the local engine packs them into one build; a server reads them from
    one BuildBatch stream), each as it would be built on its own (under a geographic CRS in its own
    local projection: ``alpha`` in metres, ``area`` in square metres), and released after. The threshold keywords are :meth:`Family.shape`'s, and
    ``crs`` is :meth:`NetworkClient.build`'s. ``alphactl shape --group-by`` gives the same shapes
    for files."""
    import geopandas
    from shapely.geometry import MultiPolygon

    points, data_crs = as_points(data)
    labels = _labels(data, by, len(points))
    groups: Dict[Any, List[int]] = {}
    for i, label in enumerate(labels):
        groups.setdefault(None if _missing(label) else label, []).append(i)
    rows: Dict[str, List[Any]] = {"group": [], "points": [], "level": [], "area": []}
    geometries: List[Any] = []
    subsets = [points[np.asarray(indices)] for indices in groups.values()]
    families = client.build_batch(
        [(str(label), subset) for label, subset in zip(groups, subsets)], crs=data_crs if crs is None else crs
    )
    for (label, indices), subset, built in zip(groups.items(), subsets, families):
        with built as family:
            level = family.classify(alpha=alpha, alpha_sq=alpha_sq, rank=rank, ratio=ratio, summary_only=True).level
            rows["group"].append(label)
            rows["points"].append(len(indices))
            rows["level"].append(level)
            if level < 0:  # a negative alpha_sq: the empty complex
                rows["area"].append(0.0)
                geometries.append(MultiPolygon())
                continue
            rings = family.shape_rings(rank=level, mode=Mode.REGULARIZED, min_hole_area=min_hole_area)
            rows["area"].append(rings.area)
            geometries.append(rings_to_shapely(rings, subset, Mode.REGULARIZED))
    out_crs = data_crs if crs is None else (None if isinstance(crs, str) and crs.strip().lower() == "none" else crs)
    return geopandas.GeoDataFrame(rows, geometry=geometries, crs=out_crs)
