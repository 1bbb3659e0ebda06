"""Fixtures for the galpha package's tests: the build tree's compiled parts on sys.path, a real
galpha_server on loopback, alphactl, and the repository's data sets."""

from __future__ import annotations

import os
import pathlib
import re
import signal
import subprocess
import sys
import time
from typing import Iterator, List

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def _build_dir() -> pathlib.Path:
    """GALPHA_BUILD_DIR, else the first CMake build tree that has the server and the stubs."""
    env = os.environ.get("GALPHA_BUILD_DIR")
    if env:
        return pathlib.Path(env).resolve()
    for preset in ("cuda", "cpu"):
        candidate = REPO / "build" / preset
        if (candidate / "python" / "galpha" / "v1" / "alpha_shapes_pb2.py").exists():
            return candidate
    raise RuntimeError("no build tree with the Python parts: configure with -DGALPHA_BUILD_PYTHON=ON and build")


# OpenMP threads that spin while they wait make every engine call slow when another process (the
# test server, alphactl) holds a core: on 2 cores a 5-point build took 1.3 s instead of 3 ms. Set
# before the engine module (and the processes started here) load libgomp.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

BUILD = _build_dir()
for path in (str(REPO / "python" / "src"), str(BUILD / "python")):
    if path not in sys.path:
        sys.path.insert(0, path)

import galpha  # noqa: E402


def read_bin(path: pathlib.Path) -> np.ndarray:
    """A data/*.bin file: little-endian uint64 N, then N float64 (x, y) pairs."""
    raw = path.read_bytes()
    n = int(np.frombuffer(raw[:8], dtype="<u8")[0])
    return np.frombuffer(raw[8:], dtype="<f8").reshape(n, 2).copy()


DATA_SETS: List[pathlib.Path] = sorted((REPO / "data").glob("*.bin"))


@pytest.fixture(scope="session")
def alphactl() -> str:
    return str(BUILD / "client" / "alphactl")


class Server:
    """galpha_server as a child process on free loopback ports."""

    def __init__(self, flags: List[str]) -> None:
        binary = BUILD / "server" / "galpha_server"
        self.process = subprocess.Popen(
            [str(binary), "--listen=127.0.0.1:0", "--metrics_listen=127.0.0.1:0", "--backend=cpu", *flags],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.port = self.metrics_port = 0
        deadline = time.monotonic() + 20
        assert self.process.stdout is not None
        while time.monotonic() < deadline and not (self.port and self.metrics_port):
            line = self.process.stdout.readline()
            if not line:
                break
            if m := re.search(r"listening on port (\d+)", line):
                self.port = int(m.group(1))
            if m := re.search(r"metrics on port (\d+)", line):
                self.metrics_port = int(m.group(1))
        if not self.port:
            self.stop()
            raise RuntimeError("galpha_server did not start")

    @property
    def address(self) -> str:
        return f"127.0.0.1:{self.port}"

    def metrics(self) -> str:
        import urllib.request

        with urllib.request.urlopen(f"http://127.0.0.1:{self.metrics_port}/metrics", timeout=10) as r:
            return r.read().decode()

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGKILL)
            self.process.wait(timeout=10)


@pytest.fixture(scope="session")
def server() -> Iterator[Server]:
    s = Server([])
    yield s
    s.stop()


@pytest.fixture
def start_server() -> Iterator:
    """Starts servers with extra flags; stops them after the test."""
    started: List[Server] = []

    def start(*flags: str) -> Server:
        s = Server(list(flags))
        started.append(s)
        return s

    yield start
    for s in started:
        s.stop()


@pytest.fixture
def client(server: Server) -> Iterator[galpha.NetworkClient]:
    with galpha.connect(server.address, timeout=120) as c:
        yield c


@pytest.fixture(params=["network", "local"])
def any_client(request: pytest.FixtureRequest, server: Server) -> Iterator:
    """Each test that takes it runs on both clients: the same calls must give the same answers."""
    if request.param == "network":
        with galpha.connect(server.address, timeout=120) as c:
            yield c
    else:
        with galpha.local("cpu") as c:
            yield c
