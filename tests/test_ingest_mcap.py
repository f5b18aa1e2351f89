"""Spec MCAP form: blocks, uneven rates, gaps, metadata, calibration, zero offsets, frames."""

from __future__ import annotations

import json
import math
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pytest

import ingest


def test_streams_carry_true_si_values_on_native_time_stamps(ingest_good_mcap, ingest_spec):
    run = ingest.read_run(ingest_good_mcap)
    wrench = run.streams["/hub/wrench"]
    truth = ingest_spec.topics["/hub/wrench"]
    np.testing.assert_array_equal(wrench["t_s"].to_numpy(), truth["t_ns"] * 1e-9)
    for fld, column in (("fx", "fx_n"), ("fy", "fy_n"), ("fz", "fz_n"),
                        ("tx", "tx_nm"), ("ty", "ty_nm"), ("tz", "tz_nm")):
        np.testing.assert_allclose(wrench[column].to_numpy(), truth[fld], rtol=0, atol=1e-12)
    assert list(run.streams) == ["/hub/wrench", "/tether/force", "/wheel/encoder",
                                 "/sled/encoder", "/tether/encoder", "/suspension/angle"]
    assert run.problems == []


def test_metadata_is_typed(ingest_good_mcap):
    meta = ingest.read_run(ingest_good_mcap).metadata
    assert meta.run.run_id == "r001" and meta.run.condition.mode == "speed_control"
    assert meta.run.condition.multipass == 0 and isinstance(meta.run.condition.multipass, int)
    assert meta.run.condition.load_set_n == 150.0 and meta.run.condition.slip_setpoint == 0.25
    assert meta.run.condition.gravity_mps2 == 9.80665 and meta.run.condition.steer_deg is None
    assert meta.run.started_at == datetime(2026, 11, 20, 10, tzinfo=timezone.utc)
    assert meta.wheel.radius_m == 0.1 and meta.wheel.grouser_count == 12
    assert meta.wheel.stiffness_n_per_mm is None
    assert meta.suspension.arm_length_m == 0.8 and meta.suspension.angle_zero_rad == 0.1
    assert meta.zero == {} and meta.calibration == {}


def test_gravity_defaults_when_absent(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.records = ingest_tools.records(run={"gravity_mps2": None, "started_at": None})
    meta = ingest.read_run(ingest_tools.write_mcap(tmp_path / "g.mcap", ingest_spec)).metadata
    assert meta.run.condition.gravity_mps2 == 9.80665 and meta.run.started_at is None


def test_calibration_then_zero_offsets(tmp_path, ingest_tools, ingest_spec):
    """Raw counts -> gain*raw + offset (SI) -> minus swt.zero gives back the truth."""
    gain, offset, zero_fz, zero_ty = 0.05, -3.0, 12.5, 0.75
    wrench = ingest_spec.topics["/hub/wrench"]
    truth_fz, truth_ty = wrench["fz"].copy(), wrench["ty"].copy()
    wrench["fz"] = (truth_fz + zero_fz - offset) / gain
    wrench["ty"] = truth_ty + zero_ty
    dp_truth = ingest_spec.topics["/tether/force"]["dp"].copy()
    ingest_spec.topics["/tether/force"]["dp"] = dp_truth / 2.0
    ingest_spec.records["calibration"] = {"/hub/wrench.fz.gain": str(gain),
                                          "/hub/wrench.fz.offset": str(offset),
                                          "/tether/force.dp.gain": "2"}
    ingest_spec.records["zero"] = {"fz": str(zero_fz), "ty": str(zero_ty)}
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "cal.mcap", ingest_spec))
    np.testing.assert_allclose(run.streams["/hub/wrench"]["fz_n"], truth_fz, atol=1e-9)
    np.testing.assert_allclose(run.streams["/hub/wrench"]["ty_nm"], truth_ty, atol=1e-12)
    np.testing.assert_allclose(run.streams["/tether/force"]["dp_n"], dp_truth, atol=1e-12)
    assert run.metadata.calibration[("/hub/wrench", "fz")] == (gain, offset)
    assert run.metadata.calibration[("/tether/force", "dp")] == (2.0, 0.0)
    assert run.metadata.zero == {"fz": zero_fz, "ty": zero_ty}


def test_common_time_base_is_uniform_at_fastest_rate(ingest_good_mcap):
    run = ingest.read_run(ingest_good_mcap)
    t = run.channels["t_s"].to_numpy()
    assert run.derivation["time_base"]["rate_hz"] == 1000.0
    np.testing.assert_allclose(np.diff(t), 1e-3, rtol=1e-9)
    # a constant channel comes through exactly; a sine within linear-interpolation error
    np.testing.assert_allclose(run.channels["fz_n"], 150.0)
    fx = run.channels["fx_n"].to_numpy()
    assert np.nanmax(np.abs(fx - (10 + np.sin(t)))) < 1e-6


