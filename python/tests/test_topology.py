"""Topology of the whole family from Python: Betti curves, persistence diagrams, holes in the
classification summary and the optimal-alpha bound on holes.

Both clients give the same answers on every data set in data/ and on small generated sets; the
diagrams agree with GUDHI's exact alpha-complex persistence (an independent implementation) up to
the few ulps by which GUDHI's doubles differ (tests/gpu/alpha/persistence_gudhi_test.cpp's
MatchWithinUlps, mirrored here); every diagram counts the classes the Betti curves count; bad
arguments raise the same exception on both backends.
"""

from __future__ import annotations

import asyncio
import bisect
import collections
import math
import pathlib
import sys
from typing import Dict, Iterator, List, Tuple

import numpy as np
import pytest
from conftest import DATA_SETS, REPO, read_bin

import galpha
import galpha.aio
from galpha import _local, _network

Interval = Tuple[float, float]


def ring(n: int = 1500, seed: int = 5) -> np.ndarray:
    """Random points in the annulus 10 <= r <= 11: one hole lives from small alpha_sq to ~100."""
    rng = np.random.default_rng(seed)
    angle = 2 * np.pi * rng.random(n)
    radius = 10.0 + rng.random(n)
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)


def holed_grid() -> np.ndarray:
    """A 30 x 30 integer grid with every third point removed: holes of several sizes, tied births."""
    grid = np.array([(i, j) for i in range(30) for j in range(30)], dtype=np.float64)
    return grid[np.arange(len(grid)) % 3 != 1]


def uniform(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).random((n, 2))


SMALL_SETS: Dict[str, np.ndarray] = {
    "one_point": np.array([[1.0, 2.0]]),
    "two_points": np.array([[0.0, 0.0], [3.0, 4.0]]),
    "collinear": np.array([[0.5 * i, 0.25 * i] for i in range(20)]),
    "square_with_center": np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], dtype=np.float64),
    "duplicates": np.repeat(uniform(60, 9), 3, axis=0),
    "uniform_400": uniform(400, 1),
    "holed_grid": holed_grid(),
    "ring": ring(600, 2),
}


@pytest.fixture(scope="module")
def clients(server) -> Iterator[Tuple[galpha.NetworkClient, galpha.LocalClient]]:
    with galpha.connect(server.address, timeout=120) as network, galpha.local("cpu") as local:
        yield network, local


def assert_same_diagram(a: galpha.PersistenceDiagram, b: galpha.PersistenceDiagram) -> None:
    for d in (0, 1):
        x, y = a[d], b[d]
        assert x.dimension == y.dimension == d
        for field in ("birth_rank", "death_rank", "birth", "death", "creator", "killer"):
            got, expected = getattr(x, field), getattr(y, field)
            assert got.dtype == expected.dtype, (d, field)
            assert got.shape == expected.shape, (d, field)
            np.testing.assert_array_equal(got, expected, err_msg=f"H{d} {field}")


def assert_same_betti(a: galpha.BettiCurves, b: galpha.BettiCurves) -> None:
    assert a.first_level == b.first_level
    for field in ("components", "holes", "regularized_components", "regularized_holes"):
        got, expected = getattr(a, field), getattr(b, field)
        assert got.dtype == expected.dtype == np.uint32, field
        np.testing.assert_array_equal(got, expected, err_msg=field)


def alive_counts(pairs: galpha.PersistencePairs, k: int) -> np.ndarray:
    """Classes alive at each rank 0..K: born at or before it, dead after it (or never)."""
    births = np.bincount(pairs.birth_rank, minlength=k + 2)[: k + 1]
    dead = pairs.death_rank[pairs.death_rank >= 0]
    deaths = np.bincount(dead, minlength=k + 2)[: k + 1]
    return np.cumsum(births) - np.cumsum(deaths)


