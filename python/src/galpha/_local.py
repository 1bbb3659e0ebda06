"""The in-process backend: :class:`LocalFamilyBackend` answers :class:`galpha._backend.FamilyBackend`
from the embedded engine, the ``galpha._engine`` extension (python/engine/, built by CMake with
``GALPHA_BUILD_PYTHON``).

The extension computes every answer in C++ with the GIL released and returns NumPy arrays (the
points and the family's index arrays cross without copies); this module only wraps them in the
dataclasses of :mod:`galpha._types` and turns ``_engine.EngineError`` into galpha's exceptions, by
the same code numbers the server uses (so both backends raise the same classes for the same
mistakes). Arrays that every answer of a family shares (the spectrum, the vertices, edges and
triangles of a full classification) are read-only views into the family.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, List, Optional, Tuple, TypeVar

import numpy as np

from . import _engine
from ._errors import error_for_code
from ._types import (
    BettiCurves,
    BuildSummary,
    ClassCounts,
    Classification,
    ComponentCurve,
    Hole,
    MasterList,
    Mode,
    Optimal,
    OptimalLevel,
    PersistenceDiagram,
    PersistencePairs,
    ShapePolygon,
    ShapeRings,
    Threshold,
    VertexRule,
)

__all__ = ["LocalFamilyBackend", "build_local", "build_many_local"]

_T = TypeVar("_T")


def _translated(call: Callable[..., _T]) -> Callable[..., _T]:
    """Runs an engine call, raising galpha's exception for an EngineError (without the chain)."""

    @functools.wraps(call)
    def wrapper(*args: Any, **kwargs: Any) -> _T:
        try:
            return call(*args, **kwargs)
        except _engine.EngineError as e:
            raise error_for_code(e.code, e.message) from None

    return wrapper


def _mode(mode: Mode) -> str:
    return Mode(mode).value


def _rule(rule: VertexRule) -> str:
    return VertexRule(rule).value


def _counts(c: tuple) -> ClassCounts:
    return ClassCounts(exterior=c[0], singular=c[1], regular=c[2], interior=c[3])


def _optimal_level(level: Optional[tuple]) -> Optional[OptimalLevel]:
    if level is None:
        return None
    rank, alpha_sq, components, holes = level
    return OptimalLevel(rank=rank, alpha_sq=alpha_sq, components=components, holes=holes)


def _pairs(dimension: int, p: dict) -> PersistencePairs:
    return PersistencePairs(dimension=dimension, **p)


