"""The committed sample campaign: reproducible bit for bit, conforming to the raw-run
spec (read back with the plain ``mcap`` reader and ``json``, never swtlab's ingest),
and consistent with its truth files."""

from __future__ import annotations

import hashlib
import base64
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from mcap.reader import make_reader

from virtual_testbed.campaign import make_run, started_at, write_run
from virtual_testbed.law import self_propelled_slip
from virtual_testbed.sample_campaign import SAMPLE_TESTBED, SEED, sample_conditions

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data"
TOPICS = {
    "/hub/wrench": ["fx", "fy", "fz", "tx", "ty", "tz"],
    "/tether/force": ["dp"],
    "/wheel/encoder": ["angle"],
    "/sled/encoder": ["position"],
    "/tether/encoder": ["position"],
    "/suspension/angle": ["angle"],
}
RUN_KEYS = {"run_id", "campaign", "wheel", "soil", "multipass", "mode", "load_N", "velocity_mps",
            "gravity_mps2", "started_at"}
RADIUS_M = 0.125


def _truths() -> dict[str, dict]:
    return {p.stem: json.loads(p.read_text()) for p in sorted((SAMPLE / "truth").glob("*.json"))}


TRUTHS = _truths()


def _read_mcap(path: Path):
    """Blocks per topic, schemas/channels seen, metadata records."""
    blocks, channels, metadata = {}, {}, {}
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        for schema, channel, message in reader.iter_messages():
            channels[channel.topic] = (schema.encoding, json.loads(schema.data),
                                       channel.message_encoding)
            blocks.setdefault(channel.topic, []).append(json.loads(message.data))
        for record in reader.iter_metadata():
            metadata[record.name] = dict(record.metadata)
    return blocks, channels, metadata


def _check_track_photos(channel, messages, metadata, truth):
    """Spec: foxglove.CompressedImage JSON (timestamp, frame_id, format, base64 data), scale
    in swt.camera_track."""
    schema_encoding, schema, message_encoding = channel
    assert (schema_encoding, message_encoding) == ("jsonschema", "json")
    assert set(schema["required"]) == {"timestamp", "frame_id", "format", "data"}
    assert len(messages) == truth["count"]
    for message, t_ns in zip(messages, truth["t_ns"]):
        stamp = message["timestamp"]
        assert stamp["sec"] * 1_000_000_000 + stamp["nsec"] == t_ns
        assert message["format"] == "jpeg"
        image = cv2.imdecode(np.frombuffer(base64.b64decode(message["data"]), np.uint8),
                             cv2.IMREAD_GRAYSCALE)
        assert image is not None and image.shape == (600, 800)
    assert float(metadata["swt.camera_track"]["px_per_m"]) == truth["px_per_m"]


def _check_side_frames(images: list[tuple[int, bytes, str]], camera: dict, truth: dict):
    """Spec: ``/camera/side`` PNG frames timed inside the stable phase, ``swt.camera`` scale and
    travel direction; the frames are the render whose truth the truth file holds."""
    side = truth["side_camera"]
    assert [t for t, _, _ in images] == side["t_ns"]
    window = truth["stable_window"]
    assert window["start_s"] < side["t_ns"][0] / 1e9 < side["t_ns"][-1] / 1e9 < window["end_s"]
    for _, data, fmt in images:
        assert fmt == "png"
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
        assert image is not None and image.shape == tuple(side["scene"]["size_px"][::-1])
    assert float(camera["px_per_m"]) == side["scene"]["px_per_m"]
    assert camera["travel_direction"] == "+x"


def _columns(blocks: list[dict]) -> dict[str, np.ndarray]:
    return {k: np.concatenate([np.asarray(b[k]) for b in blocks]) for k in blocks[0]}


def _read_csv_run(folder: Path):
    meta = json.loads((folder / "run.json").read_text())
    channels = {}
    for topic, fields in TOPICS.items():
        path = folder / (topic.lstrip("/").replace("/", "_") + ".csv")
        if path.exists():
            header = path.read_text().splitlines()[0].split(",")
            assert header == ["t_s", *fields]
            data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
            channels[topic] = {"t_ns": np.round(data[:, 0] * 1e9).astype(np.int64),
                               **{f: data[:, i + 1] for i, f in enumerate(fields)}}
    return meta, channels