def test_derived_signals_match_truth(ingest_good_mcap, ingest_tools):
    truth = ingest_tools.truth
    ch = ingest.read_run(ingest_good_mcap).channels
    inner = (ch["t_s"] > 0.5) & (ch["t_s"] < 5.5)
    omega = ch.loc[inner, "wheel_omega_radps"].to_numpy()
    assert np.max(np.abs(omega / truth["omega_radps"] - 1)) < 0.02
    v = ch.loc[inner, "sled_velocity_mps"].to_numpy()
    assert np.max(np.abs(v / truth["sled_velocity_mps"] - 1)) < 0.005
    assert abs(np.mean(ch.loc[inner, "slip"]) - truth["slip"]) < 0.002
    h = truth["arm_length_m"] * (math.sin(truth["suspension_angle_rad"])
                                 - math.sin(truth["angle_zero_rad"]))
    np.testing.assert_allclose(ch["hub_height_m"].dropna(), h, rtol=1e-12)
    np.testing.assert_allclose(ch["sinkage_m"].dropna(), -h, rtol=1e-12)
    assert h < 0  # the arm below its zero angle: the wheel has sunk


def test_gap_is_nan_on_time_base_and_reported(tmp_path, ingest_tools, ingest_spec):
    dp = ingest_spec.topics["/tether/force"]
    t = dp["t_ns"] * 1e-9
    keep = (t < 2.0) | (t > 2.5)
    ingest_spec.topics["/tether/force"] = {k: v[keep] for k, v in dp.items()}
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "gap.mcap", ingest_spec))
    ch = run.channels
    inside = (ch["t_s"] > 2.01) & (ch["t_s"] < 2.49)
    outside = (ch["t_s"] > 0.01) & (ch["t_s"] < 5.99) & ~((ch["t_s"] > 1.99) & (ch["t_s"] < 2.51))
    assert ch.loc[inside, "dp_n"].isna().all()
    assert ch.loc[outside, "dp_n"].notna().all()
    gaps = [p for p in run.problems if p.channel == "/tether/force" and "gap" in p.message]
    assert len(gaps) == 1 and gaps[0].severity == "warning"
    (start, stop), = run.timing["/tether/force"].gaps
    assert 1.99 < start <= 2.0 and 2.5 <= stop < 2.51


def test_dropped_samples_are_counted(tmp_path, ingest_tools, ingest_spec):
    sled = ingest_spec.topics["/sled/encoder"]
    keep = np.ones(len(sled["t_ns"]), bool)
    keep[[100, 200, 201, 300]] = False  # 1 + 2 + 1 samples missing, no gap (<= 5 intervals)
    ingest_spec.topics["/sled/encoder"] = {k: v[keep] for k, v in sled.items()}
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "drop.mcap", ingest_spec))
    assert run.timing["/sled/encoder"].dropped == 4
    assert any("4 dropped" in p.message for p in run.problems)
    assert run.channels["sled_position_m"].iloc[50:5900].notna().all()


def test_blocks_of_one_sample_and_uneven_rates(tmp_path, ingest_tools, ingest_spec):
    """A topic written as one-sample blocks at an irregular rate reads back sample for sample."""
    rng = np.random.default_rng(3)
    t_ns = np.cumsum(rng.integers(5_000_000, 40_000_000, 200))
    ingest_spec.topics["/suspension/angle"] = {"t_ns": t_ns, "angle": np.full(200, 0.08)}
    path = ingest_tools.write_mcap(tmp_path / "one.mcap", ingest_spec)
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        sizes = [m.data.count(b",") for _, c, m in make_reader(f).iter_messages()
                 if c.topic == "/suspension/angle"]
    assert min(sizes) == 1  # "t_ns": [x], "angle": [y] -> one comma: one-sample blocks exist
    run = ingest.read_run(path)
    np.testing.assert_array_equal(run.streams["/suspension/angle"]["t_s"], t_ns * 1e-9)


def test_optional_tether_encoder_absent_is_a_warning(tmp_path, ingest_tools, ingest_spec):
    del ingest_spec.topics["/tether/encoder"]
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "no_tether.mcap", ingest_spec))
    assert [(p.severity, p.channel) for p in run.problems] == [("warning", "tether_position_m")]
    assert run.channels["tether_position_m"].isna().all()