class LocalFamilyBackend:
    """A family built in this process; :meth:`release` frees it (queries then raise NotFound)."""

    def __init__(self, family: "_engine.Family") -> None:
        self._family = family
        self._summary: Optional[BuildSummary] = None

    def __repr__(self) -> str:
        return f"<galpha.LocalFamilyBackend {self._family!r}>"

    @property
    @_translated
    def handle(self) -> str:
        return self._family.handle

    @_translated
    def summary(self) -> BuildSummary:
        if self._summary is None:
            s = self._family.summary()
            self._summary = BuildSummary(cached=False, **s)
        return self._summary

    @_translated
    def spectrum(self, first_rank: int, count: int) -> np.ndarray:
        return self._family.spectrum(int(first_rank), int(count))

    @_translated
    def rank_lower_bound(self, alpha_sq: float) -> int:
        return self._family.rank_lower_bound(float(alpha_sq))

    @_translated
    def classify(
        self, threshold: Threshold, mode: Mode, vertex_rule: VertexRule, non_exterior_only: bool, summary_only: bool
    ) -> Classification:
        c = self._family.classify(
            threshold.kind, threshold.value, _mode(mode), _rule(vertex_rule), bool(non_exterior_only), bool(summary_only)
        )
        return Classification(
            level=c["level"],
            alpha_sq=c["alpha_sq"],
            vertex_counts=_counts(c["vertex_counts"]),
            edge_counts=_counts(c["edge_counts"]),
            triangle_counts=_counts(c["triangle_counts"]),
            components=c["components"],
            solid_components=c["solid_components"],
            interior_area=c["interior_area"],
            vertices=c["vertices"],
            vertex_classes=c["vertex_classes"],
            edges=c["edges"],
            edge_classes=c["edge_classes"],
            triangles=c["triangles"],
            triangle_classes=c["triangle_classes"],
            holes=c["holes"],
            hull_area=c["hull_area"],
        )

    @_translated
    def shape_rings(self, threshold: Threshold, mode: Mode, min_hole_area: float = 0.0) -> ShapeRings:
        s = self._family.shape_rings(threshold.kind, threshold.value, _mode(mode), float(min_hole_area))
        return ShapeRings(
            polygons=[ShapePolygon(outer=outer, holes=list(holes)) for outer, holes in s["polygons"]],
            singular_edges=s["singular_edges"],
            isolated_points=s["isolated_points"],
            area=s["area"],
        )

    @_translated
    def holes(self, threshold: Threshold, min_area: float, points: np.ndarray) -> List[Hole]:
        # The engine measures with its own copy of the points (the same values).
        return [
            Hole(polygon=polygon, ring=ring, area=area)
            for polygon, ring, area in self._family.holes(threshold.kind, threshold.value, float(min_area))
        ]

    @_translated
    def master_list(self, first_rank: int, last_rank: int) -> MasterList:
        m = self._family.master_list(int(first_rank), int(last_rank))
        return MasterList(ranks=m["ranks"], kinds=m["kinds"], endpoints=m["endpoints"], vertex_indices=m["vertex_indices"])

    @_translated
    def components(self, first_level: int, last_level: int) -> ComponentCurve:
        c = self._family.components(int(first_level), int(last_level))
        return ComponentCurve(
            first_level=c["first_level"], components=c["components"], solid_components=c["solid_components"]
        )

    @_translated
    def betti(self, first_level: int, last_level: int) -> BettiCurves:
        return BettiCurves(**self._family.betti(int(first_level), int(last_level)))

    @_translated
    def optimal(self, max_components: int, max_holes: Optional[int] = None) -> Optimal:
        o = self._family.optimal(int(max_components), None if max_holes is None else int(max_holes))
        return Optimal(regularized=_optimal_level(o["regularized"]), general=_optimal_level(o["general"]))

    @_translated
    def persistence(self, dimensions: Tuple[int, ...], min_persistence: float) -> PersistenceDiagram:
        h0, h1 = self._family.persistence([int(d) for d in dimensions], float(min_persistence))
        return PersistenceDiagram(h0=_pairs(0, h0), h1=_pairs(1, h1))

    @_translated
    def hidden_points(self, points: np.ndarray) -> np.ndarray:
        return self._family.hidden_points()

    def release(self) -> bool:
        return self._family.release()


@_translated
def build_local(
    points: np.ndarray,
    backend: str,
    progress: Optional[Callable[[str, float], None]],
    *,
    name: str = "",
    weights: Optional[np.ndarray] = None,
) -> LocalFamilyBackend:
    """Builds the family of ``points`` (an (N, 2) float64 C-contiguous array, used without a copy)
    on ``backend`` ("auto", "cpu" or "cuda"); with ``weights`` (N squared radii) the weighted
    family. ``progress(phase, fraction)`` is called after each engine phase. Ctrl-C stops the
    build between phases (KeyboardInterrupt), as does an exception raised by ``progress``
    (re-raised here)."""
    return LocalFamilyBackend(_engine.build(points, backend, progress, name, weights))


@_translated
def build_many_local(points: np.ndarray, set_begin: np.ndarray, backend: str, names: List[str]) -> List[LocalFamilyBackend]:
    """Builds the families of many point sets in one packed build: set s is
    ``points[set_begin[s]:set_begin[s + 1]]``, labelled ``names[s]``; each family equals
    :func:`build_local`'s of the set alone. Unweighted."""
    return [LocalFamilyBackend(f) for f in _engine.build_many(points, set_begin, names, backend)]
