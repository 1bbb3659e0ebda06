"""galpha._engine (the embedded engine's extension, python/engine/) and its adapter galpha._local,
against oracles that do not come from the engine: answers worked out by hand for small point sets,
Euler's formula, the handle rebuilt with hashlib from its documented construction, the master list
against the class changes it must explain, and tracemalloc for the copies the build must not make."""

from __future__ import annotations

import hashlib
import signal
import struct
import threading
import time
import tracemalloc
from typing import Dict, List, Set, Tuple

import numpy as np
import pytest

import galpha
from galpha import _engine, _local
from galpha._types import Mode, Threshold, VertexRule

EXTERIOR, SINGULAR, REGULAR, INTERIOR = 1, 2, 3, 4
RHO, MU_LOW, MU_HIGH = 1, 2, 3

# A unit square with its center: the four center edges enter at (sqrt(2)/2 / 2)^2... that is,
# half of the center edge (length sqrt(1/2)) squared: 1/8; the four right isosceles triangles and
# the sides (their hypotenuses, the center exactly on their diametral circles) at (1/2)^2 = 1/4.
SQUARE = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], dtype=np.float64)
# An obtuse triangle: edge 0-2 (length^2 2) enters at 2/4, edge 1-2 (length^2 10) at 10/4; edge
# 0-1 has point 2 inside its diametral circle (attached), so it enters with the triangle, whose
# circumcenter is (2, -1): circumradius^2 5.
OBTUSE = np.array([[0, 0], [4, 0], [1, 1]], dtype=np.float64)


def build(points: np.ndarray, **kwargs) -> "_engine.Family":
    return _engine.build(np.ascontiguousarray(points, dtype=np.float64), "cpu", **kwargs)


def random_points(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).random((n, 2))


def documented_handle(points: np.ndarray) -> str:
    """BuildResponse.handle's construction (proto/galpha/v1/alpha_shapes.proto), in hashlib."""
    data = np.ascontiguousarray(points, dtype="<f8").tobytes()
    leaves = [data[i : i + (1 << 20)] for i in range(0, len(data), 1 << 20)]
    root = hashlib.sha256(b"galpha.v2.points\0" + struct.pack("<Q", len(data)))
    for leaf in leaves:
        root.update(hashlib.sha256(b"\0" + leaf).digest())
    return "sha256-" + root.hexdigest()


# ---- Answers known by hand ------------------------------------------------------------------------


