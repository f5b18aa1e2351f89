"""The soil-flow kernels' threads follow the cores the process may run on (softflow.threads)."""

import os

import cv2
import numba
import numpy as np
import pytest
from scipy import ndimage

from softflow.flow_engine import pair_displacement_px
from softflow.threads import capped
from swtlab_base.cores import available_cores

pytestmark = pytest.mark.skipif(
    not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2
    or numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 cores and a settable affinity")


@pytest.fixture(autouse=True)
def _threads_restored():
    before = numba.get_num_threads(), cv2.getNumThreads()
    yield
    numba.set_num_threads(before[0])
    cv2.setNumThreads(before[1])


def test_threads_capped_to_the_affinity_and_restored():
    cores = os.sched_getaffinity(0)
    seen = {}

    @capped
    def probe():
        seen.update(cores=available_cores(), numba=numba.get_num_threads(),
                    opencv=cv2.getNumThreads())

    numba.set_num_threads(2)
    cv2.setNumThreads(2)
    os.sched_setaffinity(0, {min(cores)})
    try:
        probe()
    finally:
        os.sched_setaffinity(0, cores)
    assert seen == {"cores": 1, "numba": 1, "opencv": 1}
    assert (numba.get_num_threads(), cv2.getNumThreads()) == (2, 2)
    probe()  # two cores again: the caller's two threads are kept
    assert seen == {"cores": len(cores), "numba": 2, "opencv": 2}


def test_displacement_independent_of_the_thread_count():
    rng = np.random.default_rng(3)
    a = ndimage.gaussian_filter(rng.random((96, 96)), 1.5).astype(np.float32) * 200
    b = ndimage.shift(a, (0.4, 0.9), order=3, mode="nearest").astype(np.float32)
    numba.set_num_threads(2)
    two = pair_displacement_px(a, b)
    numba.set_num_threads(1)
    one = pair_displacement_px(a, b)
    np.testing.assert_array_equal(one, two)
    # and it is the shift: content moved +0.9 px in x, +0.4 px in y
    inner = np.s_[24:-24, 24:-24]
    assert np.median(one[inner][..., 0]) == pytest.approx(0.9, abs=0.05)
    assert np.median(one[inner][..., 1]) == pytest.approx(0.4, abs=0.05)