def _load(truth: dict):
    """(metadata as typed dict of records, channels) for either form."""
    path = SAMPLE / truth["raw_file"]
    if truth["form"] == "csv":
        return _read_csv_run(path)
    blocks, _, metadata = _read_mcap(path)
    return ({k.removeprefix("swt."): v for k, v in metadata.items()},
            {t: _columns(b) for t, b in blocks.items()})


def _sha256_tree(path: Path) -> dict[str, str]:
    files = [path] if path.is_file() else sorted(path.rglob("*"))
    return {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in files if f.is_file()}


def test_sample_contents_and_size():
    conditions = sample_conditions()
    assert len(conditions) == len(TRUTHS) == 60
    modes = [t["condition"]["mode"] for t in TRUTHS.values()]
    assert modes.count("towed") == 3 and modes.count("free_sled") == 3
    assert modes.count("steered") == 1
    series = {(t["condition"]["load_n"], t["condition"]["multipass"]) for t in TRUTHS.values()
              if t["condition"]["mode"] == "speed_control"}
    assert series == {(70.0, 0), (70.0, 1), (180.0, 0), (180.0, 1), (300.0, 0), (300.0, 1),
                      (120.0, 0)}
    slips = sorted(t["condition"]["slip_setpoint"] for t in TRUTHS.values()
                   if (t["condition"]["mode"], t["condition"]["load_n"],
                       t["condition"]["multipass"]) == ("speed_control", 180.0, 0))
    assert len(slips) == 8 and slips[0] == -0.10 and slips[-1] == 0.90
    forms = {t["form"] for t in TRUTHS.values()}
    assert forms == {"mcap", "csv"}
    total_bytes = sum(f.stat().st_size for f in SAMPLE.rglob("*") if f.is_file())
    assert total_bytes < 7_000_000  # "a few MB at most" (1.2 MB of it side-camera frames)
    photographed = [r for r, t in TRUTHS.items() if t.get("track_photos")]
    assert sorted(photographed) == ["L180_MP0_SC_s+010", "L180_MP0_SC_s+035",
                                    "L180_MP0_SC_s+060"]
    filmed = {r: t["form"] for r, t in TRUTHS.items() if t.get("side_camera")}
    assert filmed == {"L180_MP0_SC_s+035": "mcap", "L180_MP0_FS": "csv"}


@pytest.mark.parametrize("run_id", ["L180_MP0_SC_s+020", "L300_MP0_SC_s+090", "L070_MP0_TW",
                                    "L180_MP0_FS", "L180_MP0_SC_s+035"])
def test_regenerates_raw_bit_for_bit_and_truth_to_rounding(tmp_path, run_id):
    index, (condition, form) = next((i, cf) for i, cf in enumerate(sample_conditions())
                                    if cf[0].run_id == run_id)
    raw, truth = make_run(condition, SEED, started_at(SEED, index), SAMPLE_TESTBED, form)
    path = write_run(raw, truth, tmp_path)
    assert _sha256_tree(path) == _sha256_tree(SAMPLE / truth["raw_file"])
    # the truth's steady values come from the model's trigonometry and root finding, whose
    # last bits depend on NumPy's SIMD path (AVX2 and AVX-512 differ by ~1e-14 relative):
    # the same keys, texts and integers, floats to 1e-9
    _same_to_rounding(json.loads((tmp_path / "truth" / f"{run_id}.json").read_text()),
                      json.loads((SAMPLE / "truth" / f"{run_id}.json").read_text()))


