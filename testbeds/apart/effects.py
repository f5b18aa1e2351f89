"""The testbed's effects: each one a family of shapes drawn per campaign (testbeds.apart.shapes),
sized from published ranges, and how each changes a condition's soil, contact or forces.

The six the gap diagnosis names (``swtlab gap``'s verdict vocabulary) and three outside them.
Ranges below are priors stated once here, never tuned on a bench seed.

Published anchors used for the sizes:

- Ding et al. 2011 (J. Terramech. 48(1):27-45, Fig. 9, 80 N, digitised in
  terramechanics/data/ding2011_80n.csv): the 10 mm lug wheel (h/r = 0.064, 30 lugs) pulls
  1.27-1.63 times the smooth rim's DP at s = 0.1-0.6 and sinks 1.5 times deeper at s = 0.6;
  the smooth rim sinks 3.5 times its rest sinkage at s = 0.6.
- Lyasko 2010 (J. Terramech. 47(1):21-31): slip-sinkage factor (1 + i)/(1 - 0.5 i), 2.3 at i = 0.6.
- Holm 1969 (J. Terramech. 6(3):47-71): later passes sink less and resist less; Wong 2008
  (Theory of Ground Vehicles, §2.4 and §2.5): a compacted soil reloads stiffer and shears
  with a hump (peak, then residual).
- Reece 1965: the frictional pressure term scales with the unit weight; Kobayashi et al.
  2010 (J. Terramech. 47(4):261-274) and Wong & Kobayashi 2012 (J. Terramech. 49(6)): at low
  gravity a wheel sinks more and slips more for its load.
- Rolling loss of deformable wheels on hard ground 0.01-0.035 of the load (Wong 2008, §1.2).
- Bulldozing: Rankine's passive wall ahead of the rut (Terzaghi 1943, Theoretical Soil
  Mechanics), half to three times it (Bekker 1969's blade is larger still).
"""

from __future__ import annotations

import math

import numpy as np

from testbeds.apart.shapes import draw_pchip, draw_power, evaluate
from testbeds.apart.soil import G0_MPS2, ReeceSoil

#: the diagnosis' vocabulary (its verdict names), in its order
SIX = ("grousers", "slip_sinkage", "reduced_gravity", "wheel_flexibility", "multipass",
       "bulldozing")
#: effects outside the six
OUTSIDE = ("soil_drift", "rig_artefact", "rate_effect")
#: the lug height ratio of Ding et al.'s 10 mm lug wheel, where the lug gain is sized
DING_LUG_HEIGHT_RATIO = 0.010 / 0.15735


def _log_uniform(rng, low, high) -> float:
    return float(math.exp(rng.uniform(math.log(low), math.log(high))))


