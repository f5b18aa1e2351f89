"""Channel maps are checked: a column that looks like a misspelt canonical one is refused
with "did you mean", ``swtlab inspect`` exits 3 naming a channel the stable phase needs and
the run lacks, and a rig without a drawbar-pull cell feeds ``dp_n`` from the hub's force
channel, which its results say."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np
import pytest

import ingest
from run_results import process_run
from swtlab_cli import cmd_inspect, exit_codes

SPEC_MAP = (Path(ingest.__file__).parent / "channel_maps" / "spec.toml").read_text()
SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / "L070_MP0_SC_s+010.mcap"
CHANNEL = "[[channels]]\ncolumn = '{column}'\ntopic = '/a'\nfield = 'f'\nunit = '{unit}'\n"


def _map(tmp_path, text: str) -> Path:
    path = tmp_path / "lab.toml"
    path.write_text(text)
    return path


def _without(column: str) -> str:
    """The spec map with the [[channels]] entry of ``column`` removed."""
    entries = SPEC_MAP.split("[[channels]]")
    kept = [e for e in entries[1:] if f'column = "{column}"' not in e]
    assert len(kept) == len(entries) - 2
    return "[[channels]]".join([entries[0], *kept])


@pytest.mark.parametrize("column, unit, meant", [
    ("sled_postion_m", "mm", "sled_position_m"),      # a letter left out
    ("fz_nn", "N", "fz_n"),
    ("tx_n", "N", "tx_nm"),                           # a torque's unit cut short
    ("sled_position_mm", "mm", "sled_position_m"),    # the lab's unit in the name
    ("dp_kn", "kN", "dp_n"),
    ("wheel_angle_deg", "deg", "wheel_angle_rad"),
])
def test_a_misspelt_canonical_column_is_refused_with_did_you_mean(tmp_path, column, unit,
                                                                  meant):
    with pytest.raises(ingest.IngestError) as caught:
        ingest.load_channel_map(_map(tmp_path, CHANNEL.format(column=column, unit=unit)))
    assert caught.value.channel == column
    assert f"did you mean `{meant}`?" in caught.value.problem


@pytest.mark.parametrize("column, unit", [("slip_angle_rad", "deg"), ("fx_cell2_n", "N"),
                                          ("lvdt_height_m", "mm")])
def test_extra_columns_unlike_any_canonical_one_are_kept(tmp_path, column, unit):
    cmap = ingest.load_channel_map(_map(tmp_path, CHANNEL.format(column=column, unit=unit)))
    assert [c.column for c in cmap.channels] == [column]


def _inspect(argv):
    parser = argparse.ArgumentParser(prog="swtlab")
    cmd_inspect.register(parser.add_subparsers())
    args = parser.parse_args(["inspect", *argv])
    return args.func(args)


def test_inspect_exits_3_naming_what_the_stable_phase_needs(tmp_path, ingest_good_mcap, capsys):
    cmap = _map(tmp_path, _without("sled_position_m"))
    assert _inspect([str(ingest_good_mcap), "--channel-map", str(cmap)]) == exit_codes.BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out.startswith("run r001")  # the report is still shown
    assert captured.err == (f"{ingest_good_mcap}: sled_velocity_mps: the stable phase needs it "
                            "(from sled_position_m or sled_velocity_mps); not in this source "
                            "(channel map spec)\n")
    assert _inspect([str(ingest_good_mcap)]) == exit_codes.OK


def test_dp_from_the_hub_force_channel_says_so(tmp_path):
    """The sample run read with dp_n fed from the hub's fx (a rig without a drawbar-pull
    cell): dp_n is the hub's fx sample for sample, and the result's flags say where DP
    came from instead of "no force channels"."""
    hub = SPEC_MAP.replace('topic = "/tether/force"\nfield = "dp"',
                           'topic = "/hub/wrench"\nfield = "fx"')
    assert hub != SPEC_MAP
    run = ingest.read_run(SAMPLE, _map(tmp_path, hub))
    np.testing.assert_array_equal(run.streams["/hub/wrench"]["dp_n"],
                                  run.streams["/hub/wrench"]["fx_n"])
    assert run.derivation["dp_n"]["channel"] == "/hub/wrench.fx"
    flags = process_run(run).flags
    assert "drawbar pull from the hub's force channel /hub/wrench.fx (as fx_n; no "\
           "drawbar-pull cell): DP is the hub's horizontal force" in flags
    assert not any(f.startswith("no force channels") for f in flags)


def test_the_hub_zero_tares_dp_only_when_read_alike(tmp_path):
    """swt.zero.fx is in fx_n's SI values: dp_n read with another scale keeps its own zero."""
    flipped = SPEC_MAP.replace('topic = "/tether/force"\nfield = "dp"\nunit = "N"',
                               'topic = "/hub/wrench"\nfield = "fx"\nunit = "N"\nscale = -1.0')
    assert flipped != SPEC_MAP
    run = ingest.read_run(SAMPLE, _map(tmp_path, flipped))
    zero = run.metadata.zero["fx"]
    assert zero != 0
    hub = run.streams["/hub/wrench"]
    np.testing.assert_allclose(hub["dp_n"], -(hub["fx_n"] + zero), rtol=0, atol=1e-12)


def test_a_map_without_dp_hints_at_the_hub_channel(tmp_path):
    run = ingest.read_run(SAMPLE, _map(tmp_path, _without("dp_n")))
    flags = [f for f in process_run(run).flags if f.startswith("no force channels")]
    assert len(flags) == 1 and re.search(r"\(dp_n\).*feeds dp_n from the hub's force channel "
                                         r"in its channel map \(docs/channel-map.md\)", flags[0])
