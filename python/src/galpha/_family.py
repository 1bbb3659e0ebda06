"""Family: one built family of alpha shapes and every query over it, the same on both backends.

Thresholds are explicit keywords, as in ``alphactl``: ``alpha`` (a radius), ``alpha_sq`` (a squared
radius) or ``rank`` (0..K, the complex at ``spectrum[rank - 1]``). Geometry answers are shapely
geometries (valid OGC, holes included) in the points' coordinates, or GeoDataFrames carrying the
points' CRS.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Iterable, List, Optional, Tuple, Union

import numpy as np

from ._backend import FamilyBackend
from ._crs import Frame
from . import _wkb
from ._errors import InvalidInput
from ._types import (
    BettiCurves,
    BuildSummary,
    Classification,
    ComponentCurve,
    Hole,
    MasterList,
    Mode,
    Optimal,
    PersistenceDiagram,
    ShapeRings,
    Threshold,
    VertexRule,
)


def threshold_from(
    alpha: Optional[float], alpha_sq: Optional[float], rank: Optional[int], ratio: Optional[float] = None
) -> Threshold:
    """The one threshold among the keywords; InvalidInput unless exactly one is given.

    ``ratio`` (0..1, PostGIS ``ST_ConcaveHull``'s target_percent, shapely's ``concave_hull`` ratio)
    names the smallest rank whose regularized area is at least ``ratio`` times the convex hull's,
    decided exactly by the engine."""
    named = (("alpha", alpha), ("alpha_sq", alpha_sq), ("rank", rank), ("ratio", ratio))
    given = [(k, v) for k, v in named if v is not None]
    if len(given) != 1:
        names = ", ".join(k for k, _ in given) or "none"
        raise InvalidInput(f"give exactly one of alpha=, alpha_sq=, rank= or ratio= (got {names})")
    kind, value = given[0]
    if kind == "rank":
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise InvalidInput(f"rank must be an integer, got {value!r}")
        return Threshold("rank", int(value))
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidInput(f"{kind} must be a number, got {value!r}") from None
    if kind == "ratio" and not 0.0 <= number <= 1.0:
        raise InvalidInput(f"ratio {value!r} is outside 0..1 (the share of the convex hull's area the shape covers)")
    return Threshold(kind, number)


def radius_from_alphashape(alpha: float) -> float:
    """The galpha radius ``alpha`` for the ``alpha`` parameter of the Python ``alphashape`` package.

    ``alphashape`` keeps a triangle when its circumradius is below ``1 / alpha`` (its parameter is
    an inverse radius; 0 gives the convex hull). galpha's ``alpha`` is the radius itself, and a
    simplex is in the complex when its threshold is at or below it, decided exactly. So
    ``family.shape(alpha=radius_from_alphashape(a))`` is the exact counterpart of
    ``alphashape.alphashape(points, a)`` (the two differ only on triangles whose circumradius is
    exactly ``1 / a``, and where alphashape's floating point misjudges one). ``a = 0`` gives
    ``inf``: every simplex, the convex hull.
    """
    a = float(alpha)
    if a < 0 or a != a:
        raise InvalidInput(f"alphashape's alpha must be >= 0, got {alpha!r}")
    return float("inf") if a == 0 else 1.0 / a


def _mode(mode: Union[str, Mode]) -> Mode:
    try:
        return Mode(mode)
    except ValueError:
        raise InvalidInput(f"unknown mode {mode!r} (expected 'general' or 'regularized')") from None


def _rule(rule: Union[str, VertexRule]) -> VertexRule:
    try:
        return VertexRule(rule)
    except ValueError:
        raise InvalidInput(f"unknown vertex_rule {rule!r} (expected 'report' or 'cgal')") from None


_MAX_UINT32 = (1 << 32) - 1


def _integer(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidInput(f"{name} must be an integer, got {value!r}")
    return int(value)


def level_range(first_rank: Any, last_rank: Any, k: int) -> Tuple[int, int]:
    """first_rank .. last_rank (last None: K) checked within 0..K."""
    first = _integer("first_rank", first_rank)
    last = k if last_rank is None else _integer("last_rank", last_rank)
    if not 0 <= first <= last <= k:
        raise InvalidInput(f"ranks {first}..{last} are not within 0..{k}")
    return first, last


def optimal_bounds(components: Any, holes: Any) -> Tuple[int, Optional[int]]:
    """(max_components in 1..2^32-1, max_holes None or in 0..2^32-1), as the wire's uint32s."""
    if isinstance(components, bool) or not isinstance(components, (int, np.integer)) or not 1 <= components <= _MAX_UINT32:
        raise InvalidInput(f"components must be an integer in 1..{_MAX_UINT32}, got {components!r}")
    if holes is None:
        return int(components), None
    if isinstance(holes, bool) or not isinstance(holes, (int, np.integer)) or not 0 <= holes <= _MAX_UINT32:
        raise InvalidInput(f"holes must be None or an integer in 0..{_MAX_UINT32}, got {holes!r}")
    return int(components), int(holes)


def persistence_arguments(dimensions: Union[int, Iterable[int]], min_persistence: Any) -> Tuple[Tuple[int, ...], float]:
    """The dimensions asked for (0, 1 or both; sorted, once each) and min_persistence, checked as
    the service checks them (by the same messages), before any call."""
    if isinstance(dimensions, (int, np.integer)) and not isinstance(dimensions, bool):
        dimensions = (int(dimensions),)
    try:
        asked = list(dimensions)  # type: ignore[arg-type]
    except TypeError:
        raise InvalidInput(f"dimensions must be 0, 1 or a sequence of them, got {dimensions!r}") from None
    if not asked:
        raise InvalidInput("dimensions is empty: give 0 (components), 1 (holes) or both")
    for d in asked:
        if isinstance(d, bool) or not isinstance(d, (int, np.integer)):
            raise InvalidInput(f"a dimension must be an integer, got {d!r}")
        if d not in (0, 1):
            raise InvalidInput(f"dimension {d} has no classes: a planar alpha complex has H0 (0) and H1 (1) only")
    try:
        minimum = float(min_persistence)
    except (TypeError, ValueError):
        raise InvalidInput(f"min_persistence must be a number, got {min_persistence!r}") from None
    if math.isnan(minimum) or minimum < 0:
        raise InvalidInput(f"min_persistence {c_double_text(minimum)} is not a length: give 0 or more")
    return tuple(sorted({int(d) for d in asked})), minimum


def c_double_text(value: float) -> str:
    """A double as absl::StrCat writes it (six significant digits, %g), so that messages the
    package writes read as the service's."""
    return "%.6g" % value


def area_argument(name: str, value: Any, zero_means: str) -> float:
    """An area bound (min_hole_area, min_area) as a float, checked as the service checks
    min_hole_area (by its message) before any call: a number, 0 or more (NaN refused)."""
    if isinstance(value, bool):
        raise InvalidInput(f"{name} must be a number, got {value!r}")
    try:
        area = float(value)
    except (TypeError, ValueError):
        raise InvalidInput(f"{name} must be a number, got {value!r}") from None
    if math.isnan(area) or area < 0:
        raise InvalidInput(f"{name} {c_double_text(area)} is not an area: give 0 ({zero_means}) or more")
    return area


def exact_ring_area(ring: np.ndarray, points: np.ndarray) -> Fraction:
    """The exact area of a ring of input indices (every double is a rational): half the absolute
    value of the shoelace sum, as core/geometry/shape_holes.cpp computes it in GMP rationals."""
    xy = [(Fraction(float(x)), Fraction(float(y))) for x, y in points[ring]]
    twice = sum(
        (a[0] * b[1] - b[0] * a[1] for a, b in zip(xy, xy[1:] + xy[:1])),
        Fraction(0),
    )
    return abs(twice) / 2


def ring_area(ring: np.ndarray, points: np.ndarray) -> float:
    """The area of a ring as core's RingArea reports it: the exact area's nearest double (Python's
    float() of a Fraction rounds correctly)."""
    return float(exact_ring_area(ring, points))


def holes_from_rings(rings: ShapeRings, points: np.ndarray, min_area: float) -> List[Hole]:
    """The holes of a (regularized) shape by rings, as core's ListHoles lists them: every hole ring
    whose exact area is at least min_area, largest exact area first (a stable sort: equal areas
    keep polygon, then ring order), each ring reversed to counter-clockwise."""
    bound = Fraction(min_area)
    found = []
    for index, polygon in enumerate(rings.polygons):
        for ring in polygon.holes:
            area = exact_ring_area(ring, points)
            if area >= bound:
                hole = Hole(polygon=index, ring=np.ascontiguousarray(ring[::-1], dtype=np.uint32), area=float(area))
                found.append((area, hole))
    found.sort(key=lambda item: -item[0])
    return [hole for _, hole in found]


def holes_geodataframe(holes: List[Hole], points: np.ndarray, crs: Any) -> Any:
    """One row per hole: ``polygon``, ``area`` and the hole as a shapely Polygon, in ``crs``."""
    import geopandas

    geometries = [_wkb.load(_wkb.polygon_wkb(points, h.ring, [])) for h in holes]
    columns = {
        "polygon": np.array([h.polygon for h in holes], dtype=np.int64),
        "area": np.array([h.area for h in holes], dtype=np.float64),
    }
    return geopandas.GeoDataFrame(columns, geometry=geometries, crs=crs)


def rings_to_shapely(rings: ShapeRings, points: np.ndarray, mode: Mode) -> Any:
    """A MultiPolygon (regularized), or a GeometryCollection of the MultiPolygon, the singular edges
    as a MultiLineString and the isolated points as a MultiPoint, each present when not empty
    (general). Made in one GEOS call (_wkb.py says why)."""
    # Typed even when empty (a MultiPolygon of no members: MULTIPOLYGON EMPTY).
    multipolygon = _wkb.multipolygon_wkb(points, rings.polygons)
    if mode == Mode.REGULARIZED:
        return _wkb.load(multipolygon)
    parts: List[bytes] = [multipolygon] if rings.polygons else []
    if len(rings.singular_edges):
        parts.append(_wkb.multilinestring_wkb(points, rings.singular_edges))
    if len(rings.isolated_points):
        parts.append(_wkb.multipoint_wkb(points, rings.isolated_points))
    return _wkb.load(_wkb.collection_wkb(parts))


def weighted_rows(computed: np.ndarray, weights: Optional[np.ndarray]) -> np.ndarray:
    """(N, 2) points, or (N, 3) rows (x, y, w) with their weights: what a Build stream carries, and
    what identifies a point of a weighted family (the engine's duplicates share position and
    weight). A weighted set of no points is the empty set, unweighted (one family and handle for
    every empty set)."""
    return computed if weights is None or len(weights) == 0 else np.column_stack((computed, weights))


class Family:
    """The exact family of alpha shapes of one point set (every alpha at once).

    Made by ``Client.build``; the queries run on the backend that built it (the server's cache, or
    this process). Use it as a context manager to release it when done.
    """

    def __init__(
        self, backend: FamilyBackend, points: np.ndarray, frame: Optional[Frame] = None, weights: Optional[np.ndarray] = None
    ) -> None:
        self._backend = backend
        self._points = points
        self._frame = frame if frame is not None else Frame(None, points)
        # The weights the family was built with (None unweighted): with the computed points, what
        # a server's hidden points are matched against (weighted_rows).
        self._weights = weights
        self._hidden: Optional[np.ndarray] = None
        #: The CRS of the coordinates: the ``crs=`` of the build, else the GeoSeries' or
        #: GeoDataFrame's it was built from; None for planar coordinates.
        self.crs = self._frame.crs

    @property
    def projection(self) -> Optional[str]:
        """For a geographic CRS, the local projection (a PROJ string) the family is computed in:
        alpha in metres, areas in square metres; None otherwise (computed in the input's units)."""
        return self._frame.projection

    def __repr__(self) -> str:
        s = self.summary
        return f"<galpha.Family {self.handle[:19]}... {s.points} points, K={s.spectrum_size}, {s.backend}>"

    def __enter__(self) -> "Family":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.release()

    @property
    def handle(self) -> str:
        """The content handle ("sha256-..."), the same for equal point arrays everywhere."""
        return self._backend.handle

    @property
    def points(self) -> np.ndarray:
        """The (N, 2) float64 points, as given; indices in every answer name their rows."""
        return self._points

    @property
    def summary(self) -> BuildSummary:
        return self._backend.summary()

    @property
    def hidden_points(self) -> np.ndarray:
        """Input indices (uint32, ascending) of the points a weighted family hides: no vertex of
        the regular triangulation, EXTERIOR at every threshold. Empty for an unweighted family."""
        if self._hidden is None:  # a server answers it with a Classify call: once
            self._hidden = self._backend.hidden_points(weighted_rows(self._frame.computed, self._weights))
        return self._hidden

    @property
    def spectrum_size(self) -> int:
        """K: the number of distinct thresholds; ranks run 0..K."""
        return self._backend.summary().spectrum_size

    def spectrum(self, first_rank: int = 1, count: Optional[int] = None) -> np.ndarray:
        """The distinct squared thresholds (nearest doubles of the exact values), ascending: ranks
        first_rank .. first_rank + count - 1 (all to K by default)."""
        k = self.spectrum_size
        if first_rank < 1 or first_rank > k + 1:
            raise InvalidInput(f"first_rank {first_rank} is outside 1..{k + 1}")
        if count is None:
            count = k + 1 - first_rank
        if count < 0:
            raise InvalidInput(f"count must be >= 0, got {count}")
        return self._backend.spectrum(first_rank, count) if count else np.empty(0, dtype=np.float64)

    def rank_lower_bound(self, alpha_sq: float) -> int:
        """The first rank whose exact threshold is >= alpha_sq (K + 1 when none is; CGAL's
        alpha_lower_bound)."""
        return self._backend.rank_lower_bound(float(alpha_sq))

    def classify(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.GENERAL,
        vertex_rule: Union[str, VertexRule] = VertexRule.REPORT,
        non_exterior_only: bool = False,
        summary_only: bool = False,
    ) -> Classification:
        """The class of every simplex at one threshold, as NumPy arrays (see Classification)."""
        return self._backend.classify(
            threshold_from(alpha, alpha_sq, rank, ratio), _mode(mode), _rule(vertex_rule), non_exterior_only, summary_only
        )

    def shape_rings(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.REGULARIZED,
        min_hole_area: float = 0.0,
    ) -> ShapeRings:
        """The shape by input indices: polygons (outer ring and holes), singular edges, isolated
        points, area. Holes whose area is below ``min_hole_area`` (squared input units) are
        filled: their rings leave the polygons and their areas join ``area`` (0, the default,
        keeps every hole; a negative or NaN bound raises InvalidInput)."""
        threshold = threshold_from(alpha, alpha_sq, rank, ratio)
        m = _mode(mode)
        return self._backend.shape_rings(threshold, m, area_argument("min_hole_area", min_hole_area, "keep every hole"))

    def shape(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.REGULARIZED,
        as_geodataframe: bool = False,
        min_hole_area: float = 0.0,
    ) -> Any:
        """The alpha shape at one threshold as shapely geometry (valid, holes included).

        ``mode="regularized"`` (the default, what GIS users call the concave hull) gives a
        MultiPolygon; ``mode="general"`` a GeometryCollection that also holds the singular edges
        (MultiLineString) and isolated points (MultiPoint). With ``as_geodataframe=True``: a
        GeoDataFrame with one row per polygon (``kind="polygon"``, ``area``), then one row for the
        singular edges and one for the isolated points where present, in the points' CRS.
        ``min_hole_area``: holes with a smaller area (squared input units, as :meth:`holes`
        measures them) are filled; 0 keeps every hole.
        """
        m = _mode(mode)
        rings = self.shape_rings(
            alpha=alpha, alpha_sq=alpha_sq, rank=rank, ratio=ratio, mode=m, min_hole_area=min_hole_area
        )
        if not as_geodataframe:
            return rings_to_shapely(rings, self._points, m)
        return self._geodataframe(rings)

    def _geodataframe(self, rings: ShapeRings) -> Any:
        import geopandas

        # The general shape's parts (one GEOS call); one row a polygon, then one a part.
        parts = list(rings_to_shapely(rings, self._points, Mode.GENERAL).geoms)
        geometries: List[Any] = list(parts.pop(0).geoms) if rings.polygons else []
        kinds: List[str] = ["polygon"] * len(geometries)
        if len(rings.singular_edges):
            kinds.append("singular_edges")
        if len(rings.isolated_points):
            kinds.append("isolated_points")
        geometries += parts
        frame = geopandas.GeoDataFrame({"kind": kinds}, geometry=geometries, crs=self.crs)
        if self.projection is None:
            frame["area"] = [g.area if k == "polygon" else 0.0 for k, g in zip(kinds, geometries)]
        else:
            # Square metres, as the engine measures them, not the square degrees of the geometry.
            computed = self._frame.computed
            areas = [ring_area(p.outer, computed) - sum(ring_area(h, computed) for h in p.holes) for p in rings.polygons]
            frame["area"] = areas + [0.0] * (len(kinds) - len(areas))
        return frame

    def holes(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        min_area: float = 0.0,
        as_geodataframe: bool = False,
    ) -> Any:
        """The holes of the regularized shape at one threshold with an exact area of at least
        ``min_area`` (squared input units), largest first, as ``alphactl holes`` lists them: a list
        of :class:`Hole` (polygon index, counter-clockwise open ring of input indices, the exact
        area's nearest double). With ``as_geodataframe=True``: a GeoDataFrame with columns
        ``polygon``, ``area`` and each hole as a shapely Polygon, in the points' CRS.

        The local engine lists them in C++; the network client asks the server for the shape's
        rings and measures them here, from the points this family keeps (``family.points``), to
        the same doubles."""
        threshold = threshold_from(alpha, alpha_sq, rank, ratio)
        minimum = area_argument("min_area", min_area, "every hole")
        holes = self._backend.holes(threshold, minimum, self._frame.computed)
        return holes_geodataframe(holes, self._points, self.crs) if as_geodataframe else holes

    def master_list(self, rank: int, last_rank: Optional[int] = None) -> MasterList:
        """Master-list entries of ranks rank .. last_rank (1..K; last_rank defaults to rank)."""
        return self._backend.master_list(int(rank), int(rank if last_rank is None else last_rank))

    def components(self, first_level: int = 0, last_level: Optional[int] = None) -> ComponentCurve:
        """Connected and solid components at every level first_level .. last_level (0..K; all by
        default): the curve over all ranks. :meth:`betti` adds the holes."""
        k = self.spectrum_size
        last = k if last_level is None else int(last_level)
        if not 0 <= first_level <= last <= k:
            raise InvalidInput(f"levels {first_level}..{last} are not within 0..{k}")
        return self._backend.components(int(first_level), last)

    def betti(self, first_rank: int = 0, last_rank: Optional[int] = None) -> BettiCurves:
        """Betti numbers at every rank first_rank .. last_rank (0..K; all by default): b0
        (components) and b1 (holes) of the general complex and of the regularized one. O(1) a
        rank."""
        first, last = level_range(first_rank, last_rank, self.spectrum_size)
        return self._backend.betti(first, last)

    def persistence(
        self, dimensions: Union[int, Iterable[int]] = (0, 1), min_persistence: float = 0.0
    ) -> PersistenceDiagram:
        """The persistence diagram of the alpha filtration: every component (``dimensions`` 0) and
        hole (1) class with its birth and death (squared radii, exact by rank; inf for a class that
        never dies) and the simplices that create and kill it. ``min_persistence`` (alpha_sq
        units) leaves out pairs with death - birth below it (essential classes always stay). A
        dimension not asked for is empty. O(n log n)."""
        dims, minimum = persistence_arguments(dimensions, min_persistence)
        return self._backend.persistence(dims, minimum)

    def optimal(self, components: int = 1, holes: Optional[int] = None) -> Optimal:
        """The smallest rank with at most ``components`` components and, when ``holes`` is given,
        at most that many holes (CGAL's regularized sense, holes of the regularized complex, and
        the general one); each answer carries the holes at its rank."""
        return self._backend.optimal(*optimal_bounds(components, holes))

    def release(self) -> bool:
        """Frees the family (on a server: drops it from the cache). True when it was held."""
        return self._backend.release()