def test_camera_frames_are_indexed_not_decoded(tmp_path, ingest_tools, ingest_spec):
    stamps = [int(i * 4e7) for i in range(25)]
    ingest_spec.frames = {"/camera/side": stamps, "/camera/track": [10**9, 5 * 10**9]}
    ingest_spec.records["camera"] = {"px_per_m": "2000", "wheel_center_px": "320,240"}
    ingest_spec.records["camera_track"] = {"px_per_m": "800"}
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "cam.mcap", ingest_spec))
    side = run.frames["/camera/side"]
    assert side.count == 25
    np.testing.assert_allclose(side.t_s, np.array(stamps) * 1e-9)
    assert side.data(7) == b"frame-7"
    assert run.frames["/camera/track"].count == 2
    assert run.metadata.camera.px_per_m == 2000 and run.metadata.camera.travel_direction == "+x"
    assert run.metadata.camera.wheel_center_px == (320.0, 240.0)
    assert run.metadata.camera_track.px_per_m == 800
    assert run.problems == []


def test_flexible_wheel_sinkage_removes_deflection(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.records["wheel"]["stiffness_N_per_mm"] = "30"
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "flex.mcap", ingest_spec))
    ch = run.channels.dropna(subset=["hub_height_m", "fz_n"])
    expected = -ch["hub_height_m"] - 150.0 / (1000 * 30)
    np.testing.assert_allclose(ch["sinkage_m"], expected, rtol=1e-12)
    assert run.derivation["sinkage_m"]["stiffness_n_per_mm"] == 30


def test_unknown_topics_and_records_do_not_stop_ingest(tmp_path, ingest_tools, ingest_spec):
    ingest_spec.extra_blocks = [("/lab/temperature", b'{"t_ns": [0], "celsius": [21.0]}')]
    ingest_spec.records["run"]["operator"] = "ann"
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "extra.mcap", ingest_spec))
    assert "/lab/temperature" not in run.streams
    assert [p.channel for p in run.problems] == ["swt.run.operator"]


def test_derivation_records_methods_as_plain_json(ingest_good_mcap, ingest_tools):
    derivation = ingest.read_run(ingest_good_mcap).derivation
    json.dumps(derivation, allow_nan=False)  # stored as is by traceability
    omega = derivation["wheel_omega_radps"]
    assert omega["method"] == "savitzky_golay_derivative" and omega["polyorder"] == 2
    assert omega["quantisation_step"] == pytest.approx(ingest_tools.truth["encoder_step_rad"])
    assert omega["window_samples"] == round(omega["window_s"] * 1000)
    assert derivation["sled_velocity_mps"]["quantisation_step"] == pytest.approx(1e-5)
    assert derivation["time_base"]["rate_hz"] == 1000.0
    assert set(derivation) == {"time_base", "wheel_omega_radps", "sled_velocity_mps",
                               "wheel_surface_speed_mps", "slip", "hub_height_m", "sinkage_m"}


@pytest.mark.parametrize("options", [
    {"compression": "none"}, {"compression": "lz4"}, {"use_chunking": False},
    {"use_summary_offsets": False, "use_statistics": False, "index_types": "none"},
], ids=["uncompressed", "lz4", "unchunked", "no-index"])
def test_other_writers_mcap_variants_ingest(tmp_path, ingest_tools, ingest_spec,
                                            ingest_good_mcap, options):
    """Other tools may write MCAP differently (compression, chunks, indexes): same run."""
    from mcap.writer import CompressionType, IndexType

    if "compression" in options:
        options = {"compression": CompressionType[options["compression"].upper()]}
    if options.get("index_types") == "none":
        options = dict(options, index_types=IndexType.NONE)
    path = ingest_tools.write_mcap(tmp_path / "variant.mcap", ingest_spec, **options)
    run, reference = ingest.read_run(path), ingest.read_run(ingest_good_mcap)
    assert run.metadata == reference.metadata
    np.testing.assert_array_equal(run.channels.to_numpy(), reference.channels.to_numpy())


def test_irregular_clock_is_reported(tmp_path, ingest_tools, ingest_spec):
    rng = np.random.default_rng(5)
    t_ns = np.cumsum(rng.uniform(0.1e6, 6e6, 400)).astype(np.int64)  # std/median ~ 0.56
    ingest_spec.topics["/suspension/angle"] = {"t_ns": t_ns - t_ns[0], "angle": np.full(400, 0.08)}
    run = ingest.read_run(ingest_tools.write_mcap(tmp_path / "jitter.mcap", ingest_spec))
    irregular = [p for p in run.problems if "irregular clock" in p.message]
    assert [p.channel for p in irregular] == ["/suspension/angle"]
    assert run.timing["/suspension/angle"].jitter > 0.5


