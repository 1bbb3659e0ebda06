"""Area-ratio thresholds from Python (``ratio=``, PostGIS ST_ConcaveHull's target_percent): the
shape at ``ratio`` is the first whose area covers ``ratio`` times the convex hull's, checked with
shapely (GEOS) areas and hulls, an oracle independent of the engine's area curve; both clients and
galpha.aio agree, and the Classification's ``hull_area`` is GEOS's convex hull area.
"""

from __future__ import annotations

import asyncio

import numpy as np
import pytest
import shapely.geometry

import galpha
import galpha.aio
from galpha import InvalidInput

RATIOS = [0.05, 0.3, 0.5, 0.8, 0.95, 1.0]


def clustered(seed: int) -> np.ndarray:
    """Three blobs of different densities: their shapes merge one by one as alpha grows, so the
    area ratio climbs in steps."""
    rng = np.random.default_rng(seed)
    specs = [((0, 0), 1.0, 300), ((8, 1), 0.5, 200), ((3, 7), 2.0, 150)]
    blobs = [rng.normal(centre, scale, size=(count, 2)) for centre, scale, count in specs]
    return np.concatenate(blobs)


@pytest.fixture(scope="module")
def clients(server):
    with galpha.connect(server.address, timeout=120) as network, galpha.local("cpu") as local:
        yield network, local


@pytest.mark.parametrize("which", [0, 1], ids=["network", "local"])
def test_each_ratio_gives_the_first_shape_that_covers_it(clients, which: int) -> None:
    points = clustered(7)
    family = clients[which].build(points)
    hull = shapely.geometry.MultiPoint(points).convex_hull.area
    for ratio in RATIOS:
        summary = family.classify(ratio=ratio, summary_only=True)
        level = summary.level
        assert summary.hull_area == pytest.approx(hull, rel=1e-12)
        covering = family.shape(ratio=ratio)
        assert covering.is_valid
        assert covering.area >= ratio * hull * (1 - 1e-12), ratio
        assert level >= 1
        below = family.shape(rank=level - 1)
        assert below.area < ratio * hull * (1 + 1e-12), ratio
        # Every threshold keyword names the same level.
        assert family.classify(rank=level, summary_only=True).interior_area == summary.interior_area
    assert family.classify(ratio=1.0, summary_only=True).interior_area == pytest.approx(hull, rel=1e-12)
    assert family.classify(ratio=0.0, summary_only=True).level == 0


def test_both_clients_and_aio_agree(clients, server) -> None:
    points = clustered(8)
    network, local = (c.build(points) for c in clients)

    async def aio_levels():
        async with galpha.aio.connect(server.address, timeout=120) as client:
            family = await client.build(points)
            return [(await family.classify(ratio=r, summary_only=True)).level for r in RATIOS]

    levels = [[f.classify(ratio=r, summary_only=True).level for r in RATIOS] for f in (network, local)]
    assert levels[0] == levels[1] == asyncio.run(aio_levels())
    assert levels[0] == sorted(levels[0])  # more area needs a larger alpha
    for ratio in RATIOS:
        assert network.shape(ratio=ratio).equals(local.shape(ratio=ratio))


@pytest.mark.parametrize("which", [0, 1], ids=["network", "local"])
def test_bad_ratios_and_two_thresholds_are_refused(clients, which: int) -> None:
    family = clients[which].build(clustered(9)[:50])
    for ratio in (-0.5, 1.01, float("nan"), "half"):
        with pytest.raises(InvalidInput, match="ratio"):
            family.shape(ratio=ratio)
    with pytest.raises(InvalidInput, match="exactly one of"):
        family.classify(ratio=0.5, rank=3)
