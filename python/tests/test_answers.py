"""Both clients against alphactl (the C++ command line on the embedded engine, an independent
path from the Python code) on every data set in data/: the same spectrum bit for bit, the same
classes, master list, optimal ranks and counts; every shape valid and equal to alphactl's."""

from __future__ import annotations

import functools
import json
import pathlib
import subprocess
from typing import List

import numpy as np
import pytest
import shapely.wkt
from shapely.geometry import MultiPolygon
from conftest import DATA_SETS, read_bin

import galpha

CLASS_NAMES = {1: "EXTERIOR", 2: "SINGULAR", 3: "REGULAR", 4: "INTERIOR"}
ENDPOINT_NAMES = {1: "RHO", 2: "MU_LOW", 3: "MU_HIGH"}
KIND_LETTERS = {1: "v", 2: "e", 3: "t"}


@functools.lru_cache(maxsize=None)
def run(alphactl: str, *args: str) -> str:
    """alphactl's output (cached: the oracle's answers serve both clients)."""
    return subprocess.run([alphactl, *args, "--backend=cpu"], check=True, capture_output=True, text=True).stdout


def ranks_of(k: int) -> List[int]:
    return sorted({0, 1, max(1, k // 7), max(1, k // 2), k})


def classify_text(c: galpha.Classification) -> str:
    lines = [f"v {i} {CLASS_NAMES[int(k)]}" for i, k in zip(c.vertices.tolist(), c.vertex_classes.tolist())]
    lines += [f"e {a} {b} {CLASS_NAMES[int(k)]}" for (a, b), k in zip(c.edges.tolist(), c.edge_classes.tolist())]
    lines += [
        f"t {a} {b} {d} {CLASS_NAMES[int(k)]}" for (a, b, d), k in zip(c.triangles.tolist(), c.triangle_classes.tolist())
    ]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module", params=DATA_SETS, ids=lambda p: p.stem)
def data_set(request: pytest.FixtureRequest) -> pathlib.Path:
    return request.param


def test_spectrum_and_classes_match_alphactl(any_client, alphactl: str, data_set: pathlib.Path) -> None:
    points = read_bin(data_set)
    family = any_client.build(points)
    expected_spectrum = np.array([float(v) for v in run(alphactl, "spectrum", str(data_set)).split()])
    spectrum = family.spectrum()
    assert spectrum.dtype == np.float64
    np.testing.assert_array_equal(spectrum, expected_spectrum)
    assert family.summary.spectrum_size == len(expected_spectrum)
    assert family.summary.points == len(points)
    k = family.spectrum_size
    for rank in ranks_of(k)[1:4]:
        for mode in ("general", "regularized"):
            got = family.classify(rank=rank, mode=mode, vertex_rule="report")
            assert classify_text(got) == run(alphactl, "classify", str(data_set), f"--rank={rank}", f"--mode={mode}")
    # The other threshold kinds resolve as alphactl resolves them.
    alpha_sq = float(spectrum[k // 3])
    got = family.classify(alpha_sq=alpha_sq, vertex_rule="cgal")
    assert classify_text(got) == run(alphactl, "classify", str(data_set), f"--alpha-sq={alpha_sq!r}", "--vertex-rule=cgal")
    radius = float(np.sqrt(spectrum[k // 4]))
    got = family.classify(alpha=radius)
    assert classify_text(got) == run(alphactl, "classify", str(data_set), f"--alpha={radius!r}")
    # The summary's counts agree with alphactl summary.
    summary = json.loads(run(alphactl, "summary", str(data_set), f"--rank={k // 2}"))
    got = family.classify(rank=k // 2, summary_only=True)
    assert len(got.edges) == 0 and len(got.vertices) == 0
    assert got.level == summary["level"]
    assert got.components == summary["components"]
    assert got.triangle_counts.interior == summary["triangles"]["INTERIOR"]
    assert got.edge_counts.singular == summary["edges"]["SINGULAR"]


def test_master_list_and_optimal_match_alphactl(any_client, alphactl: str, data_set: pathlib.Path) -> None:
    family = any_client.build(read_bin(data_set))
    k = family.spectrum_size
    for rank in ranks_of(k)[1:]:
        entries = family.master_list(rank)
        offsets = entries.offsets
        lines = []
        for i in range(len(entries.kinds)):
            indices = " ".join(str(v) for v in entries.vertex_indices[offsets[i] : offsets[i + 1]].tolist())
            lines.append(f"{KIND_LETTERS[int(entries.kinds[i])]} {indices} {ENDPOINT_NAMES[int(entries.endpoints[i])]}")
        assert set(entries.ranks.tolist()) <= {rank}
        assert "\n".join(lines) + "\n" == run(alphactl, "masterlist", str(data_set), f"--rank={rank}")
    for n in (1, 3):
        expected = json.loads(run(alphactl, "optimal", str(data_set), f"--components={n}"))
        got = family.optimal(components=n)
        for sense in ("regularized", "general"):
            level = getattr(got, sense)
            if expected.get(sense) is None:
                assert level is None
            else:
                assert level.rank == expected[sense]["rank"]
                key = "solid_components" if sense == "regularized" else "components"
                assert level.components == expected[sense][key]
    curve = family.components()
    assert len(curve.components) == k + 1
    assert curve.components[0] == family.summary.distinct_points


def parts_by_type(geometry) -> dict:
    """{"MultiPolygon": ..., "MultiLineString": ..., "MultiPoint": ...} of a shape's geometry.
    alphactl's WKT writes one polygon as a POLYGON: here it is a MultiPolygon of one, as the
    package's shapes hold it."""
    members = geometry.geoms if geometry.geom_type == "GeometryCollection" else [geometry]
    members = [MultiPolygon([g]) if g.geom_type == "Polygon" else g for g in members]
    return {g.geom_type: g for g in members if not g.is_empty}


def alphactl_wkt_type(geometry) -> str:
    """The WKT type alphactl must write for the package's shape: POLYGON or MULTIPOLYGON for
    polygons alone (MULTIPOLYGON EMPTY for none), a GEOMETRYCOLLECTION only with singular edges or
    isolated points."""
    parts = parts_by_type(geometry)
    if parts.keys() - {"MultiPolygon"}:
        return "GeometryCollection"
    polygons = parts.get("MultiPolygon")
    return "Polygon" if polygons is not None and len(polygons.geoms) == 1 else "MultiPolygon"


def test_every_shape_is_valid_and_equals_alphactl(any_client, alphactl: str, data_set: pathlib.Path) -> None:
    family = any_client.build(read_bin(data_set))
    for rank in ranks_of(family.spectrum_size):
        for mode in ("regularized", "general"):
            geometry = family.shape(rank=rank, mode=mode)
            assert geometry.is_valid, f"rank {rank} {mode}"
            assert geometry.geom_type == ("MultiPolygon" if mode == "regularized" else "GeometryCollection")
            rings = family.shape_rings(rank=rank, mode=mode)
            got = parts_by_type(geometry)
            polygons = got.get("MultiPolygon")
            assert (0.0 if polygons is None else polygons.area) == pytest.approx(rings.area, rel=1e-9)
            args = ("shape", str(data_set), f"--rank={rank}", f"--mode={mode}", "--format=wkt")
            wkt = shapely.wkt.loads(run(alphactl, *args))
            assert wkt.geom_type == alphactl_wkt_type(geometry), f"rank {rank} {mode}"
            expected = parts_by_type(wkt)
            assert got.keys() == expected.keys(), f"rank {rank} {mode}"
            for kind, part in got.items():
                # Exactly the same vertices in the same canonical order (the input doubles): the same
                # well-known binary, byte for byte (one GEOS call, where comparing member by
                # member took most of this test's time on the 110K-point data set).
                assert part.wkb == expected[kind].wkb, f"rank {rank} {mode} {kind}"
