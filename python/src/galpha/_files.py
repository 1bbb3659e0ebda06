"""Point files in alphactl's formats, read by galpha's C++ readers: ``galpha.read_points``."""

from __future__ import annotations

import dataclasses
import os
from typing import Optional, Union

import numpy as np

from ._errors import InvalidInput, error_for_code


@dataclasses.dataclass(frozen=True)
class PointFile:
    """The points of a file and the CRS it states; ``client.build`` takes it as it is (the CRS
    becomes the build's default ``crs``, as a GeoDataFrame's does)."""

    points: np.ndarray  #: (N, 2) float64, in file order
    crs: Optional[str]  #: the file's CRS (GeoJSON: "OGC:CRS84", LAS, GDAL layers), or None
    #: Structures (PDB, mmCIF): each atom's radius, its element's van der Waals radius in gemmi's
    #: table in ångström (NaN where gemmi does not know the element); None for other formats.
    #: ``client.build(f.points, weights=(f.radii + 1.4) ** 2)`` builds the solvent-accessible
    #: weighted family (a 1.4 Å water probe).
    radii: Optional[np.ndarray] = None


def read_points(
    path: Union[str, "os.PathLike[str]"],
    *,
    layer: Optional[str] = None,
    plane: Optional[str] = None,
    slab: Optional[str] = None,
    max_points: int = 100_000_000,
) -> PointFile:
    """Reads a point file as ``alphactl`` does, the format chosen by extension: ``.bin``, ``.npy``,
    GeoJSON, uncompressed LAS, Shapefile/GeoPackage/FlatGeobuf (``layer``: by default the first),
    PDB/mmCIF structures, also gzip-compressed (``plane`` "xy", "yz" or "zx"; ``slab`` "MIN:MAX"
    keeps a section of the third axis), or delimited text. InvalidInput for what cannot be read
    (naming the file), ResourceExhausted beyond ``max_points``."""
    try:
        from . import _engine
    except ImportError:
        raise InvalidInput("read_points needs galpha's compiled module (galpha._engine)") from None
    try:
        read = _engine.read_points(os.fspath(path), layer or "", plane, slab, int(max_points))
    except _engine.EngineError as e:
        raise error_for_code(e.code, e.message) from None
    return PointFile(read["points"], read["crs"], read["radii"])
