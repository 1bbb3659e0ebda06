"""Point files from Python (galpha.read_points): every format alphactl reads, with the CRS the
file states, built as alphactl builds them (its spectrum is the oracle), and GDAL's own writer
(GeoPandas) for a GeoPackage with a CRS."""

from __future__ import annotations

import json
import pathlib
import subprocess

import geopandas
import numpy as np
import pytest

import galpha
from galpha import InvalidInput

PDB = (
    "ATOM      1  N   ALA A   1       0.000   0.000   0.000  1.00  0.00           N\n"
    "ATOM      2  CA  ALA A   1       4.000   0.000   1.000  1.00  0.00           C\n"
    "ATOM      3  C   ALA A   1       4.000   3.000   2.000  1.00  0.00           C\n"
    "ATOM      4  O   ALA A   1       0.000   3.000   3.000  1.00  0.00           O\n"
    "END\n"
)


def alphactl_spectrum(alphactl: str, path: pathlib.Path, *options: str) -> np.ndarray:
    text = subprocess.run([alphactl, "spectrum", str(path), *options, "--backend=cpu"], check=True, capture_output=True, text=True).stdout
    return np.array([float(v) for v in text.split()])


def test_geojson_is_wgs84_and_builds_as_alphactl(tmp_path: pathlib.Path, alphactl: str) -> None:
    rng = np.random.default_rng(3)
    lonlat = np.column_stack([rng.uniform(14.0, 14.2, 300), rng.uniform(46.0, 46.1, 300)])
    path = tmp_path / "points.geojson"
    path.write_text(json.dumps({"type": "MultiPoint", "coordinates": lonlat.tolist()}))
    read = galpha.read_points(path)
    assert read.crs == "OGC:CRS84"
    np.testing.assert_array_equal(read.points, lonlat)
    with galpha.local("cpu") as client:
        family = client.build(read)
        assert family.crs == "OGC:CRS84" and family.projection is not None
        np.testing.assert_array_equal(family.spectrum(), alphactl_spectrum(alphactl, path))


def test_geopackage_with_its_crs(tmp_path: pathlib.Path) -> None:
    rng = np.random.default_rng(4)
    xy = np.column_stack([rng.uniform(500000, 501000, 200), rng.uniform(5000000, 5001000, 200)])
    path = tmp_path / "points.gpkg"
    geopandas.GeoDataFrame(geometry=geopandas.points_from_xy(xy[:, 0], xy[:, 1]), crs="EPSG:32633").to_file(path, layer="wells")
    read = galpha.read_points(path, layer="wells")
    assert read.crs == "EPSG:32633"
    np.testing.assert_array_equal(read.points, xy)
    with galpha.local("cpu") as client:
        assert client.build(read).projection is None  # projected: computed as given
    with pytest.raises(InvalidInput, match="no layer 'nope'|nope"):
        galpha.read_points(path, layer="nope")


def test_structures_and_text(tmp_path: pathlib.Path) -> None:
    pdb = tmp_path / "atoms.pdb"
    pdb.write_text(PDB)
    np.testing.assert_array_equal(galpha.read_points(pdb).points, [[0, 0], [4, 0], [4, 3], [0, 3]])
    np.testing.assert_array_equal(galpha.read_points(pdb, plane="zx").points, [[0, 0], [1, 4], [2, 4], [3, 0]])
    assert len(galpha.read_points(pdb, slab="0:1").points) == 2
    assert galpha.read_points(pdb).crs is None
    # Each atom's element radius (N 1.55, C 1.70, O 1.52: the decimals, not gemmi's floats widened).
    np.testing.assert_array_equal(galpha.read_points(pdb).radii, [1.55, 1.70, 1.70, 1.52])
    np.testing.assert_array_equal(galpha.read_points(pdb, slab="0:1").radii, [1.55, 1.70])
    csv = tmp_path / "points.csv"
    csv.write_text("x,y\n0.1,0.2\n1e-3,5\n")
    text = galpha.read_points(csv)
    np.testing.assert_array_equal(text.points, [[0.1, 0.2], [1e-3, 5.0]])
    assert text.crs is None and text.radii is None
    with pytest.raises(InvalidInput, match="plane and slab apply to PDB"):
        galpha.read_points(csv, plane="xy")
    with pytest.raises(InvalidInput, match="layer applies to"):
        galpha.read_points(csv, layer="a")
    with pytest.raises(galpha.NotFound):
        galpha.read_points(tmp_path / "missing.csv")
    with pytest.raises(galpha.ResourceExhausted):
        galpha.read_points(pdb, max_points=3)


def test_alphactl_group_by_a_geopackage_field(tmp_path: pathlib.Path, alphactl: str) -> None:
    """One hull per region of a lon/lat GeoPackage (GDAL-written), each as the Python package
    builds that region's points alone (its own local projection): the GIS user's whole path."""
    rng = np.random.default_rng(5)
    centres = {"north": (14.5, 46.5), "south": (15.5, 45.5), "east": (16.5, 46.0)}
    frames = []
    for name, centre in centres.items():
        xy = rng.normal(centre, 0.05, (150, 2))
        frames.append(geopandas.GeoDataFrame({"region": [name] * len(xy)}, geometry=geopandas.points_from_xy(xy[:, 0], xy[:, 1]), crs="EPSG:4326"))
    table = geopandas.GeoDataFrame(np.concatenate([f.values for f in frames]), columns=frames[0].columns, crs="EPSG:4326")
    path = tmp_path / "regions.gpkg"
    table.to_file(path, layer="points")
    text = subprocess.run(
        [alphactl, "shape", str(path), "--group-by", "region", "--ratio", "0.8", "--format", "geojson", "--backend=cpu"],
        check=True, capture_output=True, text=True,
    ).stdout
    hulls = geopandas.GeoDataFrame.from_features(json.loads(text)["features"], crs="EPSG:4326")
    assert list(hulls["group"]) == list(centres)
    with galpha.local("cpu") as client:
        for frame, (_, row) in zip(frames, hulls.iterrows()):
            family = client.build(frame)
            expected = family.shape(ratio=0.8)
            assert row.geometry.is_valid
            assert row.geometry.equals(expected)
            assert row["area"] == pytest.approx(family.shape_rings(ratio=0.8).area, rel=1e-12)
    # The Python path to the same hulls: one call on the GeoDataFrame.
    with galpha.local("cpu") as client:
        by_region = galpha.shapes_by_group(client, table, "region", ratio=0.8)
    assert by_region.crs == table.crs
    assert list(by_region["group"]) == list(centres) and list(by_region["points"]) == [150, 150, 150]
    assert all(a.equals(b) for a, b in zip(by_region.geometry, hulls.geometry))
    assert list(by_region["area"]) == pytest.approx(list(hulls["area"]), rel=1e-12)
    # RFC 7946 GeoJSON from it is GeoPandas' own (already WGS84 here).
    assert json.loads(by_region.to_json())["features"][0]["geometry"]["type"] == "MultiPolygon"
    with pytest.raises(InvalidInput, match="names no column"):
        galpha.shapes_by_group(client, table, "nope", ratio=0.8)
    missing = subprocess.run(
        [alphactl, "shape", str(path), "--group-by", "nope", "--ratio", "0.8", "--format", "wkt"], capture_output=True, text=True
    )
    assert missing.returncode == 1 and "has no field 'nope'" in missing.stderr
