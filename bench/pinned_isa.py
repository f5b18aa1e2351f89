"""One x86-64 code path for the numbers that must repeat from machine to machine: the stored
reference of the sample campaign (tests/reference/regenerate.py) and the validation records
whose figures count verdicts at a threshold (a benchmark module with ``ON_PINNED_ISA =
True``, run by ``python -m bench`` in a child process on this instruction set).

NumPy's AVX-512 kernels, OpenBLAS' per-CPU kernels, Numba's host target and OpenCV's AVX-512
kernels otherwise round the last bits differently from machine to machine; an optimiser
that stops a few ulps elsewhere can move a stable window by one sample (seen: 6 of the 60
sample runs between an AVX-512 machine and an AVX2 one), and a verdict near its 0.9 bar
can turn (docs/validation/gap-apart.md, "The same campaigns on two instruction sets").
"""

from __future__ import annotations

import os
import platform
from collections.abc import Mapping

#: NumPy's AVX-512 dispatch targets off (names as NumPy 2.4 knows them), OpenBLAS' Haswell
#: kernels on one thread, Numba for Haswell, OpenCV without AVX-512 (its AVX512_SKX kernels
#: need AVX512F; on a machine without it OpenCV says on stderr that there is nothing to
#: disable): one code path on every x86-64 machine with AVX2
PINNED_ISA = {"NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",
              "OPENBLAS_CORETYPE": "Haswell", "OPENBLAS_NUM_THREADS": "1",
              "NUMBA_CPU_NAME": "haswell", "OPENCV_CPU_DISABLE": "AVX512F"}
#: set in a pinned child's environment, so that it does not pin itself again
MARKER = "SWTLAB_PINNED_ISA"


def pinned_env(environ: Mapping[str, str] = os.environ) -> dict[str, str]:
    """``environ`` with :data:`PINNED_ISA` on x86-64 (nothing of it elsewhere: its names are
    x86 ones, and the stored figures are x86-64 ones) and :data:`MARKER`."""
    on_x86 = platform.machine() in ("x86_64", "AMD64")
    return {**environ, **(PINNED_ISA if on_x86 else {}), MARKER: "1"}


def is_pinned(environ: Mapping[str, str] = os.environ) -> bool:
    """Whether this process was started by :func:`pinned_env`'s environment."""
    return environ.get(MARKER) == "1"
