"""Files cut short are read as far as they go, say where they end, and flag their run: an
MCAP without its summary and footer, a CSV whose last line was cut or whose run stops before
its end-of-run rest, a delimited text log cut mid-line, a ROS 1 bag without its index.

Every file is written by its format's own library (mcap, pandas, rosbags) and then cut by
bytes; the truth is the same file whole (or the samples written), never the reader."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import ingest
from bench import format_files as fw
from run_results import process_run

CAMPAIGN = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
SAMPLE = CAMPAIGN / "L070_MP0_SC_s+010.mcap"


def _assert_prefix(run, whole):
    """Each stream of ``run`` is the first part of the same stream of ``whole``."""
    assert run.streams.keys() == whole.streams.keys()
    for topic, want in whole.streams.items():
        got = run.streams[topic]
        assert len(got) <= len(want), topic
        pd.testing.assert_frame_equal(got, want.iloc[:len(got)], obj=topic)


def _end_s(run) -> float:
    return max(float(frame["t_s"].iloc[-1]) for frame in run.streams.values())


def test_mcap_without_summary_or_footer(tmp_path, ingest_spec):
    """A logger that dies before ``finish()`` leaves its metadata and flushed chunks and no
    summary or footer: the samples of the chunks are read, exactly as written."""
    from mcap.writer import Writer

    path = tmp_path / "run.mcap"
    stream = open(path, "wb")
    writer = Writer(stream, chunk_size=4096)
    writer.start(profile="", library="swtlab-tests")
    for name, values in ingest_spec.records.items():
        writer.add_metadata(name=f"swt.{name}", data=values)
    messages = []
    for topic, fields in ingest_spec.topics.items():
        schema = writer.register_schema(name=topic, encoding="jsonschema", data=b"{}")
        channel = writer.register_channel(topic=topic, message_encoding="json", schema_id=schema)
        for start in range(0, len(fields["t_ns"]), 20):
            block = {k: v[start:start + 20].tolist() for k, v in fields.items()}
            messages.append((int(fields["t_ns"][start]), channel, json.dumps(block).encode()))
    for log_time, channel, data in sorted(messages, key=lambda m: m[0]):
        writer.add_message(channel_id=channel, log_time=log_time, data=data,
                           publish_time=log_time)
    stream.close()  # no finish(): the last chunk, summary and footer never written

    run = ingest.read_run(path)
    end = _end_s(run)
    read = sum(len(frame) for frame in run.streams.values())
    assert 0 < read < sum(len(fields["t_ns"]) for fields in ingest_spec.topics.values())
    assert run.cut_short == (f"run.mcap: file ends at t = {end:.3f} s (cut short?): truncated "
                             "MCAP: no summary and no footer (the logger stopped mid-write); the "
                             "messages of its whole records are read")
    assert any(p.message == run.cut_short and p.severity == "error" for p in run.problems)
    dp = run.streams["/tether/force"]
    truth = ingest_spec.topics["/tether/force"]
    np.testing.assert_array_equal(dp["t_s"].to_numpy(), truth["t_ns"][:len(dp)] * 1e-9)
    np.testing.assert_array_equal(dp["dp_n"].to_numpy(), truth["dp"][:len(dp)])


@pytest.mark.parametrize("fraction", [0.6, 0.97])
def test_mcap_cut_inside_its_chunk_is_flagged_not_ok(tmp_path, fraction):
    """The sample MCAP (one zstd chunk) cut by bytes: what the chunk's whole compressed
    blocks hold is read, and the run is flagged where the whole file is ``ok``."""
    whole = ingest.read_run(SAMPLE)
    assert process_run(whole).status == "ok"
    path = tmp_path / SAMPLE.name
    data = SAMPLE.read_bytes()
    path.write_bytes(data[:int(len(data) * fraction)])
    run = ingest.read_run(path)
    _assert_prefix(run, whole)
    assert run.cut_short.startswith(f"{SAMPLE.name}: file ends at t = {_end_s(run):.3f} s "
                                    "(cut short?)")
    result = process_run(run)
    assert result.status != "ok" and run.cut_short in result.flags


def test_mcap_too_short_for_any_record_is_an_error(tmp_path):
    path = tmp_path / "r.mcap"
    path.write_bytes(SAMPLE.read_bytes()[:200])
    with pytest.raises(ingest.IngestError, match="corrupt or truncated MCAP"):
        ingest.read_run(path)


def test_csv_run_with_its_last_line_cut(tmp_path, ingest_tools, ingest_spec):
    """A topic CSV (written by pandas) cut in the middle of a row: the row is dropped (its
    last number may be cut too), every whole row is read, and the run names the file."""
    folder = ingest_tools.write_csv_run(tmp_path / "run", ingest_spec.topics,
                                        ingest_spec.records)
    csv = folder / "tether_force.csv"
    text = csv.read_bytes()
    rows = text.count(b"\n") - 1
    middle = text.rindex(b"\n", 0, len(text) // 2) + 7  # 6 bytes into a row
    csv.write_bytes(text[:middle])
    whole_rows = text[:middle].count(b"\n") - 1
    assert 0 < whole_rows < rows
    run = ingest.read_run(folder)
    dp = run.streams["/tether/force"]
    truth = ingest_spec.topics["/tether/force"]
    assert len(dp) == whole_rows
    np.testing.assert_array_equal(dp["dp_n"].to_numpy(), truth["dp"][:whole_rows])
    assert run.cut_short == (f"run: file ends at t = {_end_s(run):.3f} s (cut short?): "
                             "tether_force.csv: its last line has no line break (the logger "
                             "stopped mid-row); that line is dropped")
    assert process_run(run).status != "ok"


def test_csv_run_that_ends_before_its_rest_is_flagged(tmp_path):
    """The sample free-sled run folder cut at whole rows at 50 s, mid-drive: the files look
    whole, but the run rests before its drive and not after; without the end-of-run rest the
    drift of the load cells is not measured and u(DP) comes out smaller. Flagged, not ok."""
    source = CAMPAIGN / "L070_MP0_FS"
    whole = process_run(ingest.read_run(source))
    assert whole.status == "ok"
    folder = shutil.copytree(source, tmp_path / source.name)
    for csv in folder.glob("*.csv"):
        lines = csv.read_text().splitlines(keepends=True)
        csv.write_text("".join(lines[:1] + [ln for ln in lines[1:]
                                            if float(ln.split(",")[0]) <= 50.0]))
    run = ingest.read_run(folder)
    assert run.cut_short is None
    result = process_run(run)
    assert result.status == "flagged"
    flag = result.flags[0]
    assert flag.startswith(f"{source.name}: file ends at t = {_end_s(run):.3f} s (cut short?): "
                           "the run rests 2.2 s before its drive")
    assert flag.endswith("its end-of-run rest reading is missing")
    assert result.uncertainty["dp_n"].u < whole.uncertainty["dp_n"].u  # why it must be flagged


def test_delimited_text_log_cut_mid_line(tmp_path, ingest_cmu_root):
    """A CMU motion log cut in the middle of a line reads its whole lines and says so (it
    used to report a NaN sample, as if a sensor had failed)."""
    source = sorted((ingest_cmu_root / "raw").rglob("*.txt"))[0]
    whole = ingest.read_run(source, "cmu_3d_terramechanics")
    text = source.read_bytes()
    cut = tmp_path / source.name
    cut.write_bytes(text[:text.rindex(b"\n", 0, len(text) // 2) + 10])
    run = ingest.read_run(cut, "cmu_3d_terramechanics")
    _assert_prefix(run, whole)
    assert len(run.streams["/cmu/motion"]) == text[:len(text) // 2].count(b"\n")
    assert run.cut_short == (f"{source.name}: file ends at t = {_end_s(run):.3f} s (cut "
                             "short?): its last line has no line break (the logger stopped "
                             "mid-row); that line is dropped")


@pytest.mark.parametrize("fraction", [0.3, 0.8])
def test_ros1_bag_cut_short(tmp_path, fraction):
    """The sample run written as a ROS 1 bag by rosbags and cut by bytes: its index is gone;
    the messages of its whole records are read (the first part of what the whole bag gives)
    and the run is flagged."""
    spec = fw.read_spec_mcap(SAMPLE)
    bag = fw.write_ros1(spec, tmp_path / "run.bag")
    whole = ingest.read_run(bag, "spec_ros")
    data = bag.read_bytes()
    bag.write_bytes(data[:int(len(data) * fraction)])
    run = ingest.read_run(bag, "spec_ros")
    _assert_prefix(run, whole)
    assert 0 < _end_s(run) < _end_s(whole)
    assert run.cut_short == (f"run.bag: file ends at t = {_end_s(run):.3f} s (cut short?): ROS 1 "
                             "bag without its index (the recorder stopped mid-write); the "
                             "messages of its whole chunks and records are read")
    assert process_run(run).status != "ok"
