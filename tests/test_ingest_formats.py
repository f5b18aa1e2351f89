"""Every format ingests a virtual-testbed run to the same canonical table as its MCAP form.

Each file is written by that format's own library (tests/format_writers.py) from the samples
of a committed sample-campaign MCAP; the reference is ``read_run`` of that MCAP.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import ingest
from ingest.formats import sniff
from tests import format_writers as fw

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / "L070_MP0_SC_s+010.mcap"


@pytest.fixture(scope="module")
def spec_run() -> fw.SpecRun:
    return fw.read_spec_mcap(SAMPLE)


@pytest.fixture(scope="module")
def reference():
    return ingest.read_run(SAMPLE)


def _assert_same_table(run, reference):
    got, want = run.channels, reference.channels
    assert list(got.columns) == list(want.columns)
    np.testing.assert_array_equal(got["t_s"].to_numpy(), want["t_s"].to_numpy())
    for column in want.columns[1:]:
        np.testing.assert_allclose(got[column].to_numpy(), want[column].to_numpy(),
                                   rtol=1e-9, atol=0, equal_nan=True, err_msg=column)
    for topic, frame in reference.streams.items():
        np.testing.assert_array_equal(run.streams[topic]["t_s"].to_numpy(),
                                      frame["t_s"].to_numpy(), err_msg=topic)
    # calibration is keyed by source field, which a ROS map names by message path
    assert replace(run.metadata, calibration={}) == replace(reference.metadata, calibration={})
    assert sorted(run.metadata.calibration.values()) == \
        sorted(reference.metadata.calibration.values())
    assert len(reference.metadata.calibration) > 0
    assert run.derivation["time_base"] == reference.derivation["time_base"]


CASES = {
    "hdf5": (lambda r, d: fw.write_hdf5(r, d / "run.h5"), None),
    "mat5": (lambda r, d: fw.write_mat5(r, d / "run.mat"), None),
    "mat73": (lambda r, d: fw.write_mat73(r, d / "run.mat"), None),
    "tdms": (lambda r, d: fw.write_tdms(r, d / "run.tdms"), None),
    "rosbag1": (lambda r, d: fw.write_ros1(r, d / "run.bag"), "spec_ros"),
    "rosbag2": (lambda r, d: fw.write_ros2(r, d / "bag2"), "spec_ros"),
    "mcap_cdr": (lambda r, d: fw.write_ros2(r, d / "bag3", storage="mcap") / "bag3.mcap",
                 "spec_ros"),
}


@pytest.mark.parametrize("fmt", list(CASES))
def test_format_round_trips_to_the_mcap_table(fmt, tmp_path, spec_run, reference):
    write, cmap = CASES[fmt]
    path = write(spec_run, tmp_path)
    if fmt == "mcap_cdr":  # the bare CDR MCAP file, with its sidecar, out of its bag folder
        bare = tmp_path / "cdr.mcap"
        path.rename(bare)
        (tmp_path / "bag3.run.json").rename(tmp_path / "cdr.run.json")
        path = bare
    assert sniff(path) == fmt
    _assert_same_table(ingest.read_run(path, cmap), reference)
