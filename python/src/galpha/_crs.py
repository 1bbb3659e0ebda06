"""Coordinate reference systems of point sets: the frame a family is computed in.

A geographic CRS (longitude/latitude) is computed in metres, in the local azimuthal equidistant
projection that galpha's C++ core chooses with PROJ (``core/io/coordinate_system.hpp``, the same
as ``alphactl --crs``): alpha, areas and the spectrum are then in metres and square metres, while
shapes keep the input's coordinates (each vertex is an input point). A projected CRS, or none, is
computed as given. docs/design.md, "Coordinate reference systems", has the semantics.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Optional

import numpy as np

from ._errors import InvalidInput, error_for_code


@dataclasses.dataclass(frozen=True)
class Frame:
    """What a family is built from, and the CRS it came in."""

    crs: Any  #: the CRS as given (a string, a pyproj CRS...), or None for planar coordinates
    computed: np.ndarray  #: the points the engine computes with: the input, or its local projection
    projection: Optional[str] = None  #: the local projection (PROJ string) of a geographic CRS
    name: Optional[str] = None  #: PROJ's name of the CRS
    geographic: bool = False


def definition_of(crs: Any) -> str:
    """The text PROJ reads for ``crs``: a string as it is, an EPSG code (int), or anything with a
    ``to_wkt()`` method (pyproj's CRS, GeoPandas' ``.crs``)."""
    if isinstance(crs, str):
        return crs
    if isinstance(crs, (int, np.integer)) and not isinstance(crs, bool):
        return f"EPSG:{int(crs)}"
    to_wkt = getattr(crs, "to_wkt", None)
    if callable(to_wkt):
        return str(to_wkt())
    raise InvalidInput(f"crs must be a string (as 'EPSG:4326'), an EPSG code or a pyproj CRS, got {crs!r}")


def frame_of(points: np.ndarray, crs: Any, data_crs: Any) -> Frame:
    """The frame of ``points``: under ``crs`` when given ("none": planar, whatever the data says),
    else under the CRS the data carried (a GeoSeries' or GeoDataFrame's), else planar."""
    chosen = data_crs if crs is None else crs
    if chosen is None or (isinstance(chosen, str) and chosen.strip().lower() == "none"):
        return Frame(None, points)
    definition = definition_of(chosen)
    try:
        from . import _engine
    except ImportError:
        raise InvalidInput(
            "a CRS needs galpha's compiled module (galpha._engine), where PROJ projects the points; "
            "give crs='none' to use the coordinates as planar ones"
        ) from None
    try:
        frame = _engine.frame(definition, points)
    except _engine.EngineError as e:
        raise error_for_code(e.code, e.message) from None
    computed = frame["points"] if frame["geographic"] else points
    return Frame(chosen, computed, frame["projection"], frame["name"], bool(frame["geographic"]))
