"""The committed sample campaign: a BB2-like wheel on one sandy soil.

``python -m virtual_testbed.sample_campaign --out sample_data --seed 20260``
rewrites ``sample_data/`` bit for bit. Contents (see docs/virtual-testbed.md):

- speed control, loads 70/180/300 N, multipass 0 and 1, 8 slips from -10 % to
  90 % each (MCAP form);
- a 120 N validation series, multipass 0, 5 slips between the others (MCAP form);
- one towed and one free-sled run per load, multipass 0 (CSV form);
- one steered run, 180 N, slip 0.2 at a 10 degree slip angle (MCAP form);
- a photo of the track (``/camera/track``) after three 180 N runs (slip 10, 35, 60 %);
- side-camera frames (``/camera/side``) of the soil flow under the wheel in the stable phase
  of two 180 N runs: slip 35 % (MCAP) and the free sled (CSV).
"""

from __future__ import annotations

import argparse
import shutil
from dataclasses import replace
from pathlib import Path

from virtual_testbed.campaign import Testbed, generate_campaign
from virtual_testbed.conditions import RunCondition
from virtual_testbed.sensors import Rates, SensorModel

SEED = 20260
LOADS_N = (70.0, 180.0, 300.0)
MULTIPASSES = (0, 1)
SLIPS = (-0.10, 0.0, 0.05, 0.10, 0.20, 0.35, 0.60, 0.90)
#: runs whose track is photographed after the run (image slip beside encoder slip)
PHOTOGRAPHED = {(180.0, 0, 0.10), (180.0, 0, 0.35), (180.0, 0, 0.60)}
#: runs filmed by the side camera (soil flow), and how many frames each (6 keep the sample small)
FILMED = ("L180_MP0_SC_s+035", "L180_MP0_FS")
SIDE_CAMERA_FRAMES = 6
VALIDATION_LOAD_N = 120.0
VALIDATION_SLIPS = (-0.05, 0.03, 0.15, 0.45, 0.75)
#: Modest rates keep the committed sample small; the grouser frequency is below 2 Hz.
SAMPLE_RATES = Rates(wrench_hz=40.0, dp_hz=40.0, wheel_encoder_hz=20.0, sled_encoder_hz=20.0,
                     tether_encoder_hz=10.0, suspension_hz=10.0)
#: A logger with a millisecond clock.
SAMPLE_TESTBED = Testbed(campaign="bb2_sand_sample", soil="ES-3-like sand", rates=SAMPLE_RATES,
                         sensors=SensorModel(clock_resolution_ns=1_000_000))


def run_id(load_n: float, multipass: int, mode: str, slip: float | None = None) -> str:
    """``L180_MP0_SC_s+020``: load, multipass, mode tag and slip in percent."""
    tag = {"speed_control": "SC", "free_sled": "FS", "towed": "TW", "steered": "ST"}[mode]
    slip_tag = "" if slip is None else f"_s{round(slip * 100):+04d}"
    return f"L{load_n:03.0f}_MP{multipass}_{tag}{slip_tag}"


def sample_conditions() -> list[tuple[RunCondition, str]]:
    """Every sample run with its form, in campaign order."""
    runs = []
    for load in LOADS_N:
        for mp in MULTIPASSES:
            runs += [(RunCondition.of(run_id(load, mp, "speed_control", s), "speed_control", load,
                                      mp, s, track_photos=int((load, mp, s) in PHOTOGRAPHED)),
                      "mcap") for s in SLIPS]
    runs += [(RunCondition.of(run_id(VALIDATION_LOAD_N, 0, "speed_control", s), "speed_control",
                              VALIDATION_LOAD_N, 0, s), "mcap") for s in VALIDATION_SLIPS]
    for load in LOADS_N:
        runs += [(RunCondition.of(run_id(load, 0, mode), mode, load, 0), "csv")
                 for mode in ("towed", "free_sled")]
    runs.append((RunCondition.of(run_id(180.0, 0, "steered", 0.2) + "_b10", "steered", 180.0, 0,
                                 0.2, steer_deg=10.0), "mcap"))
    return [(replace(c, side_camera_frames=SIDE_CAMERA_FRAMES) if c.run_id in FILMED else c, form)
            for c, form in runs]


def generate_sample(out_dir: Path, seed: int = SEED) -> None:
    """Rewrite the sample campaign in ``out_dir`` (replacing its ``campaign/`` and ``truth/``)."""
    for sub in ("campaign", "truth"):
        shutil.rmtree(out_dir / sub, ignore_errors=True)
    runs = sample_conditions()
    generate_campaign(out_dir, [c for c, _ in runs], seed,
                      form={c.run_id: f for c, f in runs}, testbed=SAMPLE_TESTBED)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m virtual_testbed.sample_campaign",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("sample_data"))
    parser.add_argument("--seed", type=int, default=SEED)
    args = parser.parse_args(argv)
    generate_sample(args.out, args.seed)


if __name__ == "__main__":
    main()
