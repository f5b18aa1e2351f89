"""Calibrate the base model's soil on measured points (no effect): bounded plain least squares
of Bekker k_phi and n, cohesion, friction angle and Janosi-Hanamoto K on the standardised
residuals of every measured quantity (a relative sinkage has its offset profiled out), so
that every slip counts, not only those the model can follow."""

from __future__ import annotations

import terramechanics as tm
from sim_gap.candidates import Candidate, Param
from sim_gap.fit import FitResult, fit_candidate, sigmas
from sim_gap.simulated import Simulated


def calibration_candidate(model: tm.WheelModel) -> Candidate:
    s = model.soil
    kphi = max(s.kphi, 1e3)
    return Candidate((), (
        Param("soil.kphi", kphi, kphi / 100, kphi * 100, True),
        Param("soil.n", s.n, 0.3, 2.0),
        Param("soil.cohesion_pa", max(s.cohesion_pa, 10.0), 0.0, 5e3),
        Param("soil.friction_angle_deg", s.friction_angle_deg, 15.0, 50.0),
        Param("soil.shear_modulus_m", s.shear_modulus_m, 1e-4, 0.1, True)))


SOIL_KEYS = ("kc", "kphi", "n", "cohesion_pa", "friction_angle_deg", "shear_modulus_m")


def calibrate_soil(points, model: tm.WheelModel, max_nfev: int = 200
                   ) -> tuple[tm.WheelModel, FitResult]:
    """The model with its soil fitted to ``points`` and the fit: the best of starts from the
    model's own soil and each literature set of ``terramechanics.SOILS`` (the fit has
    several local minima)."""
    sig = sigmas(points, model.wheel.radius_m)
    best = None
    for soil in [model.soil, *tm.SOILS.values()]:
        start = model.with_soil(**{k: getattr(soil, k) for k in SOIL_KEYS})
        fit = fit_candidate(Simulated(start), calibration_candidate(start), points, sig,
                            max_nfev=max_nfev, loss="linear")
        if best is None or fit.chi2 < best[1].chi2:
            best = start.with_parameters(fit.values), fit
    return best
