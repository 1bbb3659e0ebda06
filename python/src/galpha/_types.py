"""The values galpha's queries return, shared by the network and the in-process backends.

Every array is a NumPy array (no per-simplex Python objects). Index arrays hold input indices
(``uint32``): the position of a point in the array given to ``Client.build``. Semantics follow the
project's docs/design.md, "Semantics": a threshold is a squared radius ``alpha_sq`` (or a radius
``alpha``, or a rank of the spectrum); the level of a threshold is the number of spectrum values at
or below it; rank ``r`` (1..K) stands for the complex at ``spectrum[r - 1]``, rank 0 for alpha = 0.
"""

from __future__ import annotations

import dataclasses
import enum
from typing import Dict, List, Optional

import numpy as np

__all__ = [
    "SimplexClass",
    "SimplexKind",
    "Endpoint",
    "Mode",
    "VertexRule",
    "Threshold",
    "BuildSummary",
    "ClassCounts",
    "Classification",
    "ShapePolygon",
    "ShapeRings",
    "Hole",
    "MasterList",
    "ComponentCurve",
    "OptimalLevel",
    "Optimal",
    "BettiCurves",
    "PersistencePairs",
    "PersistenceDiagram",
]


class SimplexClass(enum.IntEnum):
    """A simplex's class at one threshold (the numbers of the wire protocol's SimplexClass)."""

    EXTERIOR = 1
    SINGULAR = 2
    REGULAR = 3
    INTERIOR = 4


class SimplexKind(enum.IntEnum):
    VERTEX = 1
    EDGE = 2
    TRIANGLE = 3


class Endpoint(enum.IntEnum):
    """Which end of a simplex's interval a master-list entry is."""

    RHO = 1  #: the simplex enters (singular; a triangle enters interior)
    MU_LOW = 2  #: it becomes regular
    MU_HIGH = 3  #: it becomes interior


class Mode(str, enum.Enum):
    """``general`` keeps singular simplices; ``regularized`` only what bounds or fills triangles."""

    GENERAL = "general"
    REGULARIZED = "regularized"


class VertexRule(str, enum.Enum):
    """Vertex classes from incident edges (the report's rule) or incident triangles (CGAL's)."""

    REPORT = "report"
    CGAL = "cgal"


@dataclasses.dataclass(frozen=True)
class Threshold:
    """Exactly one of a squared radius, a radius, a rank or an area ratio; built by
    :func:`threshold_from`."""

    kind: str  # "alpha_sq", "alpha", "rank" or "ratio"
    value: float  # an int for "rank"

    def __post_init__(self) -> None:
        if self.kind not in ("alpha_sq", "alpha", "rank", "ratio"):
            raise ValueError(f"unknown threshold kind {self.kind!r}")


@dataclasses.dataclass(frozen=True)
class ClassCounts:
    exterior: int
    singular: int
    regular: int
    interior: int


@dataclasses.dataclass(frozen=True)
class BuildSummary:
    """What a build produced and measured (the wire protocol's BuildSummary)."""

    name: str
    points: int  #: points as given
    distinct_points: int
    duplicates: int  #: points equal to an earlier one
    triangles: int
    edges: int
    spectrum_size: int  #: K: ranks run 0..K
    backend: str  #: "cuda" or "cpu"
    stage_times: Dict[str, float]  #: seconds per pipeline stage
    comparisons: Dict[str, int]  #: exact radius comparisons: "filter", "device_exact", "cpu_fallback"
    peak_memory_bytes: int
    family_bytes: int
    cached: bool = False  #: the server already held the family (nothing was computed)
    #: Bytes of the point messages this call uploaded (protobuf encoding, without gRPC's framing;
    #: raw doubles are 16 a point): 0 when nothing was uploaded (a family the server held, the local engine).
    upload_bytes: int = 0
    #: A weighted family (built with ``weights=``: the regular triangulation's alpha shapes).
    weighted: bool = False
    #: Points a weighted family hides (no vertex of the regular triangulation; EXTERIOR at every
    #: threshold): :attr:`Family.hidden_points` lists them. 0 when unweighted.
    hidden_points: int = 0


