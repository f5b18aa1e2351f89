"""Whether a campaign's design can tell each of its effects from its absence, judged by an
oracle that knows every law of the truth: the scorer's answer to "where the design can tell
them apart" (issue 36), computed from the generator's physics alone, never from a verdict.

For an effect ``e`` of the truth ``T``, each run's readings with and without it,
``delta = y_T - y_{T without e}``, are whitened by that run's noise: the per-run soil
preparation scatter the campaign drew (``scatter_sd``: moduli and friction angle, carried to
DP, torque and sinkage through the testbed's own solver, so the three readings of one run
share it) plus the rig's measurement noise of a run mean
(:class:`validation.second_rig.SensorModel`), both taken without the effect. The campaign
soil is unknown to any analyst, so the part of ``delta`` that a change of the campaign soil
(the five parameters :func:`testbeds.apart.campaign.draw_soil` moves) can mimic is projected
out, to first order::

    D_e = || (I - P_J) L^-1 delta ||^2,   P_J the projection on the whitened soil Jacobian

In a linear-Gaussian model with the nuisance soil profiled out, ``D_e / 2`` is the expected
log-likelihood ratio of ``T`` over ``T without e`` on data made by ``T`` (Kullback-Leibler
divergence of two Gaussians of equal covariance). The verdict names a hypothesis at
posterior 0.9 (docs/gap-report.md): from even prior odds, the oracle reaches odds of 9 on
average only when ``D_e / 2 >= ln 9``, so :data:`TELLABLE_D` is ``2 ln 9 = 4.39``. An effect
below it cannot be told from its absence by this design even with the true laws, so no
diagnosis can be asked to name it; the oracle holds the other effects at their true laws,
which is kinder than any diagnosis can be (it must fit their strengths too).
"""

from __future__ import annotations

import math

import numpy as np

from testbeds.apart.campaign import draw_campaign
from testbeds.apart.effects import SIX
from testbeds.apart.soil import ReeceSoil
from testbeds.apart.solver import NoEquilibrium
from testbeds.apart.truth import Truth
from validation.second_rig import SensorModel

#: the verdict's bar (0.9) as an oracle's expected evidence from even odds: 2 ln(0.9 / 0.1)
TELLABLE_D = 2 * math.log(9.0)
QUANTITIES = ("dp_n", "torque_nm", "sinkage_m")
#: steady window of a run in the testbed's timeline (testbeds.apart.campaign.STEADY_S)
_STEADY_S = 14.5


def _measurement_sd(values: np.ndarray, sensors: SensorModel) -> np.ndarray:
    """Standard deviation of a run mean per quantity: the AR(1) noise over the steady window
    (``sd sqrt(2 tau / T)``), the zero reading and the gain's relative uncertainty; sinkage:
    the arm's angle noise times its length, the same way."""
    shrink = math.sqrt(2 * sensors.noise_tau_s / _STEADY_S)
    dp = math.hypot(sensors.dp_ar_sd_n * shrink, sensors.zero_reading_sd_n)
    torque = math.hypot(sensors.torque_ar_sd_nm * shrink, sensors.zero_reading_sd_nm)
    sinkage = sensors.arm_noise_sd_rad * sensors.arm_length_m * shrink
    floor = np.array([dp, torque, sinkage])
    return np.hypot(floor, sensors.gain_rel_u * np.abs(values))