def test_blocks_decode_the_same_on_the_one_pass_and_the_checked_path():
    """Numbers, a null and out-of-order blocks; a key holding "true" sends the same blocks
    through the sample-by-sample checks: both give the hand-written arrays."""
    from ingest.mcap_reader import _decode_blocks

    blocks = [b'{"t_ns": [20], "fz": [2]}', b'{"t_ns": [0, 10], "fz": [1.5, null]}']
    for key, data in (("fz", blocks), ("true_fz", [b.replace(b'"fz"', b'"true_fz"')
                                                   for b in blocks])):
        topic = _decode_blocks(Path("run.mcap"), "/hub/wrench", data)
        np.testing.assert_array_equal(topic.t_s, np.array([0, 10, 20]) * 1e-9)  # t_ns 1e-9
        np.testing.assert_array_equal(topic.fields[key], [1.5, np.nan, 2.0])
        assert topic.fields[key].dtype == np.float64


@pytest.mark.parametrize("blocks, plain", [
    ([b'{"t_ns": [5, 9], "fz": [1, 2.5]}', b'{"t_ns": [], "fz": []}',
      b'{"t_ns": [0], "fz": [null]}'], True),
    ([b'{"t_\\u006es": [0, 10], "fz": [1.5, 2]}'], False),  # a key spelt with an escape
    ([b'{"t_ns": [0, 1e3], "fz": [1.5, 2]}'], False),       # an exponent: the checks say
    ([b'{"t_ns": [[0], [10]], "fz": [1.5, 2]}'], False)])   # nested stamps
def test_blocks_one_at_a_time_decode_as_the_checked_path_or_leave_it_to_it(blocks, plain):
    """The per-block pass gives the checked path's arrays, or declines (None) and lets the
    checked path decode or name the problem."""
    from ingest.errors import IngestError
    from ingest.mcap_reader import _checked_blocks, _plain_blocks

    fast = _plain_blocks(blocks)
    assert (fast is not None) == plain
    try:
        checked = _checked_blocks(Path("run.mcap"), "/hub/wrench", blocks)
    except IngestError as exc:
        assert not plain and "t_ns" in exc.channel
        return
    if fast is not None:
        np.testing.assert_array_equal(fast.t_s, checked.t_s)
        assert fast.fields.keys() == checked.fields.keys()
        for name, values in checked.fields.items():
            np.testing.assert_array_equal(fast.fields[name], values)
            assert fast.fields[name].dtype == values.dtype == np.float64


@pytest.mark.parametrize("block", [b'{"t_ns": [0, 10], "fz": [1.5, "2"]}',  # a string sample
                                   b'{"t_ns": [0, 10], "fz": [true, 2]}',   # a boolean
                                   b'{"t_ns": [0, 10], "fz": [1.5, 2], "unit": "N"}',
                                   b'{"t_ns": [], "fz": {}}'])              # not a list
def test_blocks_with_more_than_numbers_are_left_to_the_checks(block):
    """Samples that ``array.array`` or ``np.array`` would turn into numbers (a boolean, a
    numeric string) or an empty object where a list belongs: the one-pass decode declines."""
    from ingest.mcap_reader import _plain_blocks

    assert _plain_blocks([block]) is None


def _parsed(text: str):
    """``ingest.json_blocks.parse_blocks`` of one block ``{"x": [text]}``: (value, int or
    None), or None where it declines."""
    from ingest.json_blocks import FIELD_COLUMNS, parse_blocks

    block = f'{{"x": [{text}]}}'.encode()
    values, ints = np.empty(4), np.empty(4, np.int64)
    fields = np.empty((4, FIELD_COLUMNS), np.int64)
    rows = parse_blocks(np.frombuffer(block, np.uint8), np.array([0]), np.array([len(block)]),
                        values, ints, fields)
    if rows < 0:
        return None
    assert rows == 1 and fields[0, 4] - fields[0, 3] == 1
    return values[0], (int(ints[0]) if fields[0, 5] else None)


