#!/usr/bin/env python3
"""A real data set end to end: the Autzen LiDAR ground points (data/lidar_autzen_ground.bin, feet,
Oregon GIC Lambert) into galpha, the concave hull at the smallest alpha that keeps every point
on one solid piece, and a PNG of the shape over the points.

    python3 python/examples/shape_of_lidar.py [--server HOST:PORT] [--out build/autzen_shape.png]

Without --server the engine runs in this process (galpha.local(); CUDA when there is a GPU).
Run from a checkout after building with -DGALPHA_BUILD_PYTHON=ON, or after pip-installing the
package (python/README.md).
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[2]


def import_galpha():
    """galpha from the environment, else from this checkout and its CMake build tree."""
    try:
        import galpha  # noqa: F401
    except ImportError:
        sys.path.insert(0, str(REPO / "python" / "src"))
        for preset in ("cuda", "cpu"):
            sys.path.insert(0, str(REPO / "build" / preset / "python"))
    import galpha

    return galpha


def read_bin(path: pathlib.Path) -> np.ndarray:
    raw = path.read_bytes()
    n = int(np.frombuffer(raw[:8], dtype="<u8")[0])
    return np.frombuffer(raw[8:], dtype="<f8").reshape(n, 2)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", help="HOST:PORT of a galpha_server (default: the engine in this process)")
    parser.add_argument("--data", default=str(REPO / "data" / "lidar_autzen_ground.bin"))
    parser.add_argument("--out", default=str(REPO / "build" / "autzen_shape.png"))
    args = parser.parse_args()

    galpha = import_galpha()
    import geopandas
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    points = read_bin(pathlib.Path(args.data))
    frame = geopandas.GeoDataFrame(geometry=geopandas.points_from_xy(points[:, 0], points[:, 1]), crs="EPSG:2994")

    client = galpha.connect(args.server) if args.server else galpha.local()
    with client, client.build(frame, progress=True) as family:
        summary = family.summary
        optimal = family.optimal(components=1).regularized
        if optimal is None:
            print("no alpha makes one solid piece of these points", file=sys.stderr)
            return 1
        shape = family.shape(rank=optimal.rank, as_geodataframe=True)
        print(
            f"{summary.points:,} points ({summary.duplicates} duplicates) on {summary.backend}: "
            f"{summary.triangles:,} triangles, {summary.spectrum_size:,} distinct alphas; "
            f"one solid piece from alpha = {optimal.alpha_sq ** 0.5:.3f} ft (rank {optimal.rank}): "
            f"{len(shape)} polygon(s), {sum(len(p.interiors) for p in shape.geometry)} hole(s), "
            f"area {shape['area'].sum():,.0f} sq ft"
        )
        figure, axes = plt.subplots(figsize=(9, 9), dpi=110)
        shape.plot(ax=axes, facecolor="#9ecae1", edgecolor="#08519c", linewidth=0.6)
        axes.scatter(points[:, 0], points[:, 1], s=0.2, color="#252525")
        axes.set_title(f"Autzen ground points and their alpha shape (alpha = {optimal.alpha_sq ** 0.5:.2f} ft)")
        axes.set_aspect("equal")
        out = pathlib.Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(out, bbox_inches="tight")
        print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