def test_square_with_center_by_hand() -> None:
    family = build(SQUARE)
    np.testing.assert_array_equal(family.spectrum(), [0.125, 0.25])
    s = family.summary()
    assert (s["points"], s["distinct_points"], s["duplicates"]) == (5, 5, 0)
    assert (s["triangles"], s["edges"], s["spectrum_size"], s["backend"]) == (4, 8, 2, "cpu")
    assert set(s["comparisons"]) == {"filter", "device_exact", "cpu_fallback"}
    assert s["family_bytes"] > 0 and all(t >= 0 for t in s["stage_times"].values())

    edges = [[0, 1], [0, 3], [0, 4], [1, 2], [1, 4], [2, 3], [2, 4], [3, 4]]
    triangles = [[0, 1, 4], [0, 3, 4], [1, 2, 4], [2, 3, 4]]
    side = {(0, 1), (0, 3), (1, 2), (2, 3)}
    expected_edges = {
        0: [EXTERIOR] * 8,
        1: [EXTERIOR if tuple(e) in side else SINGULAR for e in edges],
        2: [REGULAR if tuple(e) in side else INTERIOR for e in edges],
    }
    # A vertex is singular alone, regular on the boundary of what is in, interior inside it.
    expected_vertices = {0: [SINGULAR] * 5, 1: [REGULAR] * 5, 2: [REGULAR] * 4 + [INTERIOR]}
    for rank in (0, 1, 2):
        c = family.classify("rank", rank)
        assert c["level"] == rank and c["alpha_sq"] == [0.0, 0.125, 0.25][rank]
        np.testing.assert_array_equal(c["vertices"], np.arange(5))
        np.testing.assert_array_equal(c["edges"], edges)
        np.testing.assert_array_equal(c["triangles"], triangles)
        assert c["vertices"].dtype == np.uint32 and c["edges"].dtype == np.uint32 and c["edge_classes"].dtype == np.uint8
        np.testing.assert_array_equal(c["vertex_classes"], expected_vertices[rank])
        np.testing.assert_array_equal(c["edge_classes"], expected_edges[rank])
        np.testing.assert_array_equal(c["triangle_classes"], [INTERIOR if rank == 2 else EXTERIOR] * 4)
        assert c["components"] == [5, 1, 1][rank] and c["solid_components"] == [0, 0, 1][rank]
        assert c["interior_area"] == [0.0, 0.0, 1.0][rank]
    # Regularized: the center edges never bound or fill a triangle before rank 2.
    c = family.classify("rank", 1, mode="regularized")
    np.testing.assert_array_equal(c["edge_classes"], [EXTERIOR] * 8)
    shape = family.shape_rings("rank", 2)
    assert len(shape["polygons"]) == 1 and shape["area"] == 1.0
    outer, holes = shape["polygons"][0]
    np.testing.assert_array_equal(outer, [0, 1, 2, 3])
    assert holes == []
    comps = family.components(0, 2)
    np.testing.assert_array_equal(comps["components"], [5, 1, 1])
    np.testing.assert_array_equal(comps["solid_components"], [0, 0, 1])
    # (rank, alpha_sq, components, holes): no hole ever (the center edges come before the sides).
    assert family.optimal(1) == {"regularized": (2, 0.25, 1, 0), "general": (1, 0.125, 1, 0)}
    assert family.optimal(1, max_holes=0) == family.optimal(1)
    betti = family.betti(0, 2)
    np.testing.assert_array_equal(betti["holes"], [0, 0, 0])
    np.testing.assert_array_equal(betti["regularized_components"], [0, 0, 1])


def test_obtuse_triangle_by_hand() -> None:
    family = build(OBTUSE)
    np.testing.assert_array_equal(family.spectrum(), [0.5, 2.5, 5.0])
    assert [family.rank_lower_bound(a) for a in (0.0, 0.5, 2.4, 2.5, 2.6, 5.0, 6.0)] == [1, 1, 2, 2, 3, 3, 4]
    # Thresholds of each kind resolve to levels: values <= the threshold, compared exactly.
    assert family.classify("alpha_sq", 2.5)["level"] == 2
    assert family.classify("alpha_sq", np.nextafter(2.5, 0))["level"] == 1
    assert family.classify("alpha", 0.75)["level"] == 1  # 0.5625
    assert family.classify("alpha", 0.75)["alpha_sq"] == 0.5625
    assert family.classify("alpha_sq", -1.0)["level"] == -1
    np.testing.assert_array_equal(family.classify("alpha_sq", -1.0)["vertex_classes"], [EXTERIOR] * 3)

    edges = [[0, 1], [0, 2], [1, 2]]
    for rank, edge_classes, vertex_classes in (
        (1, [EXTERIOR, SINGULAR, EXTERIOR], [REGULAR, SINGULAR, REGULAR]),
        (2, [EXTERIOR, SINGULAR, SINGULAR], [REGULAR, REGULAR, REGULAR]),
        (3, [REGULAR, REGULAR, REGULAR], [REGULAR, REGULAR, REGULAR]),
    ):
        c = family.classify("rank", rank)
        np.testing.assert_array_equal(c["edges"], edges)
        np.testing.assert_array_equal(c["edge_classes"], edge_classes)
        np.testing.assert_array_equal(c["vertex_classes"], vertex_classes)
    shape = family.shape_rings("rank", 1)
    assert shape["polygons"] == [] and shape["area"] == 0.0
    np.testing.assert_array_equal(shape["singular_edges"], [[0, 2]])
    np.testing.assert_array_equal(shape["isolated_points"], [1])
    shape = family.shape_rings("rank", 2)
    np.testing.assert_array_equal(shape["singular_edges"], [[0, 2], [1, 2]])
    assert shape["singular_edges"].shape == (2, 2) and len(shape["isolated_points"]) == 0
    shape = family.shape_rings("alpha_sq", 5.0)
    np.testing.assert_array_equal(shape["polygons"][0][0], [0, 1, 2])  # counter-clockwise
    assert shape["area"] == 2.0 and shape["singular_edges"].shape == (0, 2)
    # Rank 3: the triangle enters (RHO); the attached edge 0-1 enters regular (MU_LOW) with it, as
    # do the two singular edges and every vertex.
    m = family.master_list(3)
    entries = set(zip(m["kinds"].tolist(), m["endpoints"].tolist()))
    assert (3, RHO) in entries and (2, MU_LOW) in entries and np.all(m["ranks"] == 3)