def test_short_numbers_parse_to_the_correctly_rounded_double():
    """Against CPython's ``float()`` (David Gay's correctly rounded reader, no shared code):
    random decimals of 1-15 significant digits, exponents -30..30 spelt with a point, an
    exponent or both, bit for bit; integers also as themselves."""
    rng = np.random.default_rng(2026)
    parsed = 0
    for _ in range(20000):
        digits = "".join(rng.choice(list("0123456789"), int(rng.integers(1, 16))))
        point = int(rng.integers(0, len(digits) + 1))
        mantissa = digits[:point] or "0"
        if point < len(digits):
            mantissa = f"{int(mantissa)}.{digits[point:]}"
        else:
            mantissa = str(int(mantissa))
        exponent = int(rng.integers(-30, 31))
        text = ("-" if rng.random() < 0.3 else "") + mantissa + (
            f"e{exponent}" if rng.random() < 0.5 else "")
        got = _parsed(text)
        if got is None:
            continue
        parsed += 1
        truth = float(text) if ("." in text or "e" in text) else float(int(text))
        assert np.float64(got[0]).tobytes() == np.float64(truth).tobytes(), text
        if got[1] is not None:
            assert "." not in text and "e" not in text and got[1] == int(text)
    assert parsed > 15000  # the fast path covers most short numbers


@pytest.mark.parametrize("text, value", [("-0", 0.0), ("-0.0", -0.0), ("0e7", 0.0),
                                         ("-0e-3", -0.0), ("null", np.nan), ("1E2", 100.0),
                                         ("123456789012345678", 123456789012345678.0),
                                         ("0.000000000000000000001", 1e-21)])
def test_signed_zeros_null_and_long_integers_as_orjson_and_array_give_them(text, value):
    """What the one-pass decode makes of them: ``array('d', orjson.loads(...))``."""
    import array

    import orjson

    got = _parsed(text)
    truth = np.frombuffer(array.array("d", [np.nan if v is None else v
                                             for v in orjson.loads(f"[{text}]")]))[0]
    assert np.float64(got[0]).tobytes() == np.float64(truth).tobytes() == \
        np.float64(value).tobytes()


@pytest.mark.parametrize("text", ["01", "1.", ".5", "+1", "-", "1e", "1e+", "nul", "-null",
                                  "NaN", "Infinity", "true", '"1"', "[1]", "{}",
                                  "0.30000000000000004",  # 17 digits: past 2^53
                                  "1e23", "1.5e-400", "1234567890123456789"])
def test_numbers_outside_the_fast_path_or_json_are_declined(text):
    assert _parsed(text) is None


@pytest.mark.parametrize("blocks", [
    [b'{"t_ns": [5, 9], "fz": [1, -2.5e-3]}', b'{"t_ns": [], "fz": []}',
     b'{ "fz" : [ null ] , "t_ns" : [ 0 ] }\n'],           # keys in another order, spaces
    [b'{"t_ns": [20], "fz": [2]}', b'{"t_ns": [0, 10], "fz": [1.5, null]}'],  # out of order
    [b'{"t_ns": [0, 1], "true_fz": [-0, -0.0]}']])       # "true" in a key: checked path
def test_number_blocks_give_the_checked_arrays(blocks):
    from ingest.mcap_reader import _checked_blocks, _number_blocks

    fast, checked = _number_blocks(blocks), _checked_blocks(Path("run.mcap"), "/t", blocks)
    assert fast is not None
    assert fast.t_s.tobytes() == checked.t_s.tobytes()
    assert list(fast.fields) == list(checked.fields)
    for name, values in checked.fields.items():
        assert fast.fields[name].dtype == np.float64
        assert fast.fields[name].tobytes() == values.tobytes()


@pytest.mark.parametrize("blocks", [
    [b'{"t_ns": [0, 10], "fz": [0.30000000000000004, 2]}'],  # orjson's (_plain_blocks) then
    [b'{"t_ns": [0, 1e3], "fz": [1.5, 2]}'],                 # stamps not whole
    [b'{"t_ns": [0, 10], "fz": [1.5]}'],                     # lengths differ
    [b'{"t_ns": [0], "fz": [1], "fz": [2]}'],                # a key twice
    [b'{"t_ns": [0], "fz": [1]}', b'{"t_ns": [1], "fy": [1]}'],  # other keys
    [b'{"fz": [1]}'], [b'{}'], [b'[1]'], [b'{"t_ns": [0]} x'], [b'{"t_ns": [0]'],
    [b'{"t_\\u006es": [0], "fz": [1]}'], ['{"t_ns": [0], "f\u00e9": [1]}'.encode()],
    [b'{"t_ns": [-5], "fz": [1]}'], [b'{"t_ns": [0], "fz": [[1]]}'],
    [b'{"t_ns": [0], "fz": [1], "unit": "N"}']])
def test_number_blocks_decline_what_the_other_paths_decode_or_name(blocks):
    from ingest.mcap_reader import _number_blocks

    assert _number_blocks(blocks) is None
