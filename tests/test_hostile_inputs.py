"""Hostile inputs found by fuzzing (issue 17), each a regression test: every one ends as a
one-line IngestError naming file and channel, or as a result that is not marked ok, never as
an unhandled exception, a hang, or a physically impossible value stored as ok."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import ingest
from bench.mcap_content import read_content, write_content
from ingest import IngestError
from swtlab.pipeline.process import ProcessSettings, process_file

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
GOOD_MCAP = SAMPLE / "L180_MP0_SC_s+020.mcap"
GOOD_CSV = SAMPLE / "L070_MP0_FS"
CMU_MAP = "cmu_3d_terramechanics"


def _error(path, channel_map=None) -> IngestError:
    with pytest.raises(IngestError) as info:
        ingest.read_run(path, channel_map)
    assert "\n" not in str(info.value)
    return info.value


def _with_metadata(tmp_path: Path, record: str, key: str, value: str) -> Path:
    content = read_content(GOOD_MCAP)
    content.metadata[f"swt.{record}"][key] = value
    return write_content(tmp_path / "bad.mcap", content)


def _with_block(tmp_path: Path, topic: str, data: bytes, index: int = 0) -> Path:
    content = read_content(GOOD_MCAP)
    [m for m in content.messages if m.topic == topic][index].data = data
    return write_content(tmp_path / "bad.mcap", content)


def _first_block(topic: str) -> dict:
    return read_content(GOOD_MCAP).blocks(topic)[0]


@pytest.mark.parametrize("record, key, value, channel", [
    ("wheel", "grouser_count", "1e18", "swt.wheel.grouser_count"),
    ("wheel", "stiffness_N_per_mm", "1e-300", "swt.wheel.stiffness_N_per_mm"),
    ("wheel", "radius_m", "1e-300", "swt.wheel.radius_m"),
    ("run", "load_N", "1" + "0" * 400, "swt.run.load_N"),
    ("zero", "ty", "-1e308", "swt.zero.ty"),
])
def test_metadata_outside_the_possible_range_is_refused(tmp_path, record, key, value, channel):
    err = _error(_with_metadata(tmp_path, record, key, value))
    assert err.channel == channel and "0" * 40 not in str(err)


def test_a_zero_that_overflows_after_subtraction_is_refused(tmp_path):
    """swt.zero.ty within range but the zeroed torque beyond any testbed's: refused after
    calibration and zeroing (it was stored as NULL torque, status ok)."""
    err = _error(_with_metadata(tmp_path, "zero", "ty", "-9e5"))
    assert err.channel == "/hub/wrench.ty" and "after calibration and zeroing" in err.problem


@pytest.mark.parametrize("value", ["1" + "0" * 400, "Infinity", str(2**63), "1.5", "-1"])
def test_bad_time_stamps_are_refused(tmp_path, value):
    block = _first_block("/wheel/encoder")
    text = json.dumps(block).replace(str(block["t_ns"][-1]), value, 1)
    err = _error(_with_block(tmp_path, "/wheel/encoder", text.encode()))
    assert err.channel == "/wheel/encoder.t_ns"


@pytest.mark.parametrize("value, problem", [
    ("1" + "0" * 400, "float64 range"), ("true", "JSON type bool"),
    ('"1.5"', "JSON type str"), ("[1]", "JSON type list")])
def test_samples_that_are_not_numbers_are_refused_not_converted(tmp_path, value, problem):
    block = _first_block("/hub/wrench")
    block["fz"][0] = "@"
    text = json.dumps(block).replace('"@"', value)
    err = _error(_with_block(tmp_path, "/hub/wrench", text.encode()))
    assert err.channel == "/hub/wrench.fz" and problem in err.problem


def test_a_deeply_nested_payload_is_refused(tmp_path):
    err = _error(_with_block(tmp_path, "/hub/wrench", b"[" * 100_000))
    assert err.channel == "/hub/wrench" and "not valid JSON" in err.problem


def test_run_json_with_a_huge_or_nested_or_boolean_number_is_refused(tmp_path):
    folder = shutil.copytree(GOOD_CSV, tmp_path / "run")
    meta = json.loads((folder / "run.json").read_text())
    (folder / "run.json").write_text(json.dumps(meta).replace('"load_N": 70.0',
                                                              '"load_N": 1' + "0" * 400))
    assert _error(folder).channel == "swt.run.load_N"
    (folder / "run.json").write_text(json.dumps(meta).replace('"load_N": 70.0', '"load_N": true'))
    assert _error(folder).channel == "swt.run.load_N"
    (folder / "run.json").write_text("[" * 100_000)
    assert "nested too deeply" in _error(folder).problem


def _cmu_file(ingest_cmu_root: Path) -> Path:
    return sorted((ingest_cmu_root / "raw").rglob("10_*_*_*.txt"))[0]


def _map(tmp_path: Path, change: tuple[str, str]) -> Path:
    text = (Path(ingest.__file__).parent / "channel_maps" / f"{CMU_MAP}.toml").read_text()
    assert change[0] in text
    path = tmp_path / "map.toml"
    path.write_text(text.replace(*change, 1))
    return path


@pytest.mark.parametrize("change, channel", [
    (('name = "cmu_3d_terramechanics"\nformat', 'name = 5\nformat'), "map.name"),
    (("[map]\nname", "map = \"x\"\n[mapx]\nname"), None),
    (("header_rows = 0", 'header_rows = "x"'), "files.header_rows"),
    (("header_rows = 0", "header_rows = 1000000000"), "files.header_rows"),
    (("[time]\ncolumn", "time = 5\n[timex]\ncolumn"), None),
    (('unit = "mm"\nrequired = true', 'unit = "mm"\nrequired = true\nscale = 1e308'),
     "sled_position_m.scale"),
])
def test_wrong_typed_or_unbounded_channel_map_keys_are_refused(tmp_path, change, channel):
    with pytest.raises(IngestError) as info:
        ingest.load_channel_map(_map(tmp_path, change))
    assert "channel map" in info.value.problem
    if channel:
        assert info.value.channel == channel


@pytest.mark.parametrize("name", ["/etc/passwd", "../../../../etc/passwd"])
def test_a_channel_map_cannot_name_a_file_outside_the_run(tmp_path, name):
    spec_map = (Path(ingest.__file__).parent / "channel_maps" / "spec.toml").read_text()
    assert 'field = "fx"' in spec_map
    path = tmp_path / "map.toml"
    path.write_text(spec_map.replace('field = "fx"', f'field = "fx"\ncsv_file = "{name}"', 1))
    with pytest.raises(IngestError) as info:
        ingest.read_run(shutil.copytree(GOOD_CSV, tmp_path / "run"), path)
    assert "inside the run's folder" in str(info.value) and "root:" not in str(info.value)


@pytest.mark.parametrize("lines", [0, 1, 2, 3])
def test_a_cmu_file_cut_to_a_few_lines_fails_cleanly(tmp_path, ingest_cmu_root, lines):
    source = _cmu_file(ingest_cmu_root)
    cut = tmp_path / source.name
    cut.write_text("".join(source.read_text().splitlines(keepends=True)[:lines]))
    done = process_file(cut, ProcessSettings(channel_map=CMU_MAP, max_frames=0))
    assert [f.error_type for f in done.failures] in ([], ["IngestError"])
    assert done.result is None or done.result.status == "no_stable_phase"


def test_a_cmu_cell_beyond_float64_is_refused(tmp_path, ingest_cmu_root):
    """pandas raises OverflowError on a 400-digit integer cell instead of coercing it."""
    source = _cmu_file(ingest_cmu_root)
    lines = source.read_text().splitlines(keepends=True)[:200]
    cells = lines[50].split(",")
    cells[0] = "1" + "0" * 400
    lines[50] = ",".join(cells)
    bad = tmp_path / source.name
    bad.write_text("".join(lines))
    err = _error(bad, CMU_MAP)
    assert err.channel == "/cmu/motion.x" and "NaN/inf" in err.problem


def test_an_arm_angle_beyond_a_turn_is_refused(tmp_path):
    block = _first_block("/suspension/angle")
    block["angle"][0] = 1000.0
    err = _error(_with_block(tmp_path, "/suspension/angle", json.dumps(block).encode()))
    assert err.channel == "/suspension/angle.angle" and "after calibration" in err.problem