def test_lattice_with_a_hole() -> None:
    """A 10 x 10 lattice without its 4 x 4 middle: at alpha_sq = 1/2 (the unit squares' circumradius)
    one polygon, the 9 x 9 square with a hole: the 5 x 5 square [2, 7]^2 but for its corners, where
    a right isosceles triangle (legs 1, circumradius^2 1/2) of lattice points is in too. Euler:
    V - E + T = components - holes."""
    grid = [(x, y) for y in range(10) for x in range(10) if not (3 <= x <= 6 and 3 <= y <= 6)]
    family = build(np.array(grid, dtype=np.float64))
    shape = family.shape_rings("alpha_sq", 0.5)
    assert len(shape["polygons"]) == 1 and shape["area"] == 81.0 - 23.0
    outer, holes = shape["polygons"][0]
    assert len(outer) == 36 and len(holes) == 1 and len(holes[0]) == 16
    ring = np.array(grid)[outer]
    assert set(map(tuple, ring.tolist())) == {p for p in grid if min(p) == 0 or max(p) == 9}
    hole = np.array(grid)[holes[0]]
    corners = {(2, 2), (2, 7), (7, 2), (7, 7)}
    assert set(map(tuple, hole.tolist())) == {p for p in grid if 2 <= min(p) and max(p) <= 7} - corners
    signed_area = lambda r: 0.5 * np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1])  # noqa: E731
    assert signed_area(ring) == 81.0 and signed_area(hole) == -23.0  # outer ccw, hole cw
    c = family.classify("alpha_sq", 0.5, non_exterior_only=True)
    v, e, t = len(c["vertices"]), len(c["edges"]), len(c["triangles"])
    assert (v, e, t) == (84, 196 + 4, 112 + 4)
    assert v - e + t == c["components"] - len(holes) == 0
    assert c["solid_components"] == 1 and c["interior_area"] == 58.0


def test_duplicates_share_their_first_occurrence() -> None:
    points = np.vstack([OBTUSE, OBTUSE[1:2]])  # index 3 repeats index 1
    family = build(points)
    s = family.summary()
    assert (s["points"], s["distinct_points"], s["duplicates"]) == (4, 3, 1)
    c = family.classify("rank", 3)
    np.testing.assert_array_equal(c["vertices"], [0, 1, 2])
    assert sum(c["vertex_counts"]) == 3
    np.testing.assert_array_equal(family.spectrum(), [0.5, 2.5, 5.0])


# ---- Consistency on random points ----------------------------------------------------------------


def _changes(before: Dict, after: Dict) -> Dict[Tuple[int, Tuple[int, ...]], int]:
    """(kind, sorted vertices) -> new class, for every simplex whose class changed."""
    changed = {}
    for kind, simplices, classes in ((1, "vertices", "vertex_classes"), (2, "edges", "edge_classes"), (3, "triangles", "triangle_classes")):
        idx = np.nonzero(before[classes] != after[classes])[0]
        items = after[simplices][idx].reshape(len(idx), kind)
        for key, cls in zip(map(tuple, items.tolist()), after[classes][idx].tolist()):
            changed[(kind, key)] = cls
    return changed