def draw(effect: str, rng: np.random.Generator) -> dict:
    """The campaign's law of ``effect``: its drawn strengths and shapes (JSON-ready)."""
    if effect == "grousers":
        # gain of the shear stress at full slip on Ding's lug geometry: 0.15-0.6 gives DP
        # ratios lugged/smooth of 1.1-1.8 at s = 0.2-0.6 on Ding's wheel and soil at 80 N
        # (40 draws; Ding: 1.27-1.63; tests/test_apart_testbed.py)
        return {"gain_at_ding_geometry": float(rng.uniform(0.15, 0.6)),
                "height_exponent": float(rng.uniform(0.5, 1.2)),
                "count_saturation": float(rng.uniform(5.0, 20.0)),
                "slip_shape": draw_pchip(rng, start=float(rng.uniform(0.2, 0.6))),
                # lug-induced sinkage: softening 0-0.8 at full slip on Ding's geometry
                # (Ding's lug wheel: 1.5 times the smooth rim's sinkage at s = 0.6)
                "dig_at_ding_geometry": float(rng.uniform(0.0, 0.8)),
                "dig_shape": draw_power(rng, 1.0, 3.0)}
    if effect == "slip_sinkage":
        # stiffness / (1 + A M(|s|)): sinkage ratio at full slip about (1 + A)^(1/(n+1/2)),
        # 1.3-3.5 for n = 1 (Lyasko 2.3 at 0.6; Ding's smooth rim 3.5 at 0.6)
        return {"amplitude": _log_uniform(rng, 0.5, 5.0),
                "braked_ratio": float(rng.uniform(0.2, 1.0)),
                "slip_shape": draw_pchip(rng, start=0.0, breakpoints=int(rng.integers(1, 4)))}
    if effect == "reduced_gravity":
        # unit weight of the pressure term (g/g0)^a (Reece: a = 1); shear displacement to the
        # peak grows at low g by (g/g0)^-d (more slip for the load, Kobayashi et al. 2010)
        return {"unit_weight_exponent": float(rng.uniform(0.5, 1.3)),
                "shear_peak_exponent": float(rng.uniform(0.0, 0.4))}
    if effect == "wheel_flexibility":
        # true deflection: the declared stiffness off by a factor (lognormal 10 %), and a
        # load-deflection curve W^e (softening tread, e < 1); rolling loss 0.01-0.035 W
        return {"stiffness_factor": float(math.exp(rng.normal(0.0, 0.1))),
                "deflection_exponent": float(rng.uniform(0.7, 1.0)),
                "hysteresis_ratio": float(rng.uniform(0.01, 0.035)),
                "hysteresis_load_exponent": float(rng.uniform(-0.3, 0.3))}
    if effect == "multipass":
        # pass i >= 1: moduli x (1 + A i^b), n x (1 - d_n), phi + d_phi, K_w x (1 - d_K),
        # K_r x r (a hump appears: Wong 2008 §2.4)
        return {"stiffness_gain": float(rng.uniform(0.3, 2.0)),
                "pass_exponent": float(rng.uniform(0.5, 1.0)),
                "exponent_drop": float(rng.uniform(0.0, 0.3)),
                "friction_gain_deg": float(rng.uniform(0.0, 3.0)),
                "shear_peak_drop": float(rng.uniform(0.0, 0.4)),
                "residual_ratio_factor": float(rng.uniform(0.7, 1.0))}
    if effect == "bulldozing":
        # from half of Rankine's wall (the rim's front is inclined, not a wall) to three
        # times it
        return {"rankine_multiple": _log_uniform(rng, 0.5, 3.0),
                "depth_exponent": float(rng.uniform(-0.5, 0.8))}
    if effect == "soil_drift":
        # the bin loosens or compacts through the campaign, in run order
        return {"kphi_log_change": float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.6)),
                "friction_change_deg": float(rng.choice([-1, 1]) * rng.uniform(1.5, 4.0))}
    if effect == "rig_artefact":
        channel = str(rng.choice(["torque_crosstalk", "arm_compliance"]))
        if channel == "torque_crosstalk":  # torque cell reads chi W r more
            return {"channel": channel,
                    "ratio": float(rng.choice([-1, 1]) * rng.uniform(0.01, 0.03))}
        return {"channel": channel,  # suspension arm bends: the hub reads lower by c W
                "m_per_n": float(rng.uniform(2e-6, 1e-5))}
    if effect == "rate_effect":
        # resistance grows with travel speed: a W ln(v / v_ref) / ln(4)
        return {"resistance_ratio_at_4x": float(rng.uniform(0.02, 0.06))}
    raise ValueError(f"unknown effect {effect!r}")


def lug_terms(law: dict, grouser_count: int, grouser_height_m: float, radius_m: float,
              slip: float) -> tuple[float, float]:
    """``(shear gain g, stiffness divisor)`` of a lugged wheel at ``slip`` (1, 1 when smooth).
    Gain ``G (h/r / h_D)^a (1 - exp(-N/N0)) / (1 - exp(-30/N0)) M(|s|)`` (more and taller
    lugs pull more, saturating in their count), dig ``1 + D (h/r / h_D) M_d(s+)``."""
    if grouser_count <= 0 or grouser_height_m <= 0:
        return 1.0, 1.0
    height = grouser_height_m / radius_m / DING_LUG_HEIGHT_RATIO
    n0 = law["count_saturation"]
    count = (1 - math.exp(-grouser_count / n0)) / (1 - math.exp(-30 / n0))
    gain = (law["gain_at_ding_geometry"] * height ** law["height_exponent"] * count
            * float(evaluate(law["slip_shape"], abs(slip))))
    dig = 1 + law["dig_at_ding_geometry"] * height * float(evaluate(law["dig_shape"],
                                                                      max(slip, 0.0)))
    return 1.0 + gain, dig


