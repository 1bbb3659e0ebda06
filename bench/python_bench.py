#!/usr/bin/env python3
"""The Python package's overhead, measured against the C++ tools in the same run (not a test):

  * network: NumPy points to a usable family on a galpha_server, galpha.connect().build() vs the
    C++ client (alphactl --server ... bench: the same Build call, after a Release each time);
  * in process: galpha.local().build() vs the engine's own time for the same build in alphactl
    bench (the sum of its stage times, best of --repeat);
  * classify at one alpha: NumPy arrays per second, both clients (the network one in every
    answer encoding: raw, delta, zstd; the compact two also through the NumPy decoder that
    installs without the compiled module use);
  * the shape at that alpha and at a fifth of it (a fragmented shape: many small polygons,
    singular edges and isolated points) as shapely geometry (mode general), local: Family.shape() (one GEOS call through WKB) vs the same geometry built from
    Family.shape_rings() with shapely's constructors, one object a member (what Family.shape did
    before, and what a caller of shape_rings would write).

    /usr/bin/python3 bench/python_bench.py [--points 1000000] [--repeat 3] [--backend cpu]
        [--build-dir build/cpu] [--server HOST:PORT] [--encoding auto|raw]

Both network clients upload in the same --encoding (default auto: each chunk's smallest lossless
form; uniform doubles compress only to ~13.3 bytes a point, so on loopback raw can be faster).

Without --server it starts build-dir's galpha_server on a free loopback port (same backend).
Prints one table and the ratios (Python / C++).
"""

from __future__ import annotations

import argparse
import pathlib
import re
import subprocess
import threading
import sys
import tempfile
import time

import numpy as np

REPO = pathlib.Path(__file__).resolve().parents[1]


def alphactl_bench(alphactl: str, file: str, repeat: int, extra: list) -> dict:
    out = subprocess.run([alphactl, *extra, "bench", file, f"--repeat={repeat}"], check=True, capture_output=True, text=True)
    rows = {}
    for line in out.stdout.splitlines():
        if m := re.match(r"^(\w+)\s+([-\d.e+]+)$", line.strip()):
            rows[m.group(1)] = float(m.group(2))
    return rows


def classify_rate(family, alpha: float) -> tuple:
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        c = family.classify(alpha=alpha)
        best = min(best, time.perf_counter() - start)
    size = sum(a.nbytes for a in (c.vertices, c.vertex_classes, c.edges, c.edge_classes, c.triangles, c.triangle_classes))
    return best, size / best / 1e9


def shapely_constructors(rings, points):
    """The general shape from rings, member by member (the competitor of Family.shape): the same
    parts, each present when not empty."""
    from shapely.geometry import GeometryCollection, MultiLineString, MultiPoint, MultiPolygon, Polygon

    parts = []
    if rings.polygons:
        parts.append(MultiPolygon([Polygon(points[p.outer], [points[h] for h in p.holes]) for p in rings.polygons]))
    if len(rings.singular_edges):
        parts.append(MultiLineString([points[e] for e in rings.singular_edges]))
    if len(rings.isolated_points):
        parts.append(MultiPoint(points[rings.isolated_points]))
    return GeometryCollection(parts)