def _same_to_rounding(a, b, where="truth"):
    assert type(a) is type(b), where
    if isinstance(a, dict):
        assert list(a) == list(b), where
        for k in a:
            _same_to_rounding(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same_to_rounding(x, y, f"{where}[{i}]")
    elif isinstance(a, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-12), where
    else:
        assert a == b, where


@pytest.mark.parametrize("run_id", [r for r, t in TRUTHS.items() if t["form"] == "mcap"])
def test_mcap_runs_follow_the_spec(run_id):
    blocks, channels, metadata = _read_mcap(SAMPLE / TRUTHS[run_id]["raw_file"])
    photos = TRUTHS[run_id].get("track_photos")
    filmed = "side_camera" in TRUTHS[run_id]
    assert set(channels) == (set(TOPICS) | ({"/camera/track"} if photos else set())
                             | ({"/camera/side"} if filmed else set()))
    if photos:
        _check_track_photos(channels.pop("/camera/track"), blocks.pop("/camera/track"),
                            metadata, photos)
    if filmed:
        schema_encoding, schema, message_encoding = channels.pop("/camera/side")
        assert (schema_encoding, message_encoding) == ("jsonschema", "json")
        assert set(schema["required"]) == {"timestamp", "frame_id", "format", "data"}
        _check_side_frames([(m["timestamp"]["sec"] * 1_000_000_000 + m["timestamp"]["nsec"],
                             base64.b64decode(m["data"]), m["format"])
                            for m in blocks.pop("/camera/side")],
                           metadata["swt.camera"], TRUTHS[run_id])
    for topic, (schema_encoding, schema, message_encoding) in channels.items():
        assert (schema_encoding, message_encoding) == ("jsonschema", "json")
        assert set(schema["required"]) == {"t_ns", *TOPICS[topic]}
        sizes = []
        for block in blocks[topic]:
            assert set(block) == {"t_ns", *TOPICS[topic]}
            lengths = {len(v) for v in block.values()}
            assert len(lengths) == 1
            assert all(isinstance(t, int) for t in block["t_ns"])
            sizes.append(lengths.pop())
        assert min(sizes) >= 1 and max(sizes) > 1
        t_ns = np.concatenate([b["t_ns"] for b in blocks[topic]])
        assert t_ns[0] >= 0 and np.all(np.diff(t_ns) > 0)
    assert any(len(b["t_ns"]) == 1 for bl in blocks.values() for b in bl)
    assert {"swt.run", "swt.wheel", "swt.suspension", "swt.zero"} <= set(metadata)
    assert all(isinstance(v, str) for rec in metadata.values() for v in rec.values())
    run = metadata["swt.run"]
    steered = run["mode"] == "steered"
    assert set(run) == RUN_KEYS | {"slip_setpoint"} | ({"steer_deg"} if steered else set())
    assert run["mode"] in ("speed_control", "steered") and int(run["multipass"]) in (0, 1)
    if steered:
        assert float(run["steer_deg"]) == TRUTHS[run_id]["condition"]["steer_deg"] == 10.0
    assert float(run["slip_setpoint"]) == TRUTHS[run_id]["condition"]["slip_setpoint"]
    assert metadata["swt.wheel"] == {"radius_m": "0.125", "width_m": "0.112", "grouser_count": "12",
                                     "grouser_height_m": "0.0092", "stiffness_N_per_mm": "30.0"}
    assert set(metadata["swt.zero"]) == {"fx", "fy", "fz", "tx", "ty", "tz"}
    if "swt.calibration" in metadata:
        assert set(metadata["swt.calibration"]) == {"/tether/force.dp.gain",
                                                    "/tether/force.dp.offset"}


@pytest.mark.parametrize("run_id", [r for r, t in TRUTHS.items() if t["form"] == "csv"])
def test_csv_runs_follow_the_spec(run_id):
    meta, channels = _read_csv_run(SAMPLE / TRUTHS[run_id]["raw_file"])
    mode = TRUTHS[run_id]["condition"]["mode"]
    filmed = "side_camera" in TRUTHS[run_id]
    assert set(meta) <= {"run", "wheel", "suspension", "zero", "calibration"} | (
        {"camera"} if filmed else set())
    if filmed:
        frames = sorted((SAMPLE / TRUTHS[run_id]["raw_file"] / "camera_side").iterdir(),
                        key=lambda f: int(f.stem))
        _check_side_frames([(int(f.stem), f.read_bytes(), f.suffix[1:]) for f in frames],
                           meta["camera"], TRUTHS[run_id])
    assert set(meta["run"]) == RUN_KEYS and meta["run"]["mode"] == mode
    assert isinstance(meta["run"]["load_N"], float)
    assert isinstance(meta["wheel"]["grouser_count"], int)
    expected = set(TOPICS) - ({"/tether/encoder"} if mode == "free_sled" else set())
    assert set(channels) == expected
    for channel in channels.values():
        assert np.all(np.diff(channel["t_ns"]) > 0)


def test_sample_has_sensor_effects():
    zero_fz, calibrated, dropped, spikes = [], 0, 0, 0
    for truth in TRUTHS.values():
        m = truth["measurement"]
        zero_fz.append(m["zero"]["fz"])
        calibrated += bool(m["calibration"])
        dropped += sum(c["samples_dropped"] for c in m["clocks"].values())
        spikes += len(m["gravel_spikes"]["t_s"])
        assert all(0 < abs(c["rate_error_ppm"]) <= 200 for c in m["clocks"].values())
    assert np.std(zero_fz) > 3.0
    assert 5 < calibrated < 40 and dropped > 1000 and spikes > 20


def _window(channel, truth, field):
    t_s = channel["t_ns"] / 1e9
    w = truth["stable_window"]
    keep = (t_s >= w["start_s"]) & (t_s <= w["end_s"])
    return t_s[keep], channel[field][keep].astype(float)


@pytest.mark.parametrize("run_id", ["L070_MP1_SC_s-010", "L120_MP0_SC_s+045", "L180_MP0_SC_s+020",
                                    "L300_MP0_SC_s+060", "L180_MP0_TW", "L300_MP0_FS"])
def test_raw_signals_average_to_the_truth(run_id):
    truth = TRUTHS[run_id]
    meta, ch = _load(truth)
    means = truth["stable_means"]
    _, dp = _window(ch["/tether/force"], truth, "dp")
    cal = meta.get("calibration", {})
    if cal:
        dp = float(cal["/tether/force.dp.gain"]) * dp + float(cal["/tether/force.dp.offset"])
    t_w, angle = _window(ch["/wheel/encoder"], truth, "angle")
    t_s, position = _window(ch["/sled/encoder"], truth, "position")
    omega, v = np.polyfit(t_w, angle, 1)[0], np.polyfit(t_s, position, 1)[0]
    slip = (RADIUS_M * omega - v) / max(RADIUS_M * omega, v)
    _, arm = _window(ch["/suspension/angle"], truth, "angle")
    sus = meta["suspension"]
    arm_m, zero_rad = float(sus["arm_length_m"]), float(sus["angle_zero_rad"])
    stiffness_n_per_m = 1000.0 * float(meta["wheel"]["stiffness_N_per_mm"])
    hub_height_m = arm_m * (np.sin(arm) - np.sin(zero_rad))
    _, ty = _window(ch["/hub/wrench"], truth, "ty")
    _, fz = _window(ch["/hub/wrench"], truth, "fz")
    assert dp.mean() == pytest.approx(means["dp_n"], abs=1.5)
    assert slip == pytest.approx(means["slip"], abs=1e-3)
    assert omega == pytest.approx(means["wheel_omega_radps"], rel=2e-3)
    load_n = fz.mean() - float(meta["zero"]["fz"])
    sinkage = -hub_height_m.mean() - load_n / stiffness_n_per_m  # spec, flexible wheel
    assert sinkage == pytest.approx(means["sinkage_m"], abs=1e-4)
    assert ty.mean() - float(meta["zero"]["ty"]) == pytest.approx(means["torque_nm"], abs=0.1)
    assert load_n == pytest.approx(means["wheel_load_n"], abs=1.5)


def test_stable_means_match_the_law():
    law = SAMPLE_TESTBED.law
    for truth in TRUTHS.values():
        if truth["stable_means"] is None:
            continue
        c, means = truth["condition"], truth["stable_means"]
        steady = law.evaluate(c["load_n"], means["slip"], c["multipass"], c["gravity_mps2"])
        load = c["load_n"]
        assert means["slip"] == pytest.approx(truth["law_steady"]["slip"], abs=1e-3)
        assert means["dp_n"] == pytest.approx(0.0 if c["mode"] == "free_sled" else steady["dp_n"],
                                              abs=0.01 * load)
        assert means["torque_nm"] == pytest.approx(steady["torque_nm"], abs=0.01 * load * RADIUS_M)
        assert means["sinkage_m"] == pytest.approx(steady["sinkage_m"], rel=0.01, abs=5e-5)
        assert means["wheel_load_n"] == pytest.approx(load, rel=0.005)
        assert means["motion_resistance_n"] == pytest.approx(means["thrust_n"] - means["dp_n"])


def test_no_stable_phase_runs_are_marked_and_collapse():
    digging = {r: t for r, t in TRUTHS.items() if t["stable_window"] is None}
    assert sorted(digging) == ["L180_MP0_SC_s+090", "L300_MP0_SC_s+090", "L300_MP1_SC_s+090"]
    for truth in digging.values():
        assert truth["stable_means"] is None and "dig-in" in truth["no_stable_phase_reason"]
        dig = truth["dig_in"]
        assert dig["dp_trend_end_n"] < 0.7 * dig["dp_trend_peak_n"]
        assert dig["sinkage_end_m"] > 2.0 * truth["law_steady"]["sinkage_m"]
        _, ch = _load(truth)
        t_s = ch["/hub/wrench"]["t_ns"] / 1e9
        fx = ch["/hub/wrench"]["fx"]
        early = fx[(t_s > 6) & (t_s < 12)].mean()
        late = fx[(t_s > 50) & (t_s < 56)].mean()
        assert late < early - 0.2 * truth["condition"]["load_n"]


def test_free_sled_settles_where_the_law_dp_is_zero():
    law = SAMPLE_TESTBED.law
    for truth in TRUTHS.values():
        c = truth["condition"]
        if c["mode"] != "free_sled":
            continue
        expected = self_propelled_slip(law, c["load_n"], c["multipass"], c["gravity_mps2"])
        assert truth["stable_means"]["slip"] == pytest.approx(expected, abs=1e-3)
        assert float(law.evaluate(c["load_n"], expected, 0)["dp_n"]) == pytest.approx(0.0, abs=1e-6)
        assert 0.01 < expected < 0.1


def test_towed_runs_pull_backwards():
    towed = [t for t in TRUTHS.values() if t["condition"]["mode"] == "towed"]
    assert len(towed) == 3
    for truth in towed:
        means = truth["stable_means"]
        assert means["dp_n"] < -0.05 * truth["condition"]["load_n"]
        assert abs(means["torque_nm"]) < 0.1 and means["slip"] < 0
        _, ch = _load(truth)
        _, dp = _window(ch["/tether/force"], truth, "dp")
        cal = truth["measurement"]["calibration"]
        if cal:
            dp = cal["/tether/force.dp.gain"] * dp + cal["/tether/force.dp.offset"]
        assert dp.mean() < -0.05 * truth["condition"]["load_n"]


@pytest.mark.parametrize("run_id", ["L070_MP0_SC_s+060", "L180_MP1_SC_s+090", "L120_MP0_SC_s+075"])
def test_grouser_frequency_is_visible_in_the_force_spectrum(run_id):
    truth = TRUTHS[run_id]
    _, ch = _load(truth)
    t_s, fx = _window(ch["/hub/wrench"], truth, "fx")
    rate_hz = 40.0
    t_u = np.arange(t_s[0], t_s[-1], 1.0 / rate_hz)
    f_u = np.interp(t_u, t_s, fx)
    f_u -= np.polyval(np.polyfit(t_u, f_u, 1), t_u)
    spectrum = np.abs(np.fft.rfft(f_u * np.hanning(f_u.size), 16 * f_u.size))
    freq_hz = np.fft.rfftfreq(16 * f_u.size, 1.0 / rate_hz)
    band = freq_hz > 0.05
    peak_hz = freq_hz[band][np.argmax(spectrum[band])]
    expected_hz = 12 * truth["stable_means"]["wheel_omega_radps"] / (2 * np.pi)
    assert truth["grouser_passing_frequency_hz"] == pytest.approx(expected_hz)
    assert peak_hz == pytest.approx(expected_hz, rel=0.03)