def slip_sinkage_divisor(law: dict, slip: float) -> float:
    """Stiffness divisor ``1 + A M(|s|)`` (times the braked ratio for s < 0)."""
    scale = law["amplitude"] * (law["braked_ratio"] if slip < 0 else 1.0)
    return 1.0 + scale * float(evaluate(law["slip_shape"], abs(slip)))


def multipass_soil(law: dict, soil: ReeceSoil, passes: int) -> ReeceSoil:
    """The soil a wheel meets on its ``passes``-th rerun of a rut."""
    if passes <= 0:
        return soil
    gain = 1 + law["stiffness_gain"] * passes ** law["pass_exponent"]
    return soil.with_(kc_prime=soil.kc_prime * gain, kphi_prime=soil.kphi_prime * gain,
                      n=soil.n * (1 - law["exponent_drop"]),
                      friction_angle_deg=soil.friction_angle_deg + law["friction_gain_deg"],
                      shear_peak_m=soil.shear_peak_m * (1 - law["shear_peak_drop"]),
                      residual_ratio=max(0.3, soil.residual_ratio * law["residual_ratio_factor"]))


def gravity_soil(law: dict | None, soil: ReeceSoil, gravity_mps2: float) -> ReeceSoil:
    """Without the effect the soil does not feel gravity (unit weight at g0: gravity enters
    through the load only); with it, unit weight ``rho g0 (g/g0)^a``, ``K_w (g/g0)^-d``."""
    ratio = gravity_mps2 / G0_MPS2
    if law is None:
        return soil.with_(unit_weight_n_m3=soil.density_kg_m3 * G0_MPS2)
    return soil.with_(
        unit_weight_n_m3=soil.density_kg_m3 * G0_MPS2 * ratio ** law["unit_weight_exponent"],
        shear_peak_m=soil.shear_peak_m * ratio ** -law["shear_peak_exponent"])


def deflection_m(law: dict, stiffness_n_per_mm: float, load_n: float,
                 reference_load_n: float) -> float:
    """True deflection: the declared stiffness' deflection at ``reference_load_n`` scaled by
    the stiffness factor and ``(W / W_ref)^e``."""
    at_reference = reference_load_n / (1000 * stiffness_n_per_mm * law["stiffness_factor"])
    return at_reference * (load_n / reference_load_n) ** law["deflection_exponent"]


def hysteresis_torque_nm(law: dict, load_n: float, reference_load_n: float,
                         radius_m: float) -> float:
    """Rolling loss of the deforming tread, ``mu (W/W_ref)^h W r``, paid in drive torque."""
    mu = law["hysteresis_ratio"] * (load_n / reference_load_n) ** law["hysteresis_load_exponent"]
    return mu * load_n * radius_m


def bulldozing_n(law: dict, soil: ReeceSoil, sinkage_m: float, width_m: float,
                 gravity_mps2: float) -> float:
    """``C b (gamma z^2 N/2 + 2 c z sqrt(N)) (z / 10 mm)^q``, ``N = tan^2(45 + phi/2)``
    (Rankine's passive wall, Terzaghi 1943, times a drawn multiple and depth shape)."""
    z = max(sinkage_m, 0.0)
    n_phi = math.tan(math.radians(45 + soil.friction_angle_deg / 2)) ** 2
    gamma = soil.density_kg_m3 * gravity_mps2
    wall = width_m * (gamma * z * z * n_phi / 2 + 2 * soil.cohesion_pa * z * math.sqrt(n_phi))
    return law["rankine_multiple"] * wall * (max(z, 1e-6) / 0.01) ** law["depth_exponent"]


def rate_resistance_n(law: dict, load_n: float, velocity_mps: float,
                      reference_velocity_mps: float) -> float:
    """``a W ln(v / v_ref) / ln 4``: 0 at the reference speed."""
    return (law["resistance_ratio_at_4x"] * load_n
            * math.log(velocity_mps / reference_velocity_mps) / math.log(4.0))
