"""The protocol both backends implement: what :class:`galpha.Family` needs from a built family.

``galpha.connect`` answers it over gRPC (``_network.py``), ``galpha.local`` from the embedded
engine (``_local.py`` over the ``galpha._engine`` extension). :class:`galpha.Family` adds the
user-facing conveniences (threshold keywords, shapely geometry, GeoDataFrames) once, on top.
"""

from __future__ import annotations

from typing import List, Optional, Protocol, Tuple

import numpy as np

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


class FamilyBackend(Protocol):
    @property
    def handle(self) -> str:
        """"sha256-" and 64 hex digits: the content handle (the same on both backends)."""

    def summary(self) -> BuildSummary: ...

    def spectrum(self, first_rank: int, count: int) -> np.ndarray:
        """Spectrum values of ranks first_rank .. first_rank + count - 1 (clipped at K), float64."""

    def rank_lower_bound(self, alpha_sq: float) -> int:
        """The first rank whose exact threshold is >= alpha_sq (K + 1 when none is)."""

    def classify(
        self, threshold: Threshold, mode: Mode, vertex_rule: VertexRule, non_exterior_only: bool, summary_only: bool
    ) -> Classification: ...

    def shape_rings(self, threshold: Threshold, mode: Mode, min_hole_area: float = 0.0) -> ShapeRings:
        """min_hole_area: checked by the caller (0 or more); holes below it are filled."""

    def holes(self, threshold: Threshold, min_area: float, points: np.ndarray) -> List[Hole]:
        """The regularized shape's holes of area >= min_area (checked by the caller), largest
        first; ``points`` are the family's (the network backend measures the rings with them)."""

    def master_list(self, first_rank: int, last_rank: int) -> MasterList: ...

    def components(self, first_level: int, last_level: int) -> ComponentCurve:
        """Levels first_level .. last_level (0 .. K), inclusive."""

    def betti(self, first_level: int, last_level: int) -> BettiCurves:
        """Levels first_level .. last_level (0 .. K), inclusive."""

    def optimal(self, max_components: int, max_holes: Optional[int]) -> Optimal: ...

    def persistence(self, dimensions: Tuple[int, ...], min_persistence: float) -> PersistenceDiagram:
        """The dimensions (a non-empty tuple of 0 and 1, checked by the caller); the others empty."""

    def hidden_points(self, points: np.ndarray) -> np.ndarray:
        """Input indices (uint32, ascending) of the points a weighted family hides; empty otherwise.
        `points`: the rows the family was built from, (N, 2) or weighted (N, 3) with the weights (a
        server lists first occurrences only: their duplicates, equal rows, are found among them)."""

    def release(self) -> bool:
        """Frees the family (network: drops it from the server's cache); True when it was held."""
