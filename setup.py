"""Builds the gssm package's C++ part with CMake for pip (`pip install
--no-build-isolation .`, `pip wheel --no-build-isolation .`): the modules
gssm._gssm and gssm._plot and the libgssm*.so they load, all in the package
folder (their RPATH is $ORIGIN). Metadata is in pyproject.toml.

GSSM_CMAKE_BUILD_DIR: build in (or reuse) this CMake build folder instead of
a fresh one (scripts/test reuses its own build). CMAKE_BUILD_PARALLEL_LEVEL:
build jobs (default 2).
"""
import os
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
SETUPTOOLS_BUILD = os.path.join(ROOT, "build-pip")  # not CMake's build/
os.makedirs(SETUPTOOLS_BUILD, exist_ok=True)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


def copy_package(src, dst):
    """The installed wheel folder into the package: a library's versioned
    file under its SONAME (the symlink's name), without the symlink."""
    os.makedirs(dst, exist_ok=True)
    targets = {os.path.realpath(os.path.join(src, f)) for f in os.listdir(src) if os.path.islink(os.path.join(src, f))}
    for name in os.listdir(src):
        path = os.path.join(src, name)
        if not os.path.islink(path) and os.path.realpath(path) in targets:
            continue  # libgssm.so.0.1.0: copied as libgssm.so.0.1
        shutil.copyfile(os.path.realpath(path), os.path.join(dst, name))


class CMakeBuild(build_ext):
    def run(self):
        build = os.environ.get("GSSM_CMAKE_BUILD_DIR") or os.path.join(os.path.abspath(self.build_temp), "cmake")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DGSSM_BUILD_TESTS=OFF", "-DGSSM_BUILD_BENCH=OFF",
                                   "-DPython_EXECUTABLE=" + sys.executable])
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        targets = ["_gssm"]
        if os.path.isdir(os.path.join(build, "gui-offscreen")):
            targets.append("_plot")  # figures: built where MRPT's image library is
        subprocess.check_call(["cmake", "--build", build, "-j", jobs, "--target"] + targets)
        staging = os.path.join(os.path.abspath(self.build_temp), "wheel-staging")
        shutil.rmtree(staging, ignore_errors=True)
        subprocess.check_call(["cmake", "--install", build, "--component", "wheel", "--prefix", staging])
        copy_package(os.path.join(staging, "wheel", "gssm"), os.path.join(os.path.abspath(self.build_lib), "gssm"))


setup(
    packages=["gssm"],
    package_dir={"gssm": "python/gssm"},
    package_data={"gssm": ["*.pyi", "py.typed"]},
    exclude_package_data={"gssm": ["*.pyi.in"]},
    ext_modules=[CMakeExtension("gssm._gssm")],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": SETUPTOOLS_BUILD}, "egg_info": {"egg_base": SETUPTOOLS_BUILD}},
)