def expect_consistent(family: galpha.Family, diagram: galpha.PersistenceDiagram, betti: galpha.BettiCurves) -> None:
    """The diagram's classes alive at every rank are the Betti curves (b0, b1 of the general
    complex); ranks, values and simplices are well formed."""
    k = family.spectrum_size
    spectrum = np.concatenate([[0.0], family.spectrum()])
    np.testing.assert_array_equal(alive_counts(diagram.h0, k), betti.components.astype(np.int64))
    np.testing.assert_array_equal(alive_counts(diagram.h1, k), betti.holes.astype(np.int64))
    for d, pairs in ((0, diagram.h0), (1, diagram.h1)):
        essential = pairs.death_rank < 0
        assert (pairs.death_rank[~essential] > pairs.birth_rank[~essential]).all()
        assert (pairs.death_rank[~essential] <= k).all() and (pairs.birth_rank <= k).all()
        np.testing.assert_array_equal(pairs.birth, spectrum[pairs.birth_rank])
        np.testing.assert_array_equal(pairs.death[~essential], spectrum[pairs.death_rank[~essential]])
        assert np.isinf(pairs.death[essential]).all()
        assert pairs.creator.shape == (len(pairs), d + 1) and pairs.killer.shape == (len(pairs), d + 2)
        assert (pairs.killer[essential] == 0xFFFFFFFF).all()
        assert (pairs.killer[~essential] < len(family.points)).all()
        # Simplices are named by ascending input indices.
        assert (np.diff(pairs.creator.astype(np.int64), axis=1) > 0).all()
        assert (np.diff(pairs.killer[~essential].astype(np.int64), axis=1) > 0).all()
        intervals = diagram.intervals(d)
        assert intervals.shape == (len(pairs), 2) and intervals.dtype == np.float64
    # One essential component (a non-empty set), no essential hole (the hull fills in the end).
    assert (diagram.h0.death_rank < 0).sum() == (1 if len(family.points) else 0)
    assert (diagram.h1.death_rank < 0).sum() == 0


