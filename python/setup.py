"""pip's build of the galpha package: the pure-Python sources, the gRPC stubs generated from the
repository's proto/ with protoc and grpc_python_plugin (never edited by hand), and the engine
extension galpha._engine built by the project's CMake (GALPHA_BUILD_PYTHON=ON).

    python3 -m pip install --no-build-isolation ./python

Environment: GALPHA_CMAKE_BUILD_DIR (default: build/pip in the repository) is the CMake build
tree, reused between installs; GALPHA_CMAKE_ARGS adds configure arguments (e.g.
-DGALPHA_WITH_CUDA=ON); GALPHA_ENGINE=off installs the network client only (no compiler needed
beyond protoc: for client machines that only talk to a galpha_server).
"""

from __future__ import annotations

import os
import pathlib
import shlex
import shutil
import subprocess

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parent
PROTO = REPO / "proto"


def _engine_wanted() -> bool:
    value = os.environ.get("GALPHA_ENGINE", "on").lower()
    if value not in ("on", "off"):
        raise SystemExit(f"GALPHA_ENGINE must be 'on' or 'off', got {value!r}")
    return value == "on"


class BuildPyWithStubs(build_py):
    """Generates galpha/v1/alpha_shapes_pb2{,_grpc}.py into the build tree."""

    def run(self) -> None:
        super().run()
        plugin = shutil.which("grpc_python_plugin")
        protoc = shutil.which("protoc")
        if plugin is None or protoc is None:
            raise SystemExit("protoc and grpc_python_plugin are needed: apt-get install protobuf-compiler-grpc")
        subprocess.run(
            [
                protoc,
                f"--proto_path={PROTO}",
                f"--python_out={self.build_lib}",
                f"--grpc_python_out={self.build_lib}",
                f"--plugin=protoc-gen-grpc_python={plugin}",
                "galpha/v1/alpha_shapes.proto",
            ],
            check=True,
        )


class BuildEngineWithCMake(build_ext):
    """Builds the _engine target with the project's CMake and copies the module into the package."""

    def run(self) -> None:
        if not _engine_wanted():
            return
        build_dir = pathlib.Path(os.environ.get("GALPHA_CMAKE_BUILD_DIR", REPO / "build" / "pip")).resolve()
        configure = [
            "cmake",
            "-S",
            str(REPO),
            "-B",
            str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DGALPHA_BUILD_PYTHON=ON",
            *shlex.split(os.environ.get("GALPHA_CMAKE_ARGS", "")),
        ]
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "_engine", "-j", str(os.cpu_count() or 1)], check=True)
        built = sorted((build_dir / "python" / "galpha").glob("_engine*.so"))
        if not built:
            raise SystemExit(f"the CMake build produced no galpha/_engine*.so under {build_dir / 'python'}")
        for ext in self.extensions:
            target = pathlib.Path(self.get_ext_fullpath(ext.name))
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(built[-1], target)


setup(
    ext_modules=[Extension("galpha._engine", sources=[])] if _engine_wanted() else [],
    cmdclass={"build_py": BuildPyWithStubs, "build_ext": BuildEngineWithCMake},
)
