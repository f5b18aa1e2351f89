"""A campaign's hidden truth: its soil, its effects' drawn laws, and the steady values of each
run (testbeds.apart.solver with the effects of testbeds.apart.effects).

Order of the effects on one run: the run's prepared soil (campaign soil, per-run scatter,
drift), the rerun's compaction (multipass), gravity, slip-sinkage and the lugs' dig (both
divide the pressure moduli), the solve with the lugs' shear gain and the wheel's deflection;
then forces outside the contact integral: rolling loss (torque), bulldozing and the rate
effect (drawbar pull). A rig artefact changes only what a channel reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from testbeds.apart import effects as fx
from testbeds.apart.soil import G0_MPS2, ReeceSoil
from testbeds.apart.solver import Contact, solve

REFERENCE_VELOCITY_MPS = 0.01


@dataclass(frozen=True)
class WheelSpec:
    """A test wheel; ``stiffness_n_per_mm`` is the declared one, only on a flexible wheel."""

    name: str
    radius_m: float
    width_m: float
    grouser_count: int = 0
    grouser_height_m: float = 0.0
    stiffness_n_per_mm: float | None = None


@dataclass(frozen=True)
class RunSpec:
    """One run's condition as the physics sees it (``order``: 0..1 in the campaign's run
    order, for the soil drift)."""

    run_id: str
    wheel: WheelSpec
    load_n: float
    slip: float
    multipass: int = 0
    gravity_mps2: float = G0_MPS2
    velocity_mps: float = REFERENCE_VELOCITY_MPS
    order: float = 0.0


@dataclass
class Truth:
    """The campaign soil, the effects present (name -> drawn law) and the reference load of
    the load-dependent laws (the campaign's middle set load)."""

    soil: ReeceSoil
    effects: dict[str, dict] = field(default_factory=dict)
    reference_load_n: float = 100.0

    def prepared_soil(self, run: RunSpec, scatter: dict) -> ReeceSoil:
        """The bin as prepared for this run: scatter (``kphi_factor``, ``friction_deg``) and,
        with the soil-drift effect, the drift at the run's place in the order."""
        kphi, phi = scatter["kphi_factor"], scatter["friction_deg"]
        drift = self.effects.get("soil_drift")
        if drift:
            kphi *= math.exp(drift["kphi_log_change"] * (run.order - 0.5))
            phi += drift["friction_change_deg"] * (run.order - 0.5)
        s = self.soil
        return s.with_(kc_prime=s.kc_prime * kphi, kphi_prime=s.kphi_prime * kphi,
                       friction_angle_deg=s.friction_angle_deg + phi)

    def steady(self, run: RunSpec, scatter: dict) -> dict[str, float]:
        """True steady values of one run (SI): ``dp_n``, ``torque_nm``, ``sinkage_m`` (below
        the surface the wheel runs on) and the terms that made them."""
        e, w = self.effects, run.wheel
        soil = self.prepared_soil(run, scatter)
        if "multipass" in e:
            soil = fx.multipass_soil(e["multipass"], soil, run.multipass)
        soil = fx.gravity_soil(e.get("reduced_gravity"), soil, run.gravity_mps2)
        divisor = 1.0
        if "slip_sinkage" in e:
            divisor *= fx.slip_sinkage_divisor(e["slip_sinkage"], run.slip)
        gain = 1.0
        if "grousers" in e:
            gain, dig = fx.lug_terms(e["grousers"], w.grouser_count, w.grouser_height_m,
                                     w.radius_m, run.slip)
            divisor *= dig
        soil = soil.with_(kc_prime=soil.kc_prime / divisor, kphi_prime=soil.kphi_prime / divisor)
        deflection = 0.0
        if "wheel_flexibility" in e and w.stiffness_n_per_mm:
            deflection = fx.deflection_m(e["wheel_flexibility"], w.stiffness_n_per_mm,
                                         run.load_n, self.reference_load_n)
        contact = Contact(soil, w.radius_m, w.width_m, run.gravity_mps2, deflection, gain)
        out = solve(contact, run.load_n, run.slip)
        terms = {"deflection_m": deflection, "shear_gain": gain, "stiffness_divisor": divisor,
                 "hysteresis_torque_nm": 0.0, "bulldozing_n": 0.0, "rate_resistance_n": 0.0}
        if deflection > 0:
            terms["hysteresis_torque_nm"] = fx.hysteresis_torque_nm(
                e["wheel_flexibility"], run.load_n, self.reference_load_n, w.radius_m)
        if "bulldozing" in e:
            terms["bulldozing_n"] = fx.bulldozing_n(e["bulldozing"], soil, out["sinkage_m"],
                                                    w.width_m, run.gravity_mps2)
        if "rate_effect" in e:
            terms["rate_resistance_n"] = fx.rate_resistance_n(
                e["rate_effect"], run.load_n, run.velocity_mps, REFERENCE_VELOCITY_MPS)
        return {"dp_n": out["dp_n"] - terms["bulldozing_n"] - terms["rate_resistance_n"],
                "torque_nm": out["torque_nm"] + terms["hysteresis_torque_nm"],
                "sinkage_m": out["sinkage_m"], "theta1_rad": out["theta1_rad"], **terms,
                "soil": soil.to_dict()}

    def readings(self, run: RunSpec, steady: dict[str, float]) -> dict[str, float]:
        """What the rig's channels are driven with: the physics, plus a rig artefact, and the
        arm's view of a flexible wheel (the rig drops the hub by the declared ``W / k``; the
        true hub drops by sinkage + true deflection, so the difference goes to the sinkage
        channel, floored at 0)."""
        torque, sinkage = steady["torque_nm"], steady["sinkage_m"]
        w = run.wheel
        if w.stiffness_n_per_mm:
            sinkage += steady["deflection_m"] - run.load_n / (1000 * w.stiffness_n_per_mm)
        artefact = self.effects.get("rig_artefact")
        if artefact and artefact["channel"] == "torque_crosstalk":
            torque += artefact["ratio"] * run.load_n * w.radius_m
        if artefact and artefact["channel"] == "arm_compliance":
            sinkage += artefact["m_per_n"] * run.load_n
        return {"dp_n": steady["dp_n"], "torque_nm": torque, "sinkage_m": max(sinkage, 0.0)}