def _soil_steps(soil: ReeceSoil) -> list[tuple[ReeceSoil, ReeceSoil, float]]:
    """Central-difference pairs over the campaign soil's unknowns (those
    :func:`testbeds.apart.campaign.draw_soil` moves), each with its step's width."""
    def scaled(h):
        return (soil.with_(kc_prime=soil.kc_prime * math.exp(h),
                           kphi_prime=soil.kphi_prime * math.exp(h)))
    pairs = [(scaled(0.05), scaled(-0.05), 0.1),
             (soil.with_(cohesion_pa=soil.cohesion_pa * math.exp(0.05)),
              soil.with_(cohesion_pa=soil.cohesion_pa * math.exp(-0.05)), 0.1),
             (soil.with_(friction_angle_deg=soil.friction_angle_deg + 0.2),
              soil.with_(friction_angle_deg=soil.friction_angle_deg - 0.2), 0.4),
             (soil.with_(shear_peak_m=soil.shear_peak_m * math.exp(0.05)),
              soil.with_(shear_peak_m=soil.shear_peak_m * math.exp(-0.05)), 0.1)]
    low, high = max(0.3, soil.residual_ratio - 0.02), min(1.0, soil.residual_ratio + 0.02)
    pairs.append((soil.with_(residual_ratio=high), soil.with_(residual_ratio=low), high - low))
    return pairs


def _readings(truth: Truth, run, scatter: dict) -> np.ndarray:
    reading = truth.readings(run, truth.steady(run, scatter))
    return np.array([reading[q] for q in QUANTITIES])


def effect_distances(seed: int, index: int) -> dict[str, float]:
    """``D_e`` of each effect of the six in campaign ``index`` of ``seed``."""
    return distances(draw_campaign(seed, index))


def distances(drawn: dict) -> dict[str, float]:
    """``D_e`` of each effect of the six in a drawn campaign
    (:func:`testbeds.apart.campaign.draw_campaign`; module docstring); a run the wheel cannot
    carry without the effect, or at a soil step, is left out."""
    truth: Truth = drawn["truth"]
    sd = drawn["scatter_sd"]
    sensors = SensorModel()
    out = {}
    for effect in (e for e in SIX if e in truth.effects):
        without = Truth(truth.soil, {k: v for k, v in truth.effects.items() if k != effect},
                        truth.reference_load_n)
        steps = [(Truth(hi, without.effects, truth.reference_load_n),
                  Truth(lo, without.effects, truth.reference_load_n), width)
                 for hi, lo, width in _soil_steps(truth.soil)]
        whitened, jacobian = [], []
        for row in drawn["rows"]:
            run, scatter = row["run"], row["scatter"]
            try:
                base = _readings(without, run, scatter)
                soil_cols = [(_readings(hi, run, scatter) - _readings(lo, run, scatter)) / width
                             for hi, lo, width in steps]
                k_hi = _readings(without, run, {**scatter, "kphi_factor":
                                                scatter["kphi_factor"] * math.exp(0.05)})
                k_lo = _readings(without, run, {**scatter, "kphi_factor":
                                                scatter["kphi_factor"] * math.exp(-0.05)})
                f_hi = _readings(without, run, {**scatter,
                                                "friction_deg": scatter["friction_deg"] + 0.2})
                f_lo = _readings(without, run, {**scatter,
                                                "friction_deg": scatter["friction_deg"] - 0.2})
            except NoEquilibrium:
                continue
            scatter_cols = np.column_stack([(k_hi - k_lo) / 0.1 * sd["kphi_log_sd"],
                                            (f_hi - f_lo) / 0.4 * sd["friction_sd_deg"]])
            measured = _measurement_sd(base, sensors)
            cov = scatter_cols @ scatter_cols.T + np.diag(measured ** 2)
            chol = np.linalg.cholesky(cov)
            delta = np.array([row["readings"][q] for q in QUANTITIES]) - base
            whitened.append(np.linalg.solve(chol, delta))
            jacobian.append(np.linalg.solve(chol, np.column_stack(soil_cols)))
        if not whitened:
            out[effect] = 0.0
            continue
        w, jac = np.concatenate(whitened), np.vstack(jacobian)
        fitted = jac @ np.linalg.lstsq(jac, w, rcond=None)[0]
        out[effect] = float(np.sum((w - fitted) ** 2))
    return out


def tellable(distances: dict[str, float]) -> bool:
    """Whether every effect of the truth can be told from its absence (:data:`TELLABLE_D`);
    a truth with no effect of the six is always tellable."""
    return all(d >= TELLABLE_D for d in distances.values())
