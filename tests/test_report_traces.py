"""The report's time series come from traces stored at processing: min/max decimation checked
by hand and against the raw channels read independently, a page rendered after the raw files
are gone, a placeholder for runs processed before traces were stored, and a page rendered
straight from in-memory results without a database."""

from __future__ import annotations

import math
import re
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from sqlalchemy import delete, select

import ingest
from campaign_report import from_results, gather, render_report, write_report
from run_results import process_run
from run_results.traces import MAX_TRACE_POINTS, TRACE_QUANTITIES, decimate_minmax
from test_report_campaign import NO_STABLE_RUN, SAMPLE, build_small_campaign
from traceability import open_database
from traceability.models import RawFile, Run, RunResult, RunTrace
from traceability.store_traces import unpack_arrays

#: ok, flagged (build_small_campaign marks it), no stable phase, free sled (no DP channel)
RUNS = ["L070_MP0_SC_s+020.mcap", "L070_MP0_SC_s+005.mcap", "L180_MP0_SC_s+090.mcap",
        "L070_MP0_FS"]
OK_RUN = "L070_MP0_SC_s+020"
#: raw channel (ingest) and unit of each traced quantity (no rig compliance in the sample)
RAW_CHANNEL = {"dp_n": ("dp_n", "N"), "torque_nm": ("ty_nm", "N*m"),
               "sinkage_m": ("sinkage_m", "m"), "slip": ("slip", "1")}


def test_minmax_decimation_by_hand():
    t = np.arange(7.0)
    x = np.array([3.0, 1.0, 2.0, np.nan, np.nan, np.nan, 5.0])
    # 7 samples > 6 points: blocks of ceil(2 * 7 / 6) = 3 samples, the last one short
    td, xd, block = decimate_minmax(t, x, max_points=6)
    assert block == 3
    # block [3, 1, 2]: max at t=0 then min at t=1; block of NaN: one gap at t=3; block [5]
    assert td.tolist() == [0.0, 1.0, 3.0, 3.0, 6.0, 6.0]
    assert xd[:2].tolist() == [3.0, 1.0] and np.isnan(xd[2:4]).all()
    assert xd[4:].tolist() == [5.0, 5.0]
    td, xd, block = decimate_minmax(t, x, max_points=7)  # short enough: kept whole
    assert block == 1 and td.tolist() == t.tolist() and np.array_equal(xd, x, equal_nan=True)
    # an odd limit: 10 samples in at most 2 blocks of 5, 4 points
    td, xd, block = decimate_minmax(np.arange(10.0), np.arange(10.0)[::-1], max_points=5)
    assert block == 5 and td.tolist() == [0.0, 4.0, 5.0, 9.0] and xd.tolist() == [9, 5, 4, 0]
    with pytest.raises(ValueError, match="one length"):
        decimate_minmax(t, x[:3])


@pytest.fixture(scope="module")
def processed(tmp_path_factory):
    """(database URL, folder) of four sample runs processed, their raw files deleted."""
    folder = tmp_path_factory.mktemp("traces")
    url = build_small_campaign(folder, runs=RUNS, export=False)
    shutil.rmtree(folder / "campaign")
    return url, folder


def _stored(url: str, run_id: str) -> dict[str, tuple[RunTrace, np.ndarray, np.ndarray]]:
    with open_database(url)() as session:
        rows = session.scalars(select(RunTrace).join(RunResult).join(RawFile).join(Run)
                               .where(Run.run_id == run_id)).all()
        return {r.channel: (r, *unpack_arrays(r.arrays)) for r in rows}


def test_stored_traces_are_the_raw_channels_min_and_max_per_block(processed):
    url, _ = processed
    raw = ingest.read_run(SAMPLE / f"{OK_RUN}.mcap").channels  # the committed copy
    t = raw["t_s"].to_numpy()
    stored = _stored(url, OK_RUN)
    assert set(stored) == set(RAW_CHANNEL) == set(TRACE_QUANTITIES)
    n, block = len(t), 3  # 2400 samples in at most 1000 blocks: 3 a block (800), 1600 points
    assert n == 2400
    for quantity, (row, t_s, values) in stored.items():
        channel, unit = RAW_CHANNEL[quantity]
        x = raw[channel].to_numpy()
        assert (row.samples, row.block, row.points, row.unit) == (
            n, block, 2 * math.ceil(n / block), unit)
        expected_t, expected_x = [], []
        for start in range(0, n, block):  # per block: first smallest and first largest sample
            finite = [i for i in range(start, min(start + block, n)) if np.isfinite(x[i])]
            if not finite:
                expected_t += [t[start]] * 2
                expected_x += [np.nan] * 2
                continue
            low = min(finite, key=lambda i: x[i])
            high = max(finite, key=lambda i: x[i])
            for i in sorted((low, high)):
                expected_t.append(t[i])
                expected_x.append(x[i])
        assert t_s.tolist() == expected_t
        np.testing.assert_allclose(values, expected_x, rtol=2e-7, atol=0.0)
        # the envelope is the raw one: extremes kept, where block means would shrink them
        assert np.nanmax(values) == np.float32(np.nanmax(x))
        assert np.nanmin(values) == np.float32(np.nanmin(x))


