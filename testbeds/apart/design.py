"""What a lab runs: the wheel(s), set loads, slips from braked to high driving, replicates,
and the multipass, gravity or speed levels where an effect needs them (and, as often, where
it does not, so the design does not give the truth away).

Per campaign: three set loads spanning about 3.3x (the diagnosis' load-varying laws need
three); six slips (-0.2, 0, 0.1, 0.25, 0.45, 0.7, each but 0 moved by up to 0.02); two
conditions run three times; a second multipass or gravity level at four slips per load; a
smooth twin of a lugged wheel on the same bin at two loads and five slips; 22-56 runs.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from testbeds.apart.soil import G0_MPS2
from testbeds.apart.truth import REFERENCE_VELOCITY_MPS, RunSpec, WheelSpec

BASE_SLIPS = (-0.2, 0.0, 0.1, 0.25, 0.45, 0.7)
#: the slips (indices of BASE_SLIPS) run at a second multipass or gravity level
LEVEL_SLIPS = (1, 3, 4, 5)
#: the smooth twin's slips and loads (indices)
TWIN_SLIPS = (0, 1, 2, 3, 5)
TWIN_LOADS = (0, 2)
FAST_VELOCITY_MPS = 0.03
#: probability of a level the truth has no effect for (multipass, gravity, speed)
SPARE_LEVEL = {"multipass": 0.2, "gravity": 0.15, "velocity": 0.25}


@dataclass(frozen=True)
class Plan:
    """The campaign's test plan: wheels, loads, slips, levels, runs (in run order)."""

    wheel: WheelSpec
    twin: WheelSpec | None
    loads_n: tuple[float, ...]
    slips: tuple[float, ...]
    multipass: tuple[int, ...]
    gravity_mps2: tuple[float, ...]
    velocities_mps: tuple[float, ...]
    runs: tuple[tuple[str, RunSpec], ...]   # (source: "main" | "smooth", run)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["runs"] = [{"source": source, **asdict(run)} for source, run in self.runs]
        return d


def draw_wheel(rng: np.random.Generator, name: str, lugged: bool, flexible: bool,
               middle_load_n: float) -> WheelSpec:
    """Radius 90-160 mm, width 70-150 mm; lugs 8-36 of 3-10 % of the radius; a flexible
    wheel declares the stiffness that deflects it 2-5 % of its radius at the middle load."""
    radius = round(float(rng.uniform(0.09, 0.16)), 3)
    width = round(float(rng.uniform(0.07, 0.15)), 3)
    count, height = 0, 0.0
    if lugged:
        count = int(rng.integers(8, 37))
        height = round(radius * float(rng.uniform(0.03, 0.10)) * 2000) / 2000
    stiffness = None
    if flexible:
        ratio = float(rng.uniform(0.02, 0.05))
        stiffness = round(middle_load_n / (1000 * ratio * radius) * 2) / 2
    return WheelSpec(name, radius, width, count, height, stiffness)


def draw_plan(rng: np.random.Generator, name: str, effects: set[str]) -> Plan:
    """The lab's plan for a campaign whose truth holds ``effects``."""
    low = round(float(rng.uniform(40.0, 80.0)))
    loads = (low, round(low * float(rng.uniform(1.8, 2.2))),
             round(low * float(rng.uniform(3.0, 3.6))))
    lugged = "grousers" in effects
    wheel = draw_wheel(rng, f"{name}_wheel", lugged, "wheel_flexibility" in effects, loads[1])
    twin = None
    if lugged and rng.random() < 0.5:
        twin = WheelSpec(f"{name}_smooth", wheel.radius_m, wheel.width_m, 0, 0.0,
                         wheel.stiffness_n_per_mm)
    slips = tuple(s if s == 0 else round(s + float(rng.uniform(-0.02, 0.02)), 3)
                  for s in BASE_SLIPS)
    multipass = (0, 1) if ("multipass" in effects
                           or rng.random() < SPARE_LEVEL["multipass"]) else (0,)
    low_g = float(rng.choice([3.71, 1.62]))
    gravity = (G0_MPS2, low_g) if ("reduced_gravity" in effects
                                   or rng.random() < SPARE_LEVEL["gravity"]) else (G0_MPS2,)
    fast = "rate_effect" in effects or rng.random() < SPARE_LEVEL["velocity"]
    velocities = (REFERENCE_VELOCITY_MPS, FAST_VELOCITY_MPS) if fast else (REFERENCE_VELOCITY_MPS,)

    runs: list[tuple[str, dict]] = []
    for load in loads:
        fast_slips = set(rng.choice(len(slips), size=len(slips) // 2, replace=False).tolist())
        for si, slip in enumerate(slips):
            v = FAST_VELOCITY_MPS if fast and si in fast_slips else REFERENCE_VELOCITY_MPS
            runs.append(("main", {"wheel": wheel, "load_n": load, "slip": slip, "velocity_mps": v}))
    for k in rng.choice(len(runs), size=2, replace=False):
        runs += [runs[int(k)]] * 2
    for level in multipass[1:]:
        runs += [("main", {"wheel": wheel, "load_n": load, "slip": slips[si], "multipass": level})
                 for load in loads for si in LEVEL_SLIPS]
    for g in gravity[1:]:
        runs += [("main", {"wheel": wheel, "load_n": load, "slip": slips[si], "gravity_mps2": g})
                 for load in loads for si in LEVEL_SLIPS]
    if twin:
        runs += [("smooth", {"wheel": twin, "load_n": loads[li], "slip": slips[si]})
                 for li in TWIN_LOADS for si in TWIN_SLIPS]
    order = rng.permutation(len(runs))
    specs = []
    counters = {"main": 0, "smooth": 0}
    for rank, i in enumerate(order):
        source, kw = runs[int(i)]
        tag = "S" if source == "smooth" else "L" if lugged else "W"
        run_id = f"{name}{tag}_r{counters[source]:03d}"
        counters[source] += 1
        specs.append((source, RunSpec(run_id=run_id, order=rank / max(len(runs) - 1, 1), **kw)))
    return Plan(wheel, twin, loads, slips, multipass, gravity, velocities, tuple(specs))
