"""Build and install ngfracture.

The C++ kernels in cpp_ext/ are compiled with CMake against the ngsolve that is
installed in the build environment, using NGSolve's own CMake config (the flags of
the add-on template).  The C++ ABI ties the extension to that exact ngsolve, so the
package pins ``ngsolve==<the version it was built against>``.
"""
import os
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, find_packages, setup
from setuptools.command.build_ext import build_ext

import ngsolve  # the build requirements (pyproject.toml) provide it
import ngsolve.config

HERE = Path(__file__).resolve().parent
NGSOLVE_VERSION = ngsolve.__version__


class CMakeExtension(Extension):
    def __init__(self, name, source_dir):
        super().__init__(name, sources=[])
        self.source_dir = str(source_dir)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target_dir = Path(self.get_ext_fullpath(ext.name)).resolve().parent
        build_dir = Path(self.build_temp).resolve() / ext.name
        build_dir.mkdir(parents=True, exist_ok=True)
        configure = [
            "cmake", ext.source_dir,
            f"-DNGSolve_DIR={ngsolve.config.get_cmake_dir()}",
            f"-DCMAKE_LIBRARY_OUTPUT_DIRECTORY={target_dir}",
            f"-DPython3_EXECUTABLE={sys.executable}",
            "-DCMAKE_BUILD_TYPE=Release",
        ]
        subprocess.check_call(configure, cwd=build_dir)
        jobs = str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", ".", "-j", jobs], cwd=build_dir)


setup(
    name="ngfracture",
    version="0.1.0",
    description="Brittle fracture and fragmentation by node splitting, an NGSolve plugin",
    long_description=(HERE / "README.md").read_text(encoding="utf-8"),
    long_description_content_type="text/markdown",
    packages=find_packages(include=["ngfracture", "ngfracture.*"]),
    ext_modules=[CMakeExtension("ngfracture._ngfracture", HERE / "cpp_ext")],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.10",
    install_requires=[
        f"ngsolve=={NGSOLVE_VERSION}",
        f"netgen-mesher=={NGSOLVE_VERSION}",
        "numpy",
        "scipy",
        "pyvista",
        "matplotlib",
        "pillow",          # final.png: a raster of the triangles (already a dependency of matplotlib)
        "threadpoolctl",   # one BLAS thread for the small dense solves (see README)
        # 3D problems too large to factorise: smoothed-aggregation AMG with the rigid-body
        # modes as near-null space, what elasticity needs (docs/solvers.md)
        "pyamg",
        # ensembles of runs (ngfracture.ensemble): a maintained distributed engine with a
        # LocalCluster, rescheduling of the tasks of a dead worker, and cluster deployments
        # (dask-jobqueue, SSH, Kubernetes) instead of a home-made one
        "dask[distributed]",
    ],
    # nbclient + nbformat + ipykernel: the smallest set that executes the tutorial
    # notebooks headless (tests/test_tutorials.py); no Jupyter server or UI
    extras_require={"test": ["pytest", "nbclient", "nbformat", "ipykernel"]},
    entry_points={"console_scripts": ["ngfracture=ngfracture.__main__:main"]},
    zip_safe=False,
)
