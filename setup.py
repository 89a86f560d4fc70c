"""Build the one C extension, granular._core, from csrc/.

Portable flags only: -O3 and C99; no -march=native or -ffast-math (the collision
arithmetic relies on IEEE rounding being the same on every machine)."""

import glob
import os

import numpy
from setuptools import Extension, setup

extra = ["-O3", "-g", "-std=c99", "-pthread", "-Wall", "-Wextra", "-Wno-unused-parameter"]
if os.environ.get("GRANULAR_ASAN"):
    extra += ["-fsanitize=address", "-fno-omit-frame-pointer", "-O1", "-g"]

setup(
    ext_modules=[
        Extension(
            "granular._core",
            sources=sorted(glob.glob("csrc/*.c")),
            include_dirs=[numpy.get_include(), "csrc"],
            define_macros=[("NPY_NO_DEPRECATED_API", "NPY_2_0_API_VERSION")],
            extra_compile_args=extra,
            # POSIX threads for the Langevin engine (csrc/sde.c); in glibc >= 2.34 they are in
            # libc itself, and -pthread is harmless there
            extra_link_args=["-pthread"]
            + (["-fsanitize=address"] if os.environ.get("GRANULAR_ASAN") else []),
            depends=sorted(glob.glob("csrc/*.h")),
        )
    ]
)