def test_random_points_counts_monotone_classes_and_master_list() -> None:
    points = random_points(300, seed=5)
    family = build(points)
    s = family.summary()
    k = s["spectrum_size"]
    assert np.all(np.diff(family.spectrum()) > 0)
    full = family.classify("rank", k)
    # The whole Delaunay triangulation at rank K; its hull edges are the regular ones. Euler on the
    # triangulation of n points with h on the hull: T = 2n - 2 - h, E = 3n - 3 - h.
    n, h = len(points), full["edge_counts"][REGULAR - 1]
    assert full["triangle_counts"] == (0, 0, 0, 2 * n - 2 - h)
    assert (s["triangles"], s["edges"]) == (2 * n - 2 - h, 3 * n - 3 - h)
    curve = family.components(0, k)
    previous = family.classify("rank", 0)
    for rank in range(1, k + 1):
        c = family.classify("rank", rank)
        for name, total in (("vertex_counts", n), ("edge_counts", s["edges"]), ("triangle_counts", s["triangles"])):
            assert sum(c[name]) == total
        # A simplex's class never goes down as alpha grows.
        for classes in ("vertex_classes", "edge_classes", "triangle_classes"):
            assert np.all(c[classes] >= previous[classes])
        # The master list of a rank is exactly the class changes at that rank, each to the class
        # its last end point says.
        m = family.master_list(rank)
        listed: Dict[Tuple[int, Tuple[int, ...]], Set[int]] = {}
        offsets = np.concatenate([[0], np.cumsum(m["kinds"].astype(np.int64))])
        for i, (kind, endpoint) in enumerate(zip(m["kinds"].tolist(), m["endpoints"].tolist())):
            key = (kind, tuple(m["vertex_indices"][offsets[i] : offsets[i + 1]].tolist()))
            listed.setdefault(key, set()).add(endpoint)
        final = {RHO: SINGULAR, MU_LOW: REGULAR, MU_HIGH: INTERIOR}
        expected = {key: (INTERIOR if key[0] == 3 else final[max(ends)]) for key, ends in listed.items()}
        assert _changes(previous, c) == expected, f"rank {rank}"
        # Euler: V - E + T = components - independent cycles <= components.
        v, e, t = (sum(c[name][1:]) for name in ("vertex_counts", "edge_counts", "triangle_counts"))
        assert v - e + t <= c["components"] == curve["components"][rank]
        assert c["solid_components"] == curve["solid_components"][rank]
        previous = c
    # Optimal: the first rank whose component count is within the bound, in each sense.
    holes = family.betti(0, k)["holes"]
    for bound in (1, 3, 10):
        general = family.optimal(bound)["general"]
        first = int(np.argmax(curve["components"] <= bound))
        value = 0.0 if first == 0 else family.spectrum()[first - 1]
        assert general == (first, value, curve["components"][first], holes[first])
    # Filtering and summaries change the arrays, never the counts.
    rank = k // 3
    c = family.classify("rank", rank, mode="regularized", vertex_rule="cgal")
    kept = family.classify("rank", rank, mode="regularized", vertex_rule="cgal", non_exterior_only=True)
    for simplices, classes in (("vertices", "vertex_classes"), ("edges", "edge_classes"), ("triangles", "triangle_classes")):
        mask = c[classes] != EXTERIOR
        np.testing.assert_array_equal(kept[simplices], c[simplices][mask])
        np.testing.assert_array_equal(kept[classes], c[classes][mask])
        assert not np.any(c[classes] == SINGULAR)  # regularized
    only = family.classify("rank", rank, mode="regularized", vertex_rule="cgal", summary_only=True)
    assert only["edges"].shape == (0, 2) and only["triangles"].shape == (0, 3) and len(only["vertex_classes"]) == 0
    assert {key: only[key] for key in ("level", "edge_counts", "components")} == {
        key: c[key] for key in ("level", "edge_counts", "components")
    }
    # Spectrum pages are slices, clipped at K.
    np.testing.assert_array_equal(family.spectrum(5, 10), family.spectrum()[4:14])
    assert len(family.spectrum(k, 10)) == 1 and len(family.spectrum(k + 1, 10)) == 0