@dataclasses.dataclass(frozen=True)
class Classification:
    """Every simplex's class at one threshold.

    Vertices are the distinct points in ascending input index (a duplicate shares its first
    occurrence's class and is not listed); edges ``(E, 2)`` and triangles ``(T, 3)`` hold ascending
    index pairs and triples, sorted lexicographically. Classes are :class:`SimplexClass` numbers
    (``uint8``). With ``non_exterior_only`` the exterior simplices are left out (the counts still
    count them); with ``summary_only`` the arrays are empty.
    """

    level: int  #: spectrum values <= the threshold (-1 for a negative alpha_sq)
    alpha_sq: float  #: the threshold as a squared radius
    vertex_counts: ClassCounts
    edge_counts: ClassCounts
    triangle_counts: ClassCounts
    components: int
    solid_components: int
    interior_area: float
    vertices: np.ndarray  #: (V,) uint32
    vertex_classes: np.ndarray  #: (V,) uint8
    edges: np.ndarray  #: (E, 2) uint32
    edge_classes: np.ndarray  #: (E,) uint8
    triangles: np.ndarray  #: (T, 3) uint32
    triangle_classes: np.ndarray  #: (T,) uint8
    #: Holes (b1) of the complex in the classification's mode: of the whole complex (general), of
    #: its closed interior triangles (regularized).
    holes: int = 0
    #: The convex hull's area (squared input units, within about 1e-12 of it, relative):
    #: ``interior_area / hull_area`` is the level's area ratio, what ``ratio=`` asks for.
    hull_area: float = 0.0


@dataclasses.dataclass(frozen=True)
class ShapePolygon:
    """A counter-clockwise outer ring and clockwise holes, as input indices; rings are not closed."""

    outer: np.ndarray  #: (n,) uint32
    holes: List[np.ndarray]


@dataclasses.dataclass(frozen=True)
class ShapeRings:
    """The alpha shape at one threshold by input indices (canonical order, as the C++ core gives)."""

    polygons: List[ShapePolygon]
    singular_edges: np.ndarray  #: (k, 2) uint32, (smaller, larger)
    isolated_points: np.ndarray  #: (j,) uint32
    area: float


@dataclasses.dataclass(frozen=True)
class Hole:
    """One hole of the regularized shape at a threshold (:meth:`galpha.Family.holes`), as
    ``alphactl holes`` lists it.

    ``ring`` runs counter-clockwise (the hole's boundary as a polygon of its own: the reverse of
    the clockwise hole ring of :class:`ShapePolygon`) and is not closed (its first vertex is not
    repeated, like every ring of :class:`ShapeRings`; alphactl prints it closed). ``area`` is the
    double nearest to the exact area (core/geometry/shape_holes.hpp's RingArea: the shoelace sum in
    rationals), the same on both clients and in alphactl; the holes' order and the ``min_area``
    comparisons use the exact areas."""

    polygon: int  #: index of the polygon it belongs to, in ``shape_rings(...).polygons`` (regularized)
    ring: np.ndarray  #: (n,) uint32 input indices, counter-clockwise, open
    area: float  #: squared input units


@dataclasses.dataclass(frozen=True)
class MasterList:
    """Master-list entries in rank order, vertex < edge < triangle within a rank.

    ``vertex_indices`` is flat: 1, 2 or 3 indices per entry by its kind; ``offsets`` (length
    entries + 1) delimits each entry's run.
    """

    ranks: np.ndarray  #: (M,) int64
    kinds: np.ndarray  #: (M,) uint8, SimplexKind numbers
    endpoints: np.ndarray  #: (M,) uint8, Endpoint numbers
    vertex_indices: np.ndarray  #: (sum of kinds,) uint32

    @property
    def offsets(self) -> np.ndarray:
        out = np.zeros(len(self.kinds) + 1, dtype=np.int64)
        np.cumsum(self.kinds, out=out[1:])
        return out