def test_report_renders_after_the_raw_files_are_gone(processed):
    url, folder = processed
    assert not (folder / "campaign").exists()
    page = write_report(url, folder / "report.html")
    text = page.read_text(encoding="utf-8")
    assert "not stored" not in text and "not readable" not in text
    thumbs = re.findall(r'<a href="#full-run-\d+">(<svg .*?</svg>)</a><figcaption>', text)
    assert len(thumbs) == len(RUNS)
    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample", url)
    for run, svg in zip(data.runs, thumbs):
        panels = [p for p in ET.fromstring(svg).iter("svg")
                  if p.get("class") == "axes"]
        assert [p.get("data-quantity") for p in panels] == list(TRACE_QUANTITIES)
        for panel, channel in zip(panels, TRACE_QUANTITIES):
            lines = panel.findall("path[@class='trace']")
            if channel in run.traces:  # drawn from the stored points themselves
                finite = np.isfinite(run.traces[channel].values).sum()
                points = len(re.findall(r"-?\d+ -?\d+", lines[0].get("d").replace("l", " ")))
                assert len(lines) == 1 and points == finite <= MAX_TRACE_POINTS
            else:
                assert [t.text for t in panel.iter("text")] == ["not measured"]
    nsp = next(r for r in data.runs if r.run_id == NO_STABLE_RUN)
    assert nsp.status == "no_stable_phase" and set(nsp.traces) == set(TRACE_QUANTITIES)


def test_runs_processed_before_traces_were_stored_get_a_placeholder(processed, tmp_path):
    source, _ = processed
    target = tmp_path / "old.sqlite"
    shutil.copy2(source.removeprefix("sqlite:///"), target)
    url = f"sqlite:///{target}"
    with open_database(url).begin() as session:  # as a database processed before 0006
        session.execute(delete(RunTrace))
    text = write_report(url, tmp_path / "report.html").read_text(encoding="utf-8")
    captions = re.findall(r'<figure id="run-\d+"[^>]*>.*?<figcaption>([^<]*)</figcaption>', text)
    assert len(captions) == len(RUNS)
    assert all(c.endswith(" · trace not stored; re-run swtlab process") for c in captions)


def test_report_straight_from_in_memory_results(tmp_path, monkeypatch):
    results = [process_run(ingest.read_run(SAMPLE / name)) for name in RUNS]

    def no_raw_file(*args, **kwargs):
        raise AssertionError("the report read a raw file")

    monkeypatch.setattr(ingest, "read_run", no_raw_file)
    data = from_results("bb2_sand_sample", results)
    assert [r.run_id for r in data.runs] == [r.run_id for r in results]
    ok = next(r for r in data.runs if r.run_id == OK_RUN)
    assert ok.means["dp_n"] == pytest.approx(results[0].quantities["dp_n"].mean)
    assert ok.traces["dp_n"] is results[0].traces["dp_n"]
    text = render_report(data, tmp_path / "r.html").read_text(encoding="utf-8")
    assert "in-memory pipeline results" in text and "not stored" not in text
    assert len(re.findall(r'<div class="lightbox" id="full-run-\d+"', text)) == len(RUNS)
    assert not list(tmp_path.glob(".r.html.*"))  # written atomically, no temporary left


def test_traces_stored_are_the_processed_ones_on_every_backend(db_url, tmp_path):
    from swtlab_cli.main import main

    campaign = tmp_path / "campaign"
    campaign.mkdir()
    shutil.copy2(SAMPLE / RUNS[0], campaign / RUNS[0])
    assert main(["process", str(campaign), "--db", db_url, "--quiet"]) == 0
    processed = process_run(ingest.read_run(campaign / RUNS[0])).traces
    stored = _stored(db_url, OK_RUN)
    assert set(stored) == set(processed)
    for channel, (row, t_s, values) in stored.items():
        assert t_s.dtype == np.float64 and values.dtype == np.float32
        assert np.array_equal(t_s, processed[channel].t_s)
        assert np.array_equal(values, processed[channel].values, equal_nan=True)
        assert (row.samples, row.block, row.unit) == (processed[channel].samples,
                                                       processed[channel].block,
                                                       processed[channel].unit)