# ---- Handles ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [0, 1, 5, 65536, 150_001])
def test_handle_is_the_documented_hash_tree(n: int) -> None:
    points = random_points(n, seed=n) * 1e3 - 500
    expected = documented_handle(points)
    assert _engine.handle(points) == expected
    if n >= 3:
        assert build(points).handle == expected


# ---- Errors ----------------------------------------------------------------------------------------


def engine_error(call, *args, **kwargs) -> "_engine.EngineError":
    with pytest.raises(_engine.EngineError) as info:
        call(*args, **kwargs)
    assert isinstance(info.value.code, int) and isinstance(info.value.message, str)
    return info.value


def test_errors_carry_the_status_code_and_name_the_input() -> None:
    points = random_points(10, seed=1)
    points[7, 1] = np.nan
    e = engine_error(build, points)
    assert e.code == 3 and "point 7" in e.message
    points = random_points(10, seed=1)
    points[4, 0] = -(2.0**500)
    e = engine_error(build, points)
    assert e.code == 3 and "4" in e.message
    assert engine_error(build, np.zeros((4, 3))).code == 3
    assert engine_error(build, np.zeros(4)).code == 3
    assert engine_error(_engine.build, "no points").code == 3
    assert engine_error(_engine.build, [[0, 0], [1, 1], [2]]).code == 3
    assert engine_error(_engine.build, OBTUSE, "tpu").code == 3
    family = build(OBTUSE)
    # Ranks outside 0..K are INVALID_ARGUMENT, as the server answers them (proto: "rank out of range").
    e = engine_error(family.classify, "rank", 4)
    assert e.code == 3 and "outside 0..3" in e.message
    assert engine_error(family.classify, "rank", -1).code == 3
    assert engine_error(family.classify, "rank", 2**70).code == 3
    assert engine_error(family.classify, "rank", 1.5).code == 3
    assert engine_error(family.classify, "alpha_sq", float("nan")).code == 3
    assert engine_error(family.classify, "alpha", -1.0).code == 3
    assert engine_error(family.classify, "radius", 1.0).code == 3
    assert engine_error(family.classify, "rank", 1, mode="regularised").code == 3
    assert engine_error(family.classify, "rank", 1, vertex_rule="other").code == 3
    assert engine_error(family.shape_rings, "rank", 9).code == 3
    assert engine_error(family.master_list, 0).code == 3
    assert engine_error(family.master_list, 2, 1).code == 3
    assert engine_error(family.master_list, 1, 4).code == 3
    assert engine_error(family.spectrum, 0, 1).code == 3
    assert engine_error(family.spectrum, 5, 1).code == 3
    assert engine_error(family.components, 0, 4).code == 3
    assert engine_error(family.optimal, 0).code == 3
    assert engine_error(family.rank_lower_bound, float("nan")).code == 3
    if not _engine.cuda_available():
        assert engine_error(_engine.build, OBTUSE, "cuda").code == 14  # UNAVAILABLE
    assert family.release() is True and family.release() is False
    assert engine_error(family.summary).code == 5  # NOT_FOUND, as a released handle on a server
    assert engine_error(lambda: family.handle).code == 5


