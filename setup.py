"""Build of the C library libswtwpm (libswtwpm/, docs/wpm-csv.md) into the package: one shared
object, wpm_export/_libswtwpm*.so, that Python loads with ctypes (wpm_export/clib.py) and the
FMU carries as its binary (wpm_export/fmu.py). Everything else is in pyproject.toml."""

from pathlib import Path

from setuptools import Extension, setup

SOURCES = sorted(str(p) for p in Path("libswtwpm").glob("*.c"))

setup(ext_modules=[Extension(
    "wpm_export._libswtwpm", sources=SOURCES, include_dirs=["libswtwpm"], libraries=["m"],
    depends=sorted(str(p) for p in Path("libswtwpm").glob("*.h")),
    # C99; no contraction into FMA, so the arithmetic is the one the Python runtime does
    extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off", "-fvisibility=default"],
)])
