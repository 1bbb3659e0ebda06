"""pip installs the package from the repository into a fresh venv (Debian's interpreter, its
packages visible), stubs generated and the engine built by CMake (here: the test's own build
tree, so nothing is compiled twice), and the installed package works from another directory."""

from __future__ import annotations

import os
import subprocess

import textwrap

from conftest import BUILD, REPO

SMOKE = textwrap.dedent(
    """
    import galpha, numpy, sys
    assert "site-packages" in galpha.__file__, galpha.__file__
    from galpha.v1 import alpha_shapes_pb2
    family = galpha.local("cpu").build(numpy.array([[0, 0], [2, 0], [2, 2], [0, 2], [1, 1.0]]))
    assert family.spectrum().tolist() == [0.5, 1.0], family.spectrum()
    print(family.handle)
    """
)


def test_pip_install_from_the_repository(tmp_path) -> None:
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True)
    env = dict(os.environ, GALPHA_CMAKE_BUILD_DIR=str(BUILD))
    env.pop("PYTHONPATH", None)
    subprocess.run(
        [str(venv / "bin" / "pip"), "install", "--no-build-isolation", "--no-deps", "--quiet", str(REPO / "python")],
        check=True,
        env=env,
        cwd=tmp_path,
    )
    out = subprocess.run(
        [str(venv / "bin" / "python"), "-c", SMOKE], check=True, capture_output=True, text=True, env=env, cwd=tmp_path
    )
    assert out.stdout.startswith("sha256-")