@dataclasses.dataclass(frozen=True)
class ComponentCurve:
    """Components at each level ``first_level .. first_level + len - 1``."""

    first_level: int
    components: np.ndarray  #: uint32, connected components (general sense)
    solid_components: np.ndarray  #: uint32, interior triangles joined through edges


@dataclasses.dataclass(frozen=True)
class OptimalLevel:
    rank: int
    alpha_sq: float
    components: int  #: solid components (regularized answer) or connected components (general)
    holes: int = 0  #: holes at that rank, of the regularized or the general complex as the answer's sense


@dataclasses.dataclass(frozen=True)
class Optimal:
    """The smallest rank with at most N components (and at most H holes, when asked): in CGAL's
    regularized sense (every point on an interior triangle) and in the general sense; ``None``
    where no rank qualifies."""

    regularized: Optional[OptimalLevel]
    general: Optional[OptimalLevel]


@dataclasses.dataclass(frozen=True)
class BettiCurves:
    """Betti numbers at each level ``first_level .. first_level + len - 1``: b0 (components) and b1
    (holes) of the general complex (every simplex that is in) and of the regularized one (its
    closed interior triangles; triangles sharing only a vertex are one component, unlike
    :attr:`ComponentCurve.solid_components`)."""

    first_level: int
    components: np.ndarray  #: uint32, b0 of the general complex
    holes: np.ndarray  #: uint32, b1 of the general complex
    regularized_components: np.ndarray  #: uint32, b0 of the regularized complex
    regularized_holes: np.ndarray  #: uint32, b1 of the regularized complex


@dataclasses.dataclass(frozen=True)
class PersistencePairs:
    """The classes of one homology dimension ``d`` (0: components, 1: holes), in the diagram's
    order (birth rank, death rank with essential classes last, then the creator's canonical
    position). Values are squared radii (``alpha_sq``), as GUDHI's alpha complex filtration."""

    dimension: int
    birth_rank: np.ndarray  #: (n,) int64, 0..K
    death_rank: np.ndarray  #: (n,) int64, birth_rank + 1 .. K, or -1 for an essential class
    birth: np.ndarray  #: (n,) float64, alpha_sq where the class is born (0 for rank 0)
    death: np.ndarray  #: (n,) float64, alpha_sq where it dies; inf when essential
    creator: np.ndarray  #: (n, d + 1) uint32: the vertex (H0) or edge (H1) that creates it, ascending
    killer: np.ndarray  #: (n, d + 2) uint32: the edge (H0) or triangle (H1) that kills it; 0xFFFFFFFF when essential

    def __len__(self) -> int:
        return len(self.birth_rank)

    @property
    def essential(self) -> np.ndarray:
        """(n,) bool: the classes that never die."""
        return self.death_rank < 0

    @property
    def persistence(self) -> np.ndarray:
        """(n,) float64: death - birth (inf for essential classes)."""
        return self.death - self.birth

    def intervals(self) -> np.ndarray:
        """(n, 2) float64 (birth, death) rows, like GUDHI's ``persistence_intervals_in_dimension``."""
        return np.stack([self.birth, self.death], axis=1) if len(self) else np.empty((0, 2), dtype=np.float64)


@dataclasses.dataclass(frozen=True)
class PersistenceDiagram:
    """The persistence diagram of the alpha filtration (H0 and H1), exact by ranks: every class
    whose death rank is above its birth rank (and, with ``min_persistence``, whose death - birth
    is at least that). A dimension that was not asked for is empty."""

    h0: PersistencePairs
    h1: PersistencePairs

    def __getitem__(self, dimension: int) -> PersistencePairs:
        if dimension == 0:
            return self.h0
        if dimension == 1:
            return self.h1
        raise IndexError(f"dimension {dimension!r}: a planar diagram has 0 and 1 only")

    def intervals(self, dimension: int) -> np.ndarray:
        """(n, 2) float64 (birth, death) rows of one dimension, like GUDHI's
        ``persistence_intervals_in_dimension`` (death inf for essential classes)."""
        return self[dimension].intervals()
