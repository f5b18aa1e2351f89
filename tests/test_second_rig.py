"""The second rig itself (validation/second_rig): its shapes against closed forms, its files
against the raw-run spec, and its sensor effects as stated.

- Closed forms (independent): the second-order step response against Ogata's overshoot and
  peak time; the shark-fin wave's mean and RMS by numerical integration; AR(1) lag-one
  correlation, 1/f slope and random-walk variance against their definitions.
- Spec form: MCAP read with the ``mcap`` library's reader, CSV with the standard library,
  not through swtlab's ingest.
- Round trip (in-family with ingest, the reader under test elsewhere): with every sensor
  effect off but zero offsets and a DP logged in mV, the files read back the truth; with the
  default sensors the rest readings before and after the drive show the drift the truth
  records, so a pipeline could re-zero.
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from mcap.reader import make_reader

import ingest
from validation.second_rig import (Rig, RunCondition, SecondRigError, SensorModel,
                                   WheelGeometry, write_campaign)
from validation.second_rig.sensors import drift, pink_noise, sample_clock
from validation.second_rig.signals import ar1, fin_wave, step_response

QUIET = SensorModel(force_ar_sd_n=0, force_pink_sd_n=0, torque_ar_sd_nm=0, torque_pink_sd_nm=0,
                    dp_ar_sd_n=0, dp_pink_sd_n=0, arm_noise_sd_rad=0, drift_walk_n_per_sqrt_s=0,
                    drift_rate_max_n_per_s=0, torque_drift_walk_nm_per_sqrt_s=0,
                    torque_drift_rate_max_nm_per_s=0, zero_reading_sd_n=0,
                    zero_reading_sd_nm=0, gain_rel_u=0, dp_offset_u_n=0, dp_raw_ratio=1.0,
                    clock_ppm_max=0, clock_jitter_s=0, dropped_fraction=0, spike_rate_per_s=0)


def constant_law(condition: RunCondition) -> dict[str, float]:
    """Fixed steady values (a table-like law): DP 40 % of the load, torque 5 N m."""
    slip = condition.slip_setpoint if condition.slip_setpoint is not None else 0.1
    return {"slip": slip, "travel_velocity_mps": condition.velocity_mps,
            "wheel_load_n": condition.load_n, "dp_n": 0.4 * condition.load_n,
            "torque_nm": 5.0, "sinkage_m": 0.006}


def test_step_response_overshoot_and_peak_time_match_the_closed_form():
    zeta, settle_s = 0.4, 20.0
    t = np.linspace(0, settle_s, 200001)
    y = step_response(t, zeta, settle_s)
    sigma = math.log(1e4) / settle_s
    wd = sigma / zeta * math.sqrt(1 - zeta**2)
    # Ogata (2010) eqs. 5-20, 5-21: t_p = pi/wd, M_p = exp(-zeta pi / sqrt(1 - zeta^2))
    assert y.max() - 1 == pytest.approx(math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2)),
                                        rel=1e-6)
    assert t[np.argmax(y)] == pytest.approx(math.pi / wd, abs=2e-4)
    assert abs(y[-1] - 1) <= 1e-4 / math.sqrt(1 - zeta**2)
    assert step_response(np.array([-1.0, 0.0]), zeta, settle_s).tolist() == [0.0, 0.0]


def test_fin_wave_has_zero_mean_and_unit_rms_over_a_pitch():
    u = (np.arange(400000) + 0.5) / 400000
    for decay in (0.1, 0.3, 0.8):
        w = fin_wave(u, decay)
        assert abs(w.mean()) < 1e-9 and math.sqrt((w**2).mean()) == pytest.approx(1, rel=1e-6)
        assert w.argmax() == u.size - 1  # rises through the pitch, drops at the next grouser


def test_coloured_noise_and_drift_follow_their_definitions():
    rng = np.random.default_rng(5)
    dt, tau = 0.01, 0.2
    x = ar1(400000, dt, tau, 0.3, rng)
    assert np.corrcoef(x[:-1], x[1:])[0, 1] == pytest.approx(math.exp(-dt / tau), abs=3e-3)
    assert x.std() == pytest.approx(0.3, rel=0.03)
    n, slopes = 4096, []
    for _ in range(40):
        p = np.abs(np.fft.rfft(pink_noise(n, 1.0, rng))[1:n // 4]) ** 2
        f = np.arange(1, n // 4)
        slopes.append(np.polyfit(np.log(f), np.log(p), 1)[0])
    assert np.mean(slopes) == pytest.approx(-1.0, abs=0.1)
    t = np.array([0.0, 40.0])
    ends = np.array([drift(t, 60.0, 0.05, 0.0, rng) for _ in range(3000)])
    assert ends[:, 0].var() == pytest.approx(0.05**2 * 60, rel=0.1)
    assert ends[:, 1].var() == pytest.approx(0.05**2 * 100, rel=0.1)
    assert drift(t, 60.0, 0.0, 0.01, rng).tolist() == pytest.approx([0.6, 1.0])



def test_clock_never_logs_a_sample_before_the_logger_starts():
    # jitter clipped at 0.3 of a period: without the floor at 0 the first sample falls
    # before 0 whenever the phase is smaller than its jitter (an MCAP log time is unsigned)
    sensor = SensorModel(clock_jitter_s=1.0, dropped_fraction=0.0)
    rng = np.random.default_rng(2)
    firsts = [sample_clock(120.0, 2.0, sensor, rng)[1][0] for _ in range(200)]
    assert min(firsts) == 0 and sum(f == 0 for f in firsts) > 20

@pytest.fixture(scope="module")
def two_forms(tmp_path_factory):
    out = tmp_path_factory.mktemp("rig_forms")
    runs = [RunCondition("sc", "speed_control", 150.0, 0.3),
            RunCondition("fs", "free_sled", 150.0,
                         wheel=WheelGeometry(stiffness_n_per_mm=20.0))]
    write_campaign(out, runs, constant_law, seed=3, form={"fs": "csv"})
    return out


def test_mcap_form_follows_the_spec(two_forms):
    with open(two_forms / "campaign" / "sc.mcap", "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert {c.message_encoding for c in summary.channels.values()} == {"json"}
        assert {s.encoding for s in summary.schemas.values()} == {"jsonschema"}
        last, sizes = {}, set()
        for _, channel, message in reader.iter_messages(log_time_order=False):
            block = json.loads(message.data)
            lengths = {len(v) for v in block.values()}
            assert len(lengths) == 1 and all(isinstance(t, int) for t in block["t_ns"])
            assert np.all(np.diff(block["t_ns"]) > 0)
            assert block["t_ns"][0] > last.get(channel.topic, -1)
            last[channel.topic] = block["t_ns"][-1]
            sizes |= lengths
        assert set(last) == {"/hub/wrench", "/tether/force", "/wheel/encoder", "/sled/encoder",
                             "/tether/encoder", "/suspension/angle"}
        assert 1 in sizes and max(sizes) > 20  # blocks of one sample and long blocks
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
    assert meta["swt.run"]["mode"] == "speed_control" and meta["swt.run"]["slip_setpoint"] == "0.3"
    assert set(meta["swt.zero"]) == {"fx", "fy", "fz", "tx", "ty", "tz"}
    assert {"arm_length_m", "angle_zero_rad"} == set(meta["swt.suspension"])
    assert not (two_forms / "campaign" / "sc.json").exists()
    assert sorted(p.name for p in (two_forms / "truth").iterdir()) == ["fs.json", "sc.json"]


def test_csv_form_follows_the_spec(two_forms):
    folder = two_forms / "campaign" / "fs"
    meta = json.loads((folder / "run.json").read_text())
    assert meta["run"]["mode"] == "free_sled" and "slip_setpoint" not in meta["run"]
    assert meta["wheel"]["stiffness_N_per_mm"] == 20.0 and meta["run"]["load_N"] == 150.0
    assert sorted(p.name for p in folder.glob("*.csv")) == [
        "hub_wrench.csv", "sled_encoder.csv", "suspension_angle.csv", "tether_force.csv",
        "wheel_encoder.csv"]  # free sled: no tether encoder
    with open(folder / "hub_wrench.csv") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t_s", "fx", "fy", "fz", "tx", "ty", "tz"]
    t = np.array([float(r[0]) for r in rows[1:]])
    assert np.all(np.diff(t) > 0) and len(rows) > 5000


def test_same_seed_same_bytes_and_a_run_does_not_depend_on_the_others(tmp_path):
    runs = [RunCondition(f"r{i}", "speed_control", 100.0 + 50 * i, 0.2) for i in range(3)]
    write_campaign(tmp_path / "a", runs, constant_law, seed=9)
    write_campaign(tmp_path / "b", runs[1:2], constant_law, seed=9)
    a = (tmp_path / "a" / "campaign" / "r1.mcap").read_bytes()
    assert a == (tmp_path / "b" / "campaign" / "r1.mcap").read_bytes()
    write_campaign(tmp_path / "c", runs[1:2], constant_law, seed=10)
    assert a != (tmp_path / "c" / "campaign" / "r1.mcap").read_bytes()
    assert not (tmp_path / "a" / ".staging").exists()


def test_quiet_sensors_read_back_the_truth_through_zero_and_calibration(tmp_path):
    """Offsets in the wrench (undone by swt.zero) and DP logged in mV (gain and offset)."""
    run = RunCondition("q", "speed_control", 200.0, 0.25)
    write_campaign(tmp_path, [run], constant_law, seed=4, rig=Rig(sensors=QUIET))
    truth = json.loads((tmp_path / "truth" / "q.json").read_text())
    assert truth["measurement"]["dp_logged_in"] == "mV"
    assert max(abs(v) for v in truth["measurement"]["zero_offset"].values()) > 1.0
    read = ingest.read_run(tmp_path / "campaign" / "q.mcap")
    start, end = truth["window"]["start_s"], truth["window"]["end_s"]
    means = truth["window_means"]

    def window_mean(topic: str, column: str) -> float:
        s = read.streams[topic]
        inside = (s["t_s"] >= start) & (s["t_s"] < end)
        return float(s.loc[inside, column].mean())

    # sampled means of the grouser wave over whole periods: within 0.2 % of the load
    assert window_mean("/tether/force", "dp_n") == pytest.approx(means["dp_n"], abs=0.4)
    assert window_mean("/hub/wrench", "fz_n") == pytest.approx(means["wheel_load_n"], abs=0.4)
    assert window_mean("/hub/wrench", "ty_nm") == pytest.approx(means["torque_nm"], abs=0.05)
    rest = read.streams["/tether/force"]["t_s"] < truth["timeline"]["motion_start_s"]
    assert float(read.streams["/tether/force"].loc[rest, "dp_n"].abs().max()) < 0.02
    ch = read.channels
    inside = (ch["t_s"] >= start) & (ch["t_s"] < end)
    arm_step_m = QUIET.arm_length_m * 2 * math.pi / QUIET.arm_counts_per_rev
    assert float(ch.loc[inside, "sinkage_m"].mean()) == pytest.approx(means["sinkage_m"],
                                                                      abs=arm_step_m)


def test_rest_readings_show_the_drift_since_zeroing(tmp_path):
    runs = [RunCondition(f"d{i}", "speed_control", 150.0, 0.2) for i in range(4)]
    write_campaign(tmp_path, runs, constant_law, seed=12, form={"d1": "csv"})
    for run in runs:
        truth = json.loads((tmp_path / "truth" / f"{run.run_id}.json").read_text())
        meas, tl = truth["measurement"], truth["timeline"]
        path = tmp_path / "campaign" / (run.run_id + ("" if run.run_id == "d1" else ".mcap"))
        s = ingest.read_run(path).streams["/tether/force"]
        before = s.loc[s["t_s"] < tl["motion_start_s"], "dp_n"].mean()
        after = s.loc[s["t_s"] >= tl["motion_end_s"], "dp_n"].mean()
        offset = meas["dp_offset_error_n"]
        # noise over ~3 s of rest: AR(1) 0.2 N (tau 0.08 s) plus 1/f 0.06 N
        assert before == pytest.approx(meas["drift_rest_before"]["/tether/force.dp"] + offset,
                                       abs=0.25)
        assert after == pytest.approx(meas["drift_rest_after"]["/tether/force.dp"] + offset,
                                      abs=0.25)


def test_bad_input_gives_one_line_errors(tmp_path):
    with pytest.raises(SecondRigError, match="mode 'steered'"):
        RunCondition("x", "steered", 100.0, 0.1)
    with pytest.raises(SecondRigError, match="slip_setpoint"):
        RunCondition("x", "towed", 100.0, 0.1)
    with pytest.raises(SecondRigError, match="lacks"):
        write_campaign(tmp_path, [RunCondition("x", "towed", 100.0)], lambda c: {"slip": 0.0},
                       seed=1)
    with pytest.raises(SecondRigError, match="no row"):
        write_campaign(tmp_path, [RunCondition("x", "towed", 100.0)], {}, seed=1)
    with pytest.raises(SecondRigError, match="duplicate"):
        write_campaign(tmp_path, [RunCondition("x", "towed", 100.0)] * 2, constant_law, seed=1)
    with pytest.raises(SecondRigError, match="unknown form"):
        write_campaign(tmp_path, [RunCondition("x", "towed", 100.0)], constant_law, seed=1,
                       form="hdf5")


def test_ingest_reads_the_specs_calibration_uncertainty_keys(tmp_path):
    sensors = SensorModel(write_calibration_uncertainty=True, dp_raw_ratio=1.0)
    write_campaign(tmp_path, [RunCondition("u", "speed_control", 150.0, 0.2)], constant_law,
                   seed=2, rig=Rig(sensors=sensors))
    run = ingest.read_run(tmp_path / "campaign" / "u.mcap")
    u = run.metadata.calibration_u
    assert u[("/tether/force", "dp")] == (sensors.gain_rel_u, sensors.dp_offset_u_n)
    assert u[("/hub/wrench", "fz")][0] == sensors.gain_rel_u


def test_low_speed_mode_logs_a_14_bit_wheel_encoder_and_the_sled_at_500_hz(tmp_path):
    """``low_speed_rig``: at 10 mm/s with the set slip 0.05 the wheel (r 0.1 m) turns
    0.105 rad/s, 0.55 counts of 2 pi/16384 a sample at 500 Hz; the files say so (read with
    the standard library), and the rest of the rig is unchanged."""
    from validation.second_rig import low_speed_rig

    write_campaign(tmp_path, [RunCondition("slow", "speed_control", 150.0, 0.05)],
                   constant_law, seed=4, form="csv", rig=low_speed_rig(Rig(sensors=QUIET)))
    folder = tmp_path / "campaign" / "slow"

    def column(name: str, index: int) -> tuple[np.ndarray, np.ndarray]:
        with open(folder / name) as f:
            rows = list(csv.reader(f))[1:]
        return (np.array([float(r[0]) for r in rows]), np.array([float(r[index]) for r in rows]))

    t, angle = column("wheel_encoder.csv", 1)
    assert 1 / np.median(np.diff(t)) == pytest.approx(500.0, rel=1e-3)
    counts = angle / (2 * math.pi / 2**14)
    assert np.allclose(counts, np.round(counts), atol=1e-4)   # the file's decimal digits
    counts = np.round(counts)
    moving = (t > 30.0) & (t < 45.0)
    per_sample = np.diff(counts[moving])
    assert set(np.unique(per_sample)) <= {0.0, 1.0}
    assert per_sample.mean() == pytest.approx(0.01 / 0.95 / 0.1 / 500 / (2 * math.pi / 2**14),
                                              rel=0.01)
    t_sled, _ = column("sled_encoder.csv", 1)
    assert 1 / np.median(np.diff(t_sled)) == pytest.approx(500.0, rel=1e-3)
    t_wrench, _ = column("hub_wrench.csv", 1)
    assert 1 / np.median(np.diff(t_wrench)) == pytest.approx(120.0, rel=1e-3)