def test_local_backend_raises_galpha_exceptions() -> None:
    backend = _local.build_local(np.ascontiguousarray(OBTUSE), "cpu", None, name="tri")
    assert backend.summary().name == "tri" and backend.summary().cached is False
    assert backend.handle == documented_handle(OBTUSE)
    with pytest.raises(galpha.InvalidInput, match="outside 0..3"):
        backend.classify(Threshold("rank", 4), Mode.GENERAL, VertexRule.REPORT, False, False)
    with pytest.raises(galpha.InvalidInput, match="point 1"):
        _local.build_local(np.array([[0.0, 0.0], [np.inf, 1.0], [1.0, 1.0]]), "cpu", None)
    c = backend.classify(Threshold("alpha_sq", 2.5), Mode.GENERAL, VertexRule.REPORT, False, False)
    assert c.level == 2 and c.edge_counts == galpha.ClassCounts(1, 2, 0, 0)
    rings = backend.shape_rings(Threshold("rank", 3), Mode.REGULARIZED)
    np.testing.assert_array_equal(rings.polygons[0].outer, [0, 1, 2])
    assert backend.optimal(1).general == galpha.OptimalLevel(rank=2, alpha_sq=2.5, components=1)
    assert backend.master_list(1, 3).offsets[-1] == len(backend.master_list(1, 3).vertex_indices)
    assert backend.components(0, 3).components.tolist() == [3, 2, 1, 1]
    assert backend.release() is True
    with pytest.raises(galpha.NotFound):
        backend.spectrum(1, 1)


# ---- Copies, lifetimes, the GIL and interruption ----------------------------------------------------


def test_build_does_not_copy_a_float64_array_and_converts_others() -> None:
    points = random_points(200_000, seed=9)  # 3.2 MB
    tracemalloc.start()
    try:
        build_start = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        family = _engine.build(points, "cpu")
        copied = tracemalloc.get_traced_memory()[1] - build_start
        tracemalloc.reset_peak()
        _engine.build(points.astype(np.float32), "cpu")  # converted: NumPy makes the float64 copy
        converted = tracemalloc.get_traced_memory()[1] - build_start
    finally:
        tracemalloc.stop()
    assert copied < 100_000 <= 3_200_000 <= converted
    # Non-contiguous and Fortran-ordered views are converted to the same points.
    wide = np.zeros((len(points), 4))
    wide[:, 0], wide[:, 2] = points[:, 0], points[:, 1]
    for other in (wide[:, ::2], np.asfortranarray(points), points.tolist()[:1000]):
        assert _engine.handle(other) == _engine.handle(points[: len(other)])
    # The family keeps its own copy of the points: the input may change or go away.
    handle, spectrum = family.handle, family.spectrum().copy()
    points[:] = 0.0
    del points
    assert family.handle == handle
    np.testing.assert_array_equal(family.spectrum(), spectrum)


def test_shared_arrays_are_read_only_and_outlive_release() -> None:
    family = build(random_points(1000, seed=3))
    c = family.classify("rank", 100)
    spectrum = family.spectrum()
    assert not c["edges"].flags.writeable and not spectrum.flags.writeable
    assert c["edge_classes"].flags.writeable  # computed per call: the caller's
    edges = c["edges"].copy()
    family.release()
    np.testing.assert_array_equal(c["edges"], edges)
    assert spectrum[-1] > spectrum[0]


def test_the_gil_is_released_while_the_engine_builds() -> None:
    points = random_points(300_000, seed=11)
    ticks = [0]
    done = threading.Event()

    def count() -> None:
        while not done.is_set():
            ticks[0] += 1

    thread = threading.Thread(target=count)
    thread.start()
    try:
        before = ticks[0]
        _engine.build(points, "cpu")
        during = ticks[0] - before
    finally:
        done.set()
        thread.join()
    assert during > 10_000


