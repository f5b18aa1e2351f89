"""``swtlab inspect``: text and JSON views of a run; exit code 3 with one line on bad input."""

from __future__ import annotations

import argparse
import json
import re

from swtlab_cli import cmd_inspect, exit_codes


def _main(argv):
    parser = argparse.ArgumentParser(prog="swtlab")
    cmd_inspect.register(parser.add_subparsers())
    args = parser.parse_args(["inspect", *argv])
    return args.func(args)


def test_inspect_text(ingest_good_mcap, capsys):
    assert _main([str(ingest_good_mcap)]) == exit_codes.OK
    out = capsys.readouterr().out
    assert out.startswith("run r001")
    assert re.search(r"/hub/wrench\s+fz_n\s+N\s+N\s+6000\s+100\d\.\d+\s+0\.000-5\.99\d", out)
    assert "common time base: 6000 samples at 1000 Hz" in out
    assert "problems (0):" in out


def test_inspect_json_lists_rates_gaps_units_problems(tmp_path, ingest_tools, ingest_spec, capsys):
    del ingest_spec.topics["/tether/encoder"]
    dp = ingest_spec.topics["/tether/force"]
    keep = (dp["t_ns"] < 1e9) | (dp["t_ns"] > 2e9)
    ingest_spec.topics["/tether/force"] = {k: v[keep] for k, v in dp.items()}
    path = ingest_tools.write_mcap(tmp_path / "r.mcap", ingest_spec)
    assert _main([str(path), "--json"]) == exit_codes.OK
    data = json.loads(capsys.readouterr().out)
    streams = {s["topic"]: s for s in data["streams"]}
    assert abs(streams["/hub/wrench"]["rate_hz"] - 1000) < 5
    assert len(streams["/tether/force"]["gaps"]) == 1
    assert {c["column"]: c["unit"] for c in streams["/hub/wrench"]["channels"]}["ty_nm"] == "N·m"
    assert data["metadata"]["run"]["load_n"] == 150.0
    assert [p["channel"] for p in data["problems"]] == ["tether_position_m", "/tether/force"]


def test_inspect_with_channel_map(ingest_cmu_root, capsys):
    log = ingest_cmu_root / "raw" / "gr810_vx_10" / "12-5-20" / "10_3_0_1.txt"
    assert _main([str(log), "--channel-map", "cmu_3d_terramechanics", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [p["channel"] for p in data["problems"]] == [
        "fx_n", "fy_n", "fz_n", "tx_nm", "ty_nm", "tz_nm", "dp_n"]


def test_inspect_bad_input_exit_code_and_one_line(tmp_path, ingest_good_mcap, capsys):
    bad = tmp_path / "cut.mcap"
    bad.write_bytes(ingest_good_mcap.read_bytes()[:500])
    assert _main([str(bad)]) == exit_codes.BAD_INPUT
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and captured.err.startswith(f"{bad}: -: corrupt")
