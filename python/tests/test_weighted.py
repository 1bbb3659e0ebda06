"""Weighted families from Python (issue 18): ``galpha.local().build(points, weights=...)`` against
GUDHI's weighted alpha complex in exact mode (an independent implementation over CGAL's regular
triangulation): the same distinct thresholds of edges and triangles (GUDHI's filtration values of
dimension 1 and 2 are their births, within an ulp of the exact values galpha rounds correctly), the
same hidden points (vertices GUDHI leaves out); the handle covers the weights; the network clients
build the same weighted family on the server. (The molecule's exact power ties are broken otherwise by
GUDHI's d-dimensional triangulation: there only the hidden atoms are compared.)"""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest
from conftest import REPO

import galpha
import galpha.aio


def _gudhi_births(points: np.ndarray, weights: np.ndarray):
    gudhi = pytest.importorskip("gudhi")
    tree = gudhi.AlphaComplex(points=points.tolist(), weights=weights.tolist(), precision="exact").create_simplex_tree()
    births, vertices = [], set()
    for simplex, value in tree.get_filtration():
        if len(simplex) == 1:
            vertices.add(simplex[0])
        else:
            births.append(value)
    return np.unique(np.array(births)), vertices


def _same_within_an_ulp(ours: np.ndarray, theirs: np.ndarray) -> None:
    assert ours.shape == theirs.shape
    gap = np.abs(ours - theirs)
    allowed = np.spacing(np.maximum(np.abs(ours), np.abs(theirs)))
    bad = np.nonzero(gap > allowed)[0]
    assert bad.size == 0, f"{bad.size} values differ by more than an ulp, first at rank {bad[:1] + 1}"


def _molecule():
    rows = np.loadtxt(REPO / "data" / "pdb_2xhe_radii.txt", comments="#", skiprows=4)
    return np.ascontiguousarray(rows[:, :2]), rows[:, 2]


@pytest.mark.parametrize("kind", ["uniform", "signed", "many_hidden"])
def test_weighted_family_matches_gudhi(kind: str) -> None:
    rng = np.random.default_rng(7)
    points = rng.random((1500, 2))
    spacing2 = 1.0 / len(points)
    if kind == "uniform":
        weights = rng.random(len(points)) * spacing2
    elif kind == "signed":
        weights = (rng.random(len(points)) * 2.0 - 1.0) * spacing2
    else:
        weights = np.where(np.arange(len(points)) % 2 == 0, 4.0 * spacing2, 0.0)
    family = galpha.local("cpu").build(points, weights=weights)
    births, vertices = _gudhi_births(points, weights)
    # Thresholds below 0 are GUDHI's too (overlapping disks); galpha's spectrum keeps them.
    _same_within_an_ulp(family.spectrum(), births)
    hidden = set(family.hidden_points.tolist())
    assert hidden == set(range(len(points))) - vertices
    s = family.summary
    assert s.weighted and s.hidden_points == len(hidden)
    if kind == "many_hidden":
        assert len(hidden) > 100


def test_the_molecule_with_element_radii_hides_what_gudhi_hides() -> None:
    # Coordinates with three decimals and one radius per element make exact power ties, which
    # GUDHI's d-dimensional regular triangulation breaks otherwise than CGAL's 2D one (galpha
    # follows the latter: weighted_family_cgal_test compares this set's thresholds exactly), so
    # only what no tie changes is compared here: the hidden atoms.
    points, radii = _molecule()
    weights = radii * radii
    family = galpha.local("cpu").build(points, weights=weights)
    _, vertices = _gudhi_births(points, weights)
    assert set(family.hidden_points.tolist()) == set(range(len(points))) - vertices
    # At alpha_sq = 0 the complex is the union of the van der Waals disks: hidden atoms are out.
    c = family.classify(alpha_sq=0.0)
    assert c.vertex_counts.exterior == len(family.hidden_points)


def test_weights_change_the_handle_and_are_checked() -> None:
    points = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 1.75], [1.0, 0.6]])
    local = galpha.local("cpu")
    plain = local.build(points)
    weighted = local.build(points, weights=[1.0, 1.0, 1.0, 0.5])
    assert weighted.handle != plain.handle
    assert local.build(points, weights=np.array([1.0, 1.0, 1.0, 0.5])).handle == weighted.handle
    assert not plain.summary.weighted and plain.hidden_points.size == 0
    # Negative thresholds come first; below minus the largest weight nothing is in.
    assert weighted.spectrum()[0] < 0.0
    assert weighted.classify(alpha_sq=-1.5).vertex_counts.singular == 0
    assert weighted.classify(alpha_sq=-1.0).vertex_counts.singular == 4
    with pytest.raises(galpha.InvalidInput, match="one per point"):
        local.build(points, weights=[1.0, 2.0])
    with pytest.raises(galpha.InvalidInput, match="weight 2 is not finite"):
        local.build(points, weights=[1.0, 2.0, math.nan, 0.0])


def test_network_clients_build_the_weighted_family(client, server) -> None:
    """The server builds what galpha.local() builds from (x, y, w) uploads, encoded or raw, under
    the same handle; its hidden points come back from the count and Classify at rank 0, with
    duplicates of hidden points (Classify lists first occurrences only). Decimal coordinates and
    weights go up as scaled integers, the weights with their own scale."""
    rng = np.random.default_rng(9)
    points = rng.integers(0, 10**6, (2000, 2)) / 1e6  # X / 10^6, as decimal text parses
    weight_integers = rng.integers(-50, 500, len(points))
    weights = weight_integers / 1e6
    # Duplicates (same positions and weights), and a lighter point at a point's position: a point
    # of its own, hidden, whose heavier twin is not its duplicate.
    points = np.vstack([points, points[:3], points[3:4]])
    weights = np.concatenate([weights, weights[:3], (weight_integers[3:4] - 100) / 1e6])
    local = galpha.local("cpu").build(points, weights=weights)
    remote = client.build(points, weights=weights)
    assert remote.handle == local.handle
    assert remote.summary.upload_bytes < 12 * len(points)  # scaled integers, not 24-byte triples
    assert remote.summary.weighted and remote.summary.hidden_points == local.summary.hidden_points > 0
    assert len(points) - 1 in set(local.hidden_points.tolist())
    np.testing.assert_array_equal(remote.hidden_points, local.hidden_points)
    np.testing.assert_array_equal(remote.spectrum(), local.spectrum())
    for rank in (0, local.spectrum_size // 2):
        ours, theirs = remote.classify(rank=rank), local.classify(rank=rank)
        assert ours.vertex_counts == theirs.vertex_counts and ours.edge_counts == theirs.edge_counts
        np.testing.assert_array_equal(ours.triangle_classes, theirs.triangle_classes)
    assert remote.release()
    raw = client.build(points, weights=weights, encoding="raw")
    assert raw.handle == local.handle and not raw.summary.cached
    np.testing.assert_array_equal(raw.hidden_points, local.hidden_points)
    assert client.family(local.handle, points, weights=weights).summary.hidden_points == local.summary.hidden_points
    unweighted = client.build(points)
    assert unweighted.handle != local.handle and unweighted.hidden_points.size == 0

    async def run() -> None:
        async with galpha.aio.connect(server.address, timeout=60) as aio_client:
            family = await aio_client.build(points, weights=weights)
            assert family.handle == local.handle and family.summary.cached
            np.testing.assert_array_equal(await family.hidden_points(), local.hidden_points)

    asyncio.run(run())
    with pytest.raises(galpha.InvalidInput, match="one per point"):
        client.build(points, weights=weights[1:])