def test_an_exception_in_progress_stops_the_build() -> None:
    class Stop(Exception):
        pass

    phases: List[str] = []

    def progress(phase: str, fraction: float) -> None:
        phases.append(phase)
        raise Stop(phase)

    with pytest.raises(Stop, match="triangulation"):
        _engine.build(random_points(1000, seed=2), "cpu", progress)
    assert phases == ["triangulation"]
    # Ctrl-C delivered while Python runs the callback: KeyboardInterrupt, the build stopped.
    phases.clear()

    def interrupt(phase: str, fraction: float) -> None:
        phases.append(phase)
        signal.raise_signal(signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        _engine.build(random_points(1000, seed=2), "cpu", interrupt)
    assert phases == ["triangulation"]


def test_ctrl_c_during_a_long_build_stops_it() -> None:
    """SIGINT while the engine runs (the GIL released) is seen at the engine's next check between
    phases. The progress callback is a builtin (dict.__setitem__), which runs no bytecode, so
    Python's handler can run only in the engine's check (PyErr_CheckSignals), not in the callback."""
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT is not Python's default handler here")
    points = random_points(1_000_000, seed=4)
    seen: Dict[str, float] = {}
    main = threading.main_thread().ident
    fired = []

    def interrupt() -> None:
        fired.append(time.monotonic())
        signal.pthread_kill(main, signal.SIGINT)

    timer = threading.Timer(0.1, interrupt)
    start = time.monotonic()
    timer.start()
    try:
        try:
            _engine.build(points, "cpu", seen.__setitem__)
        finally:
            end = time.monotonic()
            timer.join()
    except KeyboardInterrupt:
        if "components" in seen:  # the build ran to its end: fine only if the signal came late
            assert fired[0] - start > 0.5 * (end - start), f"SIGINT at {fired[0] - start:.2f} s went unseen"
            pytest.skip("the signal came during the build's last phase")
        assert "triangulation" in seen or "alpha" not in seen
    else:
        try:  # the build won the race: take the signal here and say so
            time.sleep(1)
        except KeyboardInterrupt:
            pass
        pytest.skip(f"the build finished in {end - start:.2f} s, before the signal")
    assert build(OBTUSE).summary()["spectrum_size"] == 3  # the interpreter and the engine go on


def test_local_build_batch_gives_each_set_the_family_it_gives_alone() -> None:
    # One packed engine build of sets of every kind (a grid's exact ties, a line, an empty set,
    # one point, a repeat); the oracle is each set built alone.
    rng = np.random.default_rng(41)
    sets = {
        "uniform": rng.random((700, 2)),
        "grid": np.array([[i, j] for i in range(20) for j in range(15)], dtype=np.float64),
        "line": np.column_stack([np.arange(40.0), np.zeros(40)]),
        "empty": np.empty((0, 2)),
        "one": np.array([[0.5, 0.25]]),
    }
    sets["again"] = sets["uniform"].copy()
    with galpha.local("cpu") as c:
        families = c.build_batch(sets)
        assert [f.summary.name for f in families] == list(sets)
        for (name, points), family in zip(sets.items(), families):
            alone = c.build(points)
            assert family.handle == alone.handle, name
            assert family.spectrum_size == alone.spectrum_size, name
            np.testing.assert_array_equal(family.spectrum(), alone.spectrum())
            assert family.summary.triangles == alone.summary.triangles, name
            for k in {0, family.spectrum_size // 2, family.spectrum_size}:
                got, want = family.classify(rank=k), alone.classify(rank=k)
                np.testing.assert_array_equal(got.triangles, want.triangles)
                np.testing.assert_array_equal(got.triangle_classes, want.triangle_classes)
                np.testing.assert_array_equal(got.edge_classes, want.edge_classes)
                assert (got.components, got.solid_components, got.interior_area) == (
                    want.components,
                    want.solid_components,
                    want.interior_area,
                ), name
        assert c.build_batch({}) == []
        with pytest.raises(galpha.InvalidInput, match="a mapping of name to points"):
            c.build_batch([sets["uniform"]])
        # A set the engine refuses: the packed build fails, the sets are built one by one, and the
        # error names its set (or takes its place).
        bad = sets["uniform"].copy()
        bad[3, 0] = np.nan
        with pytest.raises(galpha.InvalidInput, match="set 'bad': point 3 is not finite"):
            c.build_batch([("fine", sets["grid"]), ("bad", bad)])
        results = c.build_batch([("fine", sets["grid"]), ("bad", bad)], return_exceptions=True)
        assert isinstance(results[0], galpha.Family) and results[0].spectrum_size == families[1].spectrum_size
        assert isinstance(results[1], galpha.InvalidInput)
