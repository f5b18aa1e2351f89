"""Channel maps: renamed topics/fields/columns, units, headerless text, metadata, bad maps."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ingest
from ingest import IngestError, units
from ingest.channel_map import load_channel_map, shipped_maps

LAB_MAP = """
[map]
name = "lab_x"
format = "spec"

[time]
column = "time_ms"
unit = "ms"

[[channels]]
column = "fz_n"
topic = "/ft"
field = "Fz"
unit = "kN"
required = true
csv_file = "forces.csv"
[[channels]]
column = "ty_nm"
topic = "/ft"
field = "My"
unit = "lbf*in"
required = true
csv_file = "forces.csv"
[[channels]]
column = "dp_n"
topic = "/pull"
field = "F"
unit = "lbf"
scale = -1.0
required = true
[[channels]]
column = "wheel_angle_rad"
topic = "/drive"
field = "pos_deg"
unit = "deg"
required = true
[[channels]]
column = "sled_position_m"
topic = "/carriage"
field = "x"
csv_column = "X (mm)"
unit = "mm"
required = true
[[channels]]
column = "suspension_angle_rad"
topic = "/arm"
field = "a"
unit = "deg"
required = true

[metadata.run]
campaign = "lab-x-2026"
soil = "GRC-1"
"""


def _lab_topics(ingest_tools):
    """The truth topics renamed and re-united the way lab X logs them."""
    truth = ingest_tools.truth_topics()
    lbf, lbf_in = 4.4482216152605, 4.4482216152605 * 0.0254
    wrench, dp = truth["/hub/wrench"], truth["/tether/force"]
    lab = {
        "/ft": {"t_ns": wrench["t_ns"], "Fz": wrench["fz"] / 1000.0, "My": wrench["ty"] / lbf_in},
        "/pull": {"t_ns": dp["t_ns"], "F": -dp["dp"] / lbf},
        "/drive": {"t_ns": truth["/wheel/encoder"]["t_ns"],
                   "pos_deg": np.degrees(truth["/wheel/encoder"]["angle"])},
        "/carriage": {"t_ns": truth["/sled/encoder"]["t_ns"],
                      "x": truth["/sled/encoder"]["position"] * 1000.0},
        "/arm": {"t_ns": truth["/suspension/angle"]["t_ns"],
                 "a": np.degrees(truth["/suspension/angle"]["angle"])},
    }
    return truth, lab


def test_units_table():
    assert units.to_si(np.array([1.0]), units.lookup("kN"))[0] == 1000.0
    assert math.isclose(units.to_si(np.array([1.0]), units.lookup("lbf*in"))[0], 0.112984829)
    assert math.isclose(units.to_si(np.array([60.0]), units.lookup("rpm"))[0], 2 * math.pi)
    assert math.isclose(units.to_si(np.array([180.0]), units.lookup("deg/s"))[0], math.pi)
    for same in ("N·m", "N*m", "Nm"):
        assert units.lookup(same).factor == 1.0 and units.lookup(same).quantity == "torque"
    assert units.lookup("us").factor == 1e-6 and units.lookup("ns").factor == 1e-9
    assert units.lookup("furlong") is None
    assert units.column_quantity("ty_nm") == "torque" and units.column_quantity("fz_n") == "force"
    assert units.column_quantity("wheel_omega_radps") == "angular_velocity"


def test_shipped_maps():
    assert {"spec", "cmu_3d_terramechanics"} <= set(shipped_maps())
    spec = load_channel_map()
    assert spec.name == "spec" and len(spec.channels) == 11
    assert [c.column for c in spec.channels if not c.required] == ["tether_position_m"]


def test_lab_map_on_mcap_gives_canonical_si(tmp_path, ingest_tools):
    truth, lab = _lab_topics(ingest_tools)
    records = ingest_tools.records(run={"campaign": None, "soil": None})
    path = ingest_tools.write_mcap(tmp_path / "lab.mcap", ingest_tools.Spec(lab, records))
    map_path = tmp_path / "lab_x.toml"
    map_path.write_text(LAB_MAP)
    run = ingest.read_run(path, map_path)
    np.testing.assert_allclose(run.streams["/ft"]["fz_n"], truth["/hub/wrench"]["fz"], rtol=1e-12)
    np.testing.assert_allclose(run.streams["/ft"]["ty_nm"], truth["/hub/wrench"]["ty"], rtol=1e-12)
    np.testing.assert_allclose(run.streams["/pull"]["dp_n"], truth["/tether/force"]["dp"],
                               rtol=1e-12)
    np.testing.assert_allclose(run.streams["/carriage"]["sled_position_m"],
                               truth["/sled/encoder"]["position"], rtol=1e-12, atol=1e-15)
    assert run.metadata.run.campaign == "lab-x-2026" and run.metadata.run.soil == "GRC-1"
    assert run.channel_map == "lab_x" and run.units["ty_nm"] == "lbf*in"
    # fx, fy, tx, tz are not in this lab's map: reported, NaN, the rest still derived
    missing = sorted(p.channel for p in run.problems if p.severity == "error")
    assert missing == ["fx_n", "fy_n", "tx_nm", "tz_nm"]
    assert run.channels["fx_n"].isna().all()
    assert abs(np.nanmedian(run.channels["slip"]) - 0.25) < 0.002


def test_lab_map_on_csv_with_renamed_columns(tmp_path, ingest_tools):
    truth, lab = _lab_topics(ingest_tools)
    folder = tmp_path / "run"
    ingest_tools.write_csv_run(folder, {}, ingest_tools.records())
    import pandas as pd

    for topic, fields in lab.items():
        name = "forces.csv" if topic == "/ft" else topic.strip("/") + ".csv"
        table = {"time_ms": fields["t_ns"] * 1e-6}
        table.update({("X (mm)" if k == "x" else k): v for k, v in fields.items() if k != "t_ns"})
        pd.DataFrame(table).to_csv(folder / name, index=False, float_format="%.17g")
    map_path = tmp_path / "lab_x.toml"
    map_path.write_text(LAB_MAP)
    run = ingest.read_run(folder, map_path)
    np.testing.assert_allclose(run.streams["/carriage"]["t_s"],
                               truth["/sled/encoder"]["t_ns"] * 1e-9, atol=1e-12)
    np.testing.assert_allclose(run.streams["/carriage"]["sled_position_m"],
                               truth["/sled/encoder"]["position"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(run.streams["/arm"]["suspension_angle_rad"], 0.08, rtol=1e-12)


HEADERLESS_MAP = """
[map]
name = "bench_txt"
format = "delimited"
[files]
pattern = "*.dat"
delimiter = ";"
header_rows = 2
comment = "#"
columns = ["t_us", "angle_rev", "carriage_cm", "fz_lbf", "h_mm"]
[time]
column = "t_us"
unit = "us"
[[channels]]
column = "wheel_angle_rad"
field = "angle_rev"
unit = "rev"
required = true
[[channels]]
column = "sled_position_m"
field = "carriage_cm"
unit = "cm"
[[channels]]
column = "fz_n"
field = "fz_lbf"
unit = "lbf"
[[channels]]
column = "hub_height_m"
field = "h_mm"
unit = "mm"
zero = "first"
zero_value = 5.0
[metadata.run]
campaign = "bench"
wheel = "w"
soil = "s"
multipass = 0
mode = "towed"
load_N = 80
velocity_mps = 0.05
[metadata.wheel]
radius_m = 0.1
width_m = 0.05
grouser_count = 0
grouser_height_m = 0
[metadata.filename]
regex = '^run_(?P<mp>\\d+)_(?P<load>\\d+)N\\.dat$'
[metadata.filename.fields]
"run.multipass" = { group = "mp" }
"run.load_N" = { group = "load", unit = "N" }
"""


def test_headerless_delimited_file_with_column_order(tmp_path):
    t = np.arange(0, 5, 0.01)
    rows = np.column_stack([t * 1e6, 0.3 * t, 4.0 * t, np.full_like(t, 22.0), 30 - 2 * t])
    path = tmp_path / "runs" / "run_2_95N.dat"
    path.parent.mkdir()
    body = "\n".join(";".join(f"{v:.9g}" for v in row) for row in rows)
    path.write_text("bench log\nunits: us;rev;cm;lbf;mm\n# comment line\n" + body + "\n")
    map_path = tmp_path / "bench.toml"
    map_path.write_text(HEADERLESS_MAP)
    run = ingest.read_run(path, map_path)
    ch = run.channels
    inner = (ch["t_s"] > 0.5) & (ch["t_s"] < 4.5)
    np.testing.assert_allclose(ch.loc[inner, "wheel_omega_radps"], 0.3 * 2 * math.pi, rtol=1e-6)
    np.testing.assert_allclose(ch.loc[inner, "sled_velocity_mps"], 0.04, rtol=1e-6)
    np.testing.assert_allclose(ch["fz_n"], 22.0 * 4.4482216152605, rtol=1e-9)
    np.testing.assert_allclose(ch["hub_height_m"], 0.005 - 0.002 * ch["t_s"], atol=1e-9)
    condition = run.metadata.run.condition
    assert condition.multipass == 2 and condition.load_set_n == 95.0
    assert run.metadata.run.run_id == "run_2_95N"
    assert ingest.find_runs(tmp_path, map_path) == [path]


def _bad_map(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(IngestError) as info:
        load_channel_map(path)
    assert info.value.path == path and "\n" not in str(info.value)
    return info.value


def test_unknown_unit_names_map_file_and_channel(tmp_path):
    err = _bad_map(tmp_path, LAB_MAP.replace('unit = "kN"', 'unit = "kiloponds"'))
    assert err.channel == "fz_n" and "unknown unit 'kiloponds'" in err.problem


def test_unit_of_the_wrong_quantity(tmp_path):
    err = _bad_map(tmp_path, LAB_MAP.replace('unit = "kN"', 'unit = "mm"'))
    assert err.channel == "fz_n" and "'mm' is a length but the column holds a force" in err.problem


@pytest.mark.parametrize("text, channel, words", [
    ("[map]\nformat='xml'\n[[channels]]\ncolumn='fz_n'\n", "map.format", "'xml'"),
    ("[map\n", None, "not valid TOML"),
    ("[map]\n", "channels", "no [[channels]]"),
    ("[[channels]]\ncolumn='force'\ntopic='/a'\nfield='f'\nunit='N'\n", "force",
     "not a canonical column"),
    ("[[channels]]\ncolumn='fz_n'\ntopic='/a'\nfield='f'\nunit='N'\ncolour='red'\n", "fz_n",
     "unknown key 'colour'"),
    ("[[channels]]\ncolumn='fz_n'\ntopic='/a'\nfield='f'\nunit='N'\n"
     "[[channels]]\ncolumn='fz_n'\ntopic='/b'\nfield='g'\nunit='N'\n", "fz_n", "fed twice"),
    ("[time]\nunit='parsec'\n[[channels]]\ncolumn='fz_n'\ntopic='/a'\nfield='f'\nunit='N'\n",
     "time.unit", "unknown unit 'parsec'"),
    ("[[channels]]\ncolumn='fz_n'\ntopic='/a'\nfield='f'\nunit='N'\nstamp='header.stamp'\n"
     "[[channels]]\ncolumn='fx_n'\ntopic='/a'\nfield='g'\nunit='N'\n", "fx_n",
     "stamp differs from another channel of /a"),
])
def test_bad_maps(tmp_path, text, channel, words):
    err = _bad_map(tmp_path, text)
    assert err.channel == channel and words in err.problem


def test_unknown_shipped_map_name():
    with pytest.raises(IngestError, match="no such shipped channel map"):
        load_channel_map("no_such_lab")


def test_delimited_file_with_wrong_column_count(tmp_path):
    map_path = tmp_path / "bench.toml"
    map_path.write_text(HEADERLESS_MAP)
    path = tmp_path / "run_0_80N.dat"
    path.write_text("a\nb\n1;2;3\n")
    with pytest.raises(IngestError, match="3 columns, the channel map bench.toml expects 5"):
        ingest.read_run(path, map_path)


def test_delimited_map_channels_on_a_bag_topic_are_message_paths(tmp_path):
    """A delimited map's channel on another topic than its stream reads a bag's message path:
    its field need not be a text column, and the text log's map leaves it out (the CMU text
    logs' problems stay exactly the force columns: tests/test_ingest_cmu.py)."""
    path = tmp_path / "bag_topic.toml"
    path.write_text("[map]\nformat='delimited'\n[files]\nstream='/log'\ncolumns=['t','x']\n"
                    "[time]\ncolumn='t'\n[[channels]]\ncolumn='sled_position_m'\nfield='x'\n"
                    "unit='m'\nrequired=true\n[[channels]]\ncolumn='fz_n'\ntopic='/ft'\n"
                    "field='wrench.force.z'\nstamp='header.stamp'\nunit='N'\n")
    cmap = load_channel_map(path)
    assert cmap.topics == ["/log", "/ft"] and cmap.stamp_of("/ft") == "header.stamp"
    assert cmap.stamp_of("/log") is None
    assert [c.column for c in cmap.text_log_map().channels] == ["sled_position_m"]
    err = _bad_map(tmp_path, path.read_text().replace("field='x'", "field='y'"))
    assert err.channel == "y" and "not one of files.columns" in err.problem