def expect_same_topology(network: galpha.NetworkClient, local: galpha.LocalClient, points: np.ndarray) -> None:
    net = network.build(points)
    loc = local.build(points)
    k = loc.spectrum_size
    assert net.spectrum_size == k
    betti = loc.betti()
    assert len(betti.components) == k + 1
    assert_same_betti(net.betti(), betti)
    middle = k // 2
    assert_same_betti(net.betti(middle, k), loc.betti(first_rank=middle))
    assert_same_betti(net.betti(middle, middle), loc.betti(middle, middle))
    diagram = loc.persistence()
    assert_same_diagram(net.persistence(), diagram)
    expect_consistent(loc, diagram, betti)
    # Filters: by dimension, by persistence (in alpha_sq), as the server's.
    h1_only = loc.persistence(dimensions=1)
    assert len(h1_only.h0) == 0
    assert_same_diagram(h1_only, net.persistence(dimensions=[1]))
    assert_same_diagram(h1_only, galpha.PersistenceDiagram(h0=h1_only.h0, h1=diagram.h1))
    assert_same_diagram(loc.persistence(dimensions=(1, 0, 1)), diagram)
    finite = np.concatenate([diagram.h0.persistence, diagram.h1.persistence])
    finite = finite[np.isfinite(finite)]
    cut = float(np.median(finite)) if len(finite) else 1.0
    long_lived = loc.persistence(min_persistence=cut)
    assert_same_diagram(net.persistence((0, 1), min_persistence=cut), long_lived)
    for d in (0, 1):
        keep = diagram[d].persistence >= cut
        np.testing.assert_array_equal(long_lived[d].birth_rank, diagram[d].birth_rank[keep])
        np.testing.assert_array_equal(long_lived[d].creator, diagram[d].creator[keep])
    # Holes in the classification's summary: b1 of the complex in its mode.
    for rank in sorted({0, 1 if k else 0, k // 3, middle, k}):
        for mode, curve in (("general", betti.holes), ("regularized", betti.regularized_holes)):
            got = loc.classify(rank=rank, mode=mode, summary_only=True)
            assert got.holes == curve[rank], (rank, mode)
            assert net.classify(rank=rank, mode=mode, summary_only=True).holes == got.holes
        assert loc.classify(rank=rank).components == betti.components[rank]
    # Optimal with and without a bound on holes.
    for components in (1, 2, 5):
        for holes in (None, 0, 1, 3):
            got = loc.optimal(components=components, holes=holes)
            assert net.optimal(components=components, holes=holes) == got, (components, holes)
            if got.general is not None:
                rank = got.general.rank
                assert got.general.components == betti.components[rank] <= components
                assert got.general.holes == betti.holes[rank]
                ok = betti.components <= components
                if holes is not None:
                    assert got.general.holes <= holes
                    ok &= betti.holes <= holes
                assert rank == int(np.argmax(ok)), (components, holes)
            else:
                ok = betti.components <= components
                if holes is not None:
                    ok &= betti.holes <= holes
                assert not ok.any()
            if got.regularized is not None:
                assert got.regularized.holes == betti.regularized_holes[got.regularized.rank]
                assert holes is None or got.regularized.holes <= holes


@pytest.fixture(scope="module", params=DATA_SETS, ids=lambda p: p.stem)
def data_set(request: pytest.FixtureRequest) -> pathlib.Path:
    return request.param


def test_both_clients_agree_on_every_data_set(clients, data_set: pathlib.Path) -> None:
    expect_same_topology(*clients, read_bin(data_set))


@pytest.mark.parametrize("name", list(SMALL_SETS))
def test_both_clients_agree_on_small_sets(clients, name: str) -> None:
    expect_same_topology(*clients, SMALL_SETS[name])


def test_square_with_center_by_hand(any_client) -> None:
    # Spectrum: 0.125 (the center edges), 0.25 (the sides and the four triangles). At rank 1 the
    # center joins everything (b0 1) and no loop closes; at rank 2 the sides close four loops that
    # the four triangles fill at the same rank: b1 stays 0, and no H1 pair is listed.
    family = any_client.build(SMALL_SETS["square_with_center"])
    betti = family.betti()
    assert betti.first_level == 0
    np.testing.assert_array_equal(betti.components, [5, 1, 1])
    np.testing.assert_array_equal(betti.holes, [0, 0, 0])
    np.testing.assert_array_equal(betti.regularized_components, [0, 0, 1])
    np.testing.assert_array_equal(betti.regularized_holes, [0, 0, 0])
    d = family.persistence()
    np.testing.assert_array_equal(d.h0.birth_rank, [0, 0, 0, 0, 0])
    np.testing.assert_array_equal(d.h0.death_rank, [1, 1, 1, 1, -1])
    np.testing.assert_array_equal(d.intervals(0)[-1], [0.0, math.inf])
    # Every class dies at the center edges: the killers are edges through vertex 4.
    assert (d.h0.killer[:4] == 4).any(axis=1).all()
    assert len(d.h1) == 0 and d.intervals(1).shape == (0, 2)
    assert family.optimal(components=1, holes=0).general == galpha.OptimalLevel(rank=1, alpha_sq=0.125, components=1, holes=0)


def test_ring_has_one_long_lived_hole(any_client) -> None:
    family = any_client.build(ring())
    d = family.persistence(dimensions=1)
    long_lived = (d.h1.death > 90) & (d.h1.birth < 1)
    assert long_lived.sum() == 1
    hole = int(np.flatnonzero(long_lived)[0])
    # Its killer is the last triangle over the empty disk: it enters at its squared circumradius,
    # about the disk's (10^2 .. 11^2).
    a, b, c = family.points[d.h1.killer[hole]]
    sides = [np.linalg.norm(b - c), np.linalg.norm(a - c), np.linalg.norm(a - b)]
    area2 = abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    circumradius_sq = (sides[0] * sides[1] * sides[2] / (2 * area2)) ** 2
    assert circumradius_sq == pytest.approx(d.h1.death[hole], rel=1e-9)
    assert 100 <= d.h1.death[hole] <= 121
    # Only that class survives a minimum persistence of 50 (alpha_sq units).
    long = family.persistence(min_persistence=50.0)
    assert len(long.h1) == 1 and long.h1.death[0] == d.h1.death[hole]
    assert len(long.h0) == 1 and long.h0.death_rank[0] == -1  # the one essential component
    # Betti: one hole of the general complex from birth to death.
    betti = family.betti()
    b, e = int(d.h1.birth_rank[hole]), int(d.h1.death_rank[hole])
    assert (betti.holes[b:e] >= 1).all()
    # Optimal with no holes allowed is past the ring's hole; with one it can stop earlier.
    no_holes = family.optimal(components=1, holes=0).general
    assert no_holes is not None and no_holes.rank >= e and no_holes.holes == 0
    one_hole = family.optimal(components=1, holes=1).general
    assert one_hole is not None and one_hole.rank < e and one_hole.holes <= 1


def test_asyncio_client_agrees(server) -> None:
    points = read_bin(REPO / "data" / "gps_tracks_slovenia_croatia.bin")
    local = galpha.local("cpu").build(points)

    async def main() -> None:
        async with galpha.aio.connect(server.address, timeout=120) as client:
            family = await client.build(points)
            assert_same_betti(await family.betti(), local.betti())
            assert_same_betti(await family.betti(3, 10), local.betti(3, 10))
            assert_same_diagram(await family.persistence(), local.persistence())
            assert_same_diagram(await family.persistence(1, min_persistence=1e-6), local.persistence(1, 1e-6))
            assert await family.optimal(2, holes=1) == local.optimal(2, holes=1)
            got = await family.classify(rank=local.spectrum_size // 2, mode="regularized", summary_only=True)
            assert got.holes == local.classify(rank=local.spectrum_size // 2, mode="regularized").holes
            with pytest.raises(galpha.InvalidInput, match="dimension 2"):
                await family.persistence(dimensions=(0, 2))
            with pytest.raises(galpha.InvalidInput, match="min_persistence"):
                await family.persistence(min_persistence=-1)
            with pytest.raises(galpha.InvalidInput, match="holes"):
                await family.optimal(1, holes=-1)
            with pytest.raises(galpha.InvalidInput, match="not within"):
                await family.betti(0, family.summary.spectrum_size + 1)

    asyncio.run(main())


# ---- Bad arguments ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda f: f.persistence(dimensions=2), "dimension 2 has no classes"),
        (lambda f: f.persistence(dimensions=(0, -1)), "dimension -1 has no classes"),
        (lambda f: f.persistence(dimensions=()), "dimensions is empty"),
        (lambda f: f.persistence(dimensions="0"), "a dimension must be an integer"),
        (lambda f: f.persistence(dimensions=None), "dimensions must be"),
        (lambda f: f.persistence(dimensions=[True]), "a dimension must be an integer"),
        (lambda f: f.persistence(min_persistence=-0.5), "min_persistence -0.5 is not a length"),
        (lambda f: f.persistence(min_persistence=float("nan")), "min_persistence nan is not a length"),
        (lambda f: f.persistence(min_persistence="big"), "min_persistence must be a number"),
        (lambda f: f.betti(-1), "not within"),
        (lambda f: f.betti(5, 2), "not within"),
        (lambda f: f.betti(0, 10**9), "not within"),
        (lambda f: f.betti(1.5), "first_rank must be an integer"),
        (lambda f: f.optimal(components=0), "components must be"),
        (lambda f: f.optimal(components=2**32), "components must be"),
        (lambda f: f.optimal(components=1, holes=-1), "holes must be"),
        (lambda f: f.optimal(components=1, holes=2**32), "holes must be"),
        (lambda f: f.optimal(components=1, holes=1.5), "holes must be"),
        (lambda f: f.optimal(components=1, holes=True), "holes must be"),
    ],
)
def test_bad_arguments_raise_invalid_input_on_both_clients(any_client, call, match: str) -> None:
    family = any_client.build(uniform(50, 3))
    with pytest.raises(galpha.InvalidInput, match=match):
        call(family)
    assert issubclass(galpha.InvalidInput, ValueError)


def test_backends_check_what_the_package_checks_with_the_same_messages(clients) -> None:
    """Past the package's own checks, the server and the engine module refuse the same arguments
    with the same codes and messages (the package could drift; the backends must not)."""
    network, local = clients
    points = uniform(50, 4)
    net, loc = network.build(points)._backend, local.build(points)._backend
    assert isinstance(net, _network.NetworkFamilyBackend) and isinstance(loc, _local.LocalFamilyBackend)
    k = loc.summary().spectrum_size
    for call in (
        lambda b: b.persistence((2,), 0.0),
        lambda b: b.persistence((0,), -1.0),
        lambda b: b.persistence((0, 1), float("nan")),
        lambda b: b.betti(0, k + 1),
        lambda b: b.optimal(0, None),
    ):
        messages = []
        for backend in (net, loc):
            with pytest.raises(galpha.InvalidInput) as caught:
                call(backend)
            messages.append(caught.value.message)
        assert messages[0] == messages[1]


def test_betti_pages_past_the_server_limit(clients, monkeypatch: pytest.MonkeyPatch) -> None:
    # The server answers at most 262144 ranks a call; the package pages (here in pages of 7).
    network, local = clients
    points = uniform(300, 7)
    expected = local.build(points).betti()
    family = network.build(points)
    monkeypatch.setattr(_network, "COMPONENTS_PAGE", 7)
    assert_same_betti(family.betti(), expected)
    assert_same_betti(family.betti(5, 40), local.build(points).betti(5, 40))


def test_released_family_raises_not_found_on_both_clients(any_client) -> None:
    family = any_client.build(uniform(30, 5))
    family.release()
    with pytest.raises(galpha.NotFound):
        family.persistence()
    with pytest.raises(galpha.NotFound):
        family.betti(0, 0)


def test_network_client_validates_before_calling(server, monkeypatch: pytest.MonkeyPatch) -> None:
    with galpha.connect(server.address, timeout=120) as client:
        family = client.build(uniform(40, 6))
        calls = family._backend._calls

        def refuse(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            raise AssertionError("an RPC was made for arguments the package refuses")

        monkeypatch.setattr(calls, "persistence", refuse)
        monkeypatch.setattr(calls, "betti", refuse)
        monkeypatch.setattr(calls, "optimal", refuse)
        for call in (
            lambda: family.persistence(dimensions=3),
            lambda: family.persistence(min_persistence=-1),
            lambda: family.betti(2, 1),
            lambda: family.optimal(components=1, holes=-2),
        ):
            with pytest.raises(galpha.InvalidInput):
                call()


# ---- GUDHI, an independent oracle ---------------------------------------------------------------

gudhi = pytest.importorskip("gudhi")

EPS = sys.float_info.epsilon


def close(a: float, b: float) -> bool:
    """Within eight ulps of each other (relative), or equal (infinities included)."""
    if a == b:
        return True
    if not (math.isfinite(a) and math.isfinite(b)):
        return False
    return abs(a - b) <= 8 * EPS * max(abs(a), abs(b))


def within_one_ulp(a: float, b: float) -> bool:
    return a == b or math.nextafter(a, b) == b


def match_within_ulps(ours: List[Interval], theirs: List[Interval]) -> Tuple[List[str], int]:
    """persistence_gudhi_test.cpp's MatchWithinUlps: every interval of one diagram has a partner in
    the other whose birth and death are both within 8 ulps (preferring one within an ulp), or lies
    within 8 ulps of the diagonal. GUDHI's exact mode converts its exact values to double without
    correct rounding and orders simplices by those doubles, so near-ties may pair differently by
    a few ulps (stability of persistence); ours are the exact values' nearest doubles. Returns the
    failures (at most 5) and how many matched within one ulp."""
    failures: List[str] = []
    # Equal intervals first (most of them), as a multiset; the rest by the tolerant scan.
    left = collections.Counter(theirs)
    rest: List[Interval] = []
    near = 0
    for interval in sorted(ours):
        if left[interval] > 0:
            left[interval] -= 1
            near += 1
        else:
            rest.append(interval)
    open_ = sorted((death, birth) for (birth, death), n in left.items() for _ in range(n))
    deaths = [d for d, _ in open_]
    used = [False] * len(open_)
    for birth, death in rest:
        start = bisect.bisect_left(deaths, death - 8 * EPS * death if math.isfinite(death) else death)
        best = -1
        for i in range(start, len(open_)):
            their_death, their_birth = open_[i]
            if not close(their_death, death):
                break
            if used[i] or not close(their_birth, birth):
                continue
            if best < 0 or (within_one_ulp(their_death, death) and within_one_ulp(their_birth, birth)):
                best = i
        if best >= 0:
            used[best] = True
            near += within_one_ulp(open_[best][0], death) and within_one_ulp(open_[best][1], birth)
        elif not close(birth, death) and len(failures) < 5:
            failures.append(f"ours ({birth!r}, {death!r}) has no partner in GUDHI's diagram")
    for i, (death, birth) in enumerate(open_):
        if not used[i] and not close(birth, death) and len(failures) < 5:
            failures.append(f"GUDHI's ({birth!r}, {death!r}) has no partner in ours")
    return failures, near


def gudhi_intervals(points: np.ndarray) -> List[List[Interval]]:
    complex_ = gudhi.AlphaComplex(points=points, precision="exact")
    tree = complex_.create_simplex_tree()
    tree.compute_persistence(homology_coeff_field=2, min_persistence=0)
    return [[(float(b), float(d)) for b, d in tree.persistence_intervals_in_dimension(dim)] for dim in (0, 1)]


def expect_same_as_gudhi(family: galpha.Family) -> None:
    diagram = family.persistence()
    theirs = gudhi_intervals(np.asarray(family.points))
    for d in (0, 1):
        intervals = diagram.intervals(d)
        ours = [(float(b), float(e)) for b, e in intervals[intervals[:, 1] > intervals[:, 0]]]
        failures, near = match_within_ulps(ours, theirs[d])
        assert not failures, f"H{d}: {failures}"
        assert near * 100 >= len(ours) * 99, f"H{d}: only {near} of {len(ours)} intervals within one ulp"


GUDHI_SETS = {
    "uniform_2000_seed_1": lambda: uniform(2000, 1),
    "uniform_2000_seed_2": lambda: uniform(2000, 2),
    "holed_grid": holed_grid,
    "ring": ring,
    "collinear": lambda: SMALL_SETS["collinear"],
    "pdb_2xhe_proj": lambda: read_bin(REPO / "data" / "pdb_2xhe_proj.bin"),
    "gps_tracks_slovenia_croatia": lambda: read_bin(REPO / "data" / "gps_tracks_slovenia_croatia.bin"),
    "ourairports_medium_large": lambda: read_bin(REPO / "data" / "ourairports_medium_large.bin"),
}


@pytest.mark.parametrize("name", list(GUDHI_SETS))
def test_diagram_matches_gudhi(name: str) -> None:
    with galpha.local("cpu") as client:
        expect_same_as_gudhi(client.build(GUDHI_SETS[name]()))


def test_ring_hole_in_gudhi_too() -> None:
    # The oracle sees the same one long-lived hole, so the ring test above is not tautological.
    h1 = gudhi_intervals(ring())[1]
    assert sum(1 for b, d in h1 if d > 90 and b < 1) == 1


def test_matcher_catches_a_wrong_diagram() -> None:
    # The matcher is not vacuous: a pair moved by more than 8 ulps, or a missing pair, fails.
    ours = [(0.0, 1.0), (0.5, 2.0), (0.0, math.inf)]
    assert match_within_ulps(ours, list(ours)) == ([], 3)
    assert match_within_ulps(ours, [(0.0, 1.0), (0.5, math.nextafter(2.0, 3.0)), (0.0, math.inf)])[0] == []
    moved = [(0.0, 1.0), (0.5, 2.0 + 1e-12), (0.0, math.inf)]
    assert match_within_ulps(ours, moved)[0]
    assert match_within_ulps(ours, ours[:2])[0]
    # Near-diagonal intervals may be missing on either side.
    assert match_within_ulps(ours + [(3.0, math.nextafter(3.0, 4.0))], ours)[0] == []
