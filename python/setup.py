"""Builds the clpt package: plain Python (ctypes) plus libclpt.so, bundled beside it.

The library comes from the repository this folder sits in (`make lib`, run here), or
from CLPT_LIBRARY (a built libclpt.so.*), e.g. for a package built outside the
repository. See README.md.
"""
import os
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def built_library():
    given = os.environ.get("CLPT_LIBRARY")
    if given:
        return given
    if not os.path.exists(os.path.join(REPO, "include", "clpt", "clpt.h")):
        raise SystemExit("clpt: not inside the clpt repository; set CLPT_LIBRARY to a built libclpt.so")
    jobs = str(os.cpu_count() or 2)
    subprocess.check_call(["make", "-C", REPO, "-j" + jobs, "lib"])
    return os.path.join(REPO, "build", "libclpt.so")


class BuildWithLibrary(build_py):
    """The Python files, and the C library copied into the package."""

    def run(self):
        super().run()
        dest = os.path.join(self.build_lib, "clpt", "libclpt.so")
        shutil.copyfile(os.path.realpath(built_library()), dest)


class BinaryDistribution(Distribution):
    """The wheel holds a compiled library: tag it for this platform."""

    def has_ext_modules(self):
        return True


def version():
    """The one version of clpt: the repository's VERSION file (CLPT_VERSION outside it)."""
    path = os.path.join(REPO, "VERSION")
    if os.path.exists(path):
        with open(path) as f:
            return f.read().strip()
    return os.environ.get("CLPT_VERSION", "0.0.0")


setup(version=version(), cmdclass={"build_py": BuildWithLibrary}, distclass=BinaryDistribution)