def shape_times(family, points, alpha: float, repeat: int) -> tuple:
    """Best wall times (s) of Family.shape() and of shape_rings() plus shapely's constructors (both
    compute the rings), after checking that both make the same geometry."""
    ours = theirs = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        mine = family.shape(alpha=alpha, mode="general")
        ours = min(ours, time.perf_counter() - start)
        start = time.perf_counter()
        other = shapely_constructors(family.shape_rings(alpha=alpha, mode="general"), points)
        theirs = min(theirs, time.perf_counter() - start)
    if mine.wkb != other.wkb:
        raise RuntimeError(f"Family.shape and shapely's constructors disagree at alpha {alpha!r}")
    return ours, theirs


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--backend", default="cpu", choices=["auto", "cpu", "cuda"])
    parser.add_argument("--build-dir", default=str(REPO / "build" / "cpu"))
    parser.add_argument("--server", help="an already running galpha_server (default: start one)")
    parser.add_argument("--encoding", default="auto", choices=["auto", "raw"], help="how both network clients upload")
    args = parser.parse_args()
    build = pathlib.Path(args.build_dir).resolve()
    sys.path[:0] = [str(REPO / "python" / "src"), str(build / "python")]
    import galpha

    alphactl = str(build / "client" / "alphactl")
    points = np.random.default_rng(2024).random((args.points, 2))
    alpha = float(np.sqrt(3.0 / args.points))  # a few neighbours' distance: a mixed classification
    with tempfile.TemporaryDirectory() as tmp:
        file = str(pathlib.Path(tmp) / "uniform.bin")
        with open(file, "wb") as f:
            f.write(np.uint64(args.points).tobytes())
            f.write(points.astype("<f8").tobytes())

        # In process. The two alternate, so that a machine's load drifts over both alike.
        client = galpha.local(args.backend)
        cpp_local = float("inf")
        py_wall, py_engine = float("inf"), float("inf")
        for _ in range(args.repeat):
            cpp_local = min(cpp_local, alphactl_bench(alphactl, file, 1, [f"--backend={args.backend}"])["total"])
            start = time.perf_counter()
            family = client.build(points)
            py_wall = min(py_wall, time.perf_counter() - start)
            py_engine = min(py_engine, sum(family.summary.stage_times.values()))
        local_classify = classify_rate(family, alpha)
        shapes = {label: shape_times(family, points, a, args.repeat) for label, a in (("alpha", alpha), ("alpha/5", alpha / 5))}

        # Over the network.
        server_process = None
        target = args.server
        if target is None:
            server_process = subprocess.Popen(
                [str(build / "server" / "galpha_server"), "--listen=127.0.0.1:0", "--metrics_listen=", f"--backend={args.backend}"],
                stdout=subprocess.PIPE,
                text=True,
            )
            line = server_process.stdout.readline()
            target = "127.0.0.1:" + re.search(r"listening on port (\d+)", line).group(1)
        try:
            net = galpha.connect(target, timeout=600)
            handle = galpha.point_set_handle(points)
            cpp_rpc = cpp_overhead = net_wall = net_overhead = float("inf")
            for _ in range(args.repeat):
                rows = alphactl_bench(alphactl, file, 1, [f"--server={target}", f"--encoding={args.encoding}"])  # releases the handle first
                cpp_rpc = min(cpp_rpc, rows["rpc_total"])
                cpp_overhead = min(cpp_overhead, rows["rpc_total"] - rows["total"])
                try:
                    net.family(handle, points).release()
                except galpha.NotFound:
                    pass
                start = time.perf_counter()
                remote = net.build(points, encoding=args.encoding)
                wall = time.perf_counter() - start
                upload_bytes = remote.summary.upload_bytes
                net_wall = min(net_wall, wall)
                net_overhead = min(net_overhead, wall - sum(remote.summary.stage_times.values()))
            # Classify in every answer encoding (connect's answer_encoding), the same family.
            # The compact ones twice: decoded by the compiled module (what the package does) and by
            # the NumPy decoder installs without it fall back to (the reader switched off).
            net_classify = {}
            for answer_encoding, decoder in (("raw", ""), ("delta", ""), ("zstd", ""), ("delta", "numpy"), ("zstd", "numpy")):
                native_reader = galpha._wire.native_section_reader
                if decoder == "numpy":
                    galpha._wire.native_section_reader = lambda: None
                galpha._network._decode_thread = threading.local()  # the pool threads take new readers
                try:
                    with galpha.connect(target, timeout=600, answer_encoding=answer_encoding) as by_encoding:
                        label = answer_encoding + (f" ({decoder} decoder)" if decoder else "")
                        net_classify[label] = classify_rate(by_encoding.family(handle, points), alpha)
                finally:
                    galpha._wire.native_section_reader = native_reader
                    galpha._network._decode_thread = threading.local()
            remote.release()
            net.close()
        finally:
            if server_process is not None:
                server_process.terminate()
                server_process.wait(timeout=60)

    ms = lambda s: f"{s * 1e3:10.1f}"  # noqa: E731
    print(f"# {args.points:,} uniform points, backend {args.backend}, best of {args.repeat} (the two alternate)")
    print(f"{'measure':52}{'ms':>10}")
    print(f"{'in process: alphactl bench, engine stages':52}{cpp_local:10.1f}")
    print(f"{'in process: galpha.local().build(), wall':52}{ms(py_wall)}")
    print(f"{'in process: galpha.local().build(), engine stages':52}{ms(py_engine)}")
    print(f"{'network: C++ client Build (alphactl bench), wall':52}{cpp_rpc:10.1f}")
    print(f"{'network: C++ client, wall minus server stages':52}{cpp_overhead:10.1f}")
    print(f"{'network: galpha.connect().build(), wall':52}{ms(net_wall)}")
    print(f"{'network: galpha.connect().build(), minus stages':52}{ms(net_overhead)}")
    print(f"{'network: Python upload, bytes a point (' + args.encoding + ')':52}{upload_bytes / args.points:10.2f}")
    print(f"{'classify, local: ms / GB/s':52}{ms(local_classify[0])}  {local_classify[1]:.2f} GB/s")
    for answer_encoding, (seconds, rate) in net_classify.items():
        label = f"classify, network, {answer_encoding}: ms / GB/s"
        print(f"{label:52}{ms(seconds)}  {rate:.2f} GB/s")
    for label, (ours, constructors) in shapes.items():
        print(f"{'shape at ' + label + ', local: Family.shape(), general':52}{ms(ours)}")
        print(f"{'shape at ' + label + ', local: shapely constructors':52}{ms(constructors)}")
        print(f"ratio shape at {label} (constructors / Family.shape): {constructors / ours:.1f}")
    print(f"ratio local (Python wall / C++ engine stages): {py_wall * 1e3 / cpp_local:.3f}  (target <= 1.05)")
    print(f"ratio network (Python / C++ client, wall):     {net_wall * 1e3 / cpp_rpc:.3f}  (target <= 1.10)")
    print(f"client overhead beyond the server's stages: Python {net_overhead * 1e3:.1f} ms, C++ {cpp_overhead:.1f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
