"""The single-wheel model: wheel, soil, gravity and the effects switched on.

Forces of the Wong-Reece stress distribution (Wong & Reece 1967; Wong, Theory of
Ground Vehicles 2008, ch. 2), angles from the vertical, positive forward::

    Fz = b int (r_c sigma cos(t) + r_s tau sin(t)) dt
    DP = b int (r_s tau cos(t) - r_c sigma sin(t)) dt
    T  = (r - delta + lambda h) b r_s int tau dt

over [theta_2, theta_1]; r_c is the contact radius (r for a rigid wheel), r_s the
shear radius (r_c + lambda h with grousers). The sinkage solves W = Fz.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace

import numpy as np

from terramechanics import slip_soil_ding2015, stress
from terramechanics.effects import EFFECTS, LAWS, SOIL_ORDER, Effect, make_effect
from terramechanics.equilibrium import solve_increasing
from terramechanics.soil import SoilParams
from terramechanics.state import (EARTH_GRAVITY_MPS2, Condition, Contact, Geometry,
                                  SoilState)
from terramechanics.wheel import Wheel

CONVERGED_REL = 1e-3  # |W - Fz| < 0.1 % W
#: the braked (and towed) branch, s < 0: Wong & Reece 1967 part II (transition angle, flow
#: zone), or part I's laws at the signed kinematic slip ``i = 1 - v/(r omega) = s/(1 + s)``
#: (:mod:`terramechanics.stress`)
BRAKED_LAWS = ("wong_reece1967", "signed_slip")


@dataclass(frozen=True)
class WheelModel:
    """Rigid-wheel terramechanics model; ``effects`` maps effect name -> parameters."""

    wheel: Wheel
    soil: SoilParams
    gravity_mps2: float = EARTH_GRAVITY_MPS2
    effects: dict[str, Effect] = field(default_factory=dict)
    braked_law: str = BRAKED_LAWS[0]

    def __post_init__(self) -> None:
        if self.braked_law not in BRAKED_LAWS:
            raise ValueError(f"braked_law {self.braked_law!r}: one of {list(BRAKED_LAWS)}")
        unknown = set(self.effects) - set(EFFECTS)
        if unknown:
            raise KeyError(f"unknown effect(s) {sorted(unknown)}; known: {sorted(EFFECTS)}")
        ordered = {name: self.effects[name] for name in EFFECTS if name in self.effects}
        object.__setattr__(self, "effects", ordered)

    # -- switching effects and parameters -------------------------------------------------
    def with_effects(self, **changes: bool | dict | Effect | None) -> WheelModel:
        """Switch effects: ``True`` on (current or default parameters), ``False``/``None``
        off, a dict of parameters (merged into the current ones; a ``"law"`` key picks
        another law of the effect, with its defaults for what the dict does not name)
        or an ``Effect``."""
        effects = dict(self.effects)
        for name, change in changes.items():
            if change is None or change is False:
                effects.pop(name, None)
            elif change is True:
                effects[name] = effects.get(name) or make_effect(name)
            elif isinstance(change, Effect):
                effects[name] = change
            elif "law" in change and change["law"] != getattr(effects.get(name), "law", None):
                effects[name] = make_effect(name, **change)
            else:
                current = effects.get(name) or make_effect(name, change.get("law"))
                effects[name] = replace(current, **{k: v for k, v in change.items()
                                                    if k != "law"})
        return replace(self, effects=effects)

    def with_soil(self, **changes: float) -> WheelModel:
        return replace(self, soil=replace(self.soil, **changes))

    def with_wheel(self, **changes: float) -> WheelModel:
        return replace(self, wheel=replace(self.wheel, **changes))

    def parameters(self) -> dict[str, float]:
        """Every numeric parameter under a dotted name (``soil.kphi``,
        ``effects.grousers.shear_radius_factor``, ``gravity_mps2``)."""
        out: dict[str, float] = {"gravity_mps2": self.gravity_mps2}
        for prefix, obj in [("wheel", self.wheel), ("soil", self.soil)] + [
                (f"effects.{name}", eff) for name, eff in self.effects.items()]:
            for f in dataclasses.fields(obj):
                value = getattr(obj, f.name)
                if isinstance(value, (int, float)) and not isinstance(value, bool):
                    out[f"{prefix}.{f.name}"] = value
        return out

    def with_parameters(self, values: dict[str, float]) -> WheelModel:
        """A copy with dotted-name parameters changed (see :meth:`parameters`); naming
        ``effects.<name>.<param>`` switches that effect on."""
        model = self
        for key, value in values.items():
            head, _, rest = key.partition(".")
            if key == "gravity_mps2":
                model = replace(model, gravity_mps2=float(value))
            elif head == "soil":
                model = model.with_soil(**{rest: value})
            elif head == "wheel":
                model = model.with_wheel(**{rest: value})
            elif head == "effects" and "." in rest:
                name, _, param = rest.partition(".")
                model = model.with_effects(**{name: {param: value}})
            else:
                raise KeyError(f"unknown parameter {key!r}")
        return model

    # -- evaluation --------------------------------------------------------------------------
    def curves(self, load_n, slip, multipass=0, gravity_mps2=None) -> dict[str, np.ndarray]:
        """Wheel performance at every (load, slip, multipass, gravity), broadcast together.

        Inputs: wheel load W (N) at the model's (or the given) gravity, slip (driving
        ``(r w - v)/(r w)`` >= 0, skid ``(r w - v)/v`` in [-1, 0)), multipass index
        (previous passes; acts with the ``multipass`` effect), gravity (m/s^2; acts
        with ``reduced_gravity``). Outputs (SI): ``dp_n``, ``torque_nm``,
        ``sinkage_m``, ``resistance_n = T/r - DP``, ``thrust_n``,
        ``compaction_resistance_n``, ``fz_n``, ``fz_residual_n = W - Fz``,
        ``converged``, ``theta1_rad``, ``theta2_rad``, ``thetam_rad`` and the named
        terms of every effect (zero where off).
        """
        g = self.gravity_mps2 if gravity_mps2 is None else gravity_mps2
        arrays = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                       for x in (load_n, slip, multipass, g)))
        if np.any(arrays[0] <= 0):
            raise ValueError("load_n must be > 0")
        if np.any(arrays[1] < -1):
            raise ValueError("slip must be >= -1 (a locked wheel)")
        shape = arrays[0].shape
        cond = Condition(*(a.ravel().copy() for a in arrays))  # flat: the solve picks elements
        soil, geo = self._soil_state(cond), self._base_geometry(cond)
        for name in SOIL_ORDER:
            if name in self.effects:
                soil = self.effects[name].soil(soil, cond, self.wheel)
        for effect in self.effects.values():  # geometry sees the soil all effects made
            geo = effect.geometry(geo, soil, cond, self.wheel)
        contact_forces = _ContactForces(soil, geo, cond, self.braked_law)
        sinkage, residual = solve_increasing(contact_forces.fz_n,
                                             np.full(cond.slip.shape, self.wheel.radius_m),
                                             cond.load_n, np.maximum(contact_forces.n, 0.0) + 0.5)
        out = contact_forces(sinkage)
        contact = Contact(sinkage, out["theta1_rad"], out["theta2_rad"], out["thetam_rad"],
                          out.pop("exit_shear_displacement_m"))
        terms = {t: np.zeros(cond.slip.shape)
                 for laws in LAWS.values() for cls in laws.values() for t in cls.terms}
        dp, torque = out.pop("dp_soil_n"), out.pop("torque_soil_nm")
        for effect in self.effects.values():
            extra = effect.forces(contact, soil, geo, cond, self.wheel)
            dp, torque = dp + extra.dp_n, torque + extra.torque_nm
            terms.update(extra.terms)
        result = {
            "load_n": cond.load_n, "slip": cond.slip, "multipass": cond.multipass,
            "gravity_mps2": cond.gravity_mps2, "dp_n": dp, "torque_nm": torque,
            "sinkage_m": sinkage, "resistance_n": torque / self.wheel.radius_m - dp,
            "thrust_n": out["thrust_n"],
            "compaction_resistance_n": out["compaction_resistance_n"],
            "fz_n": out["fz_n"], "fz_residual_n": -residual,
            "converged": np.abs(residual) < CONVERGED_REL * cond.load_n,
            "theta1_rad": out["theta1_rad"], "theta2_rad": out["theta2_rad"],
            "thetam_rad": out["thetam_rad"], **terms,
        }
        return {name: np.reshape(values, shape) for name, values in result.items()}

    def _soil_state(self, cond: Condition) -> SoilState:
        s, shape = self.soil, cond.slip.shape
        full = lambda v: np.full(shape, float(v))  # noqa: E731
        return SoilState(kc=full(s.kc), kphi=full(s.kphi), n0=full(s.n), n_slope=full(0.0),
                         n_skid_slope=full(0.0),
                         cohesion_pa=full(s.cohesion_pa),
                         phi_rad=full(np.radians(s.friction_angle_deg)),
                         shear_modulus_m=slip_soil_ding2015.shear_modulus_m(
                             s.shear_modulus_m, s.shear_modulus_slip_m, cond.slip),
                         unit_weight_n_m3=full(s.density_kg_m3 * EARTH_GRAVITY_MPS2),
                         c1=full(s.c1), c2=full(s.c2),
                         c3=slip_soil_ding2015.exit_angle_coefficient(s.c3, s.c4, cond.slip))

    def _base_geometry(self, cond: Condition) -> Geometry:
        zeros = np.zeros(cond.slip.shape)
        return Geometry(self.wheel.radius_m, self.wheel.width_m, zeros, zeros)


class _ContactForces:
    """Stress integrals at a trial sinkage, for fixed soil state, geometry and condition."""

    def __init__(self, soil: SoilState, geo: Geometry, cond: Condition,
                 braked_law: str = BRAKED_LAWS[0]) -> None:
        b = geo.width_m
        self.soil, self.geo, self.cond, self.width = soil, geo, cond, b
        self.braked_law = braked_law
        self.k_reece = (soil.kc / b + soil.kphi) * b ** soil.n0
        self.slip = cond.slip
        if braked_law == "signed_slip":  # part I throughout, at the kinematic slip
            self.skid = np.zeros(cond.slip.shape, dtype=bool)
            self.driven_slip = stress.kinematic_slip(cond.slip)
        else:
            self.skid = cond.slip < 0
            self.driven_slip = np.maximum(cond.slip, 0.0)
        # Ding et al. 2011 N = n0 + n1 s driving; n0 + n2 |s| braked (Pavlov & Johnson's
        # CMU model, robomechanics/3d-terramechanics sigma.m)
        slope = np.where(cond.slip < 0, soil.n_skid_slope, soil.n_slope)
        self.n = soil.n0 + slope * np.abs(cond.slip)

    def _stresses(self, sinkage_m: np.ndarray) -> dict[str, np.ndarray]:
        """Contact angles, the Gauss grid and the stresses on it at a trial sinkage."""
        soil, geo = self.soil, self.geo
        r_c = geo.contact_radius_m(sinkage_m)
        r_s = r_c + geo.shear_offset_m
        theta1 = np.arccos(np.clip(1.0 - sinkage_m / r_c, -1.0, 1.0))
        theta2 = 0.0 - soil.c3 * theta1  # 0.0 - : no -0.0 in the output
        # part I (driven): theta_m = (c1 + c2 s) theta_1; part II (braked, towed): the
        # normal stress peaks at the transition angle, where the shear changes sign
        thetat = np.clip(stress.transition_angle(self.slip, soil.phi_rad), theta2, theta1)
        thetam = np.where(self.skid, thetat, stress.max_stress_angle(
            theta1, theta2, self.driven_slip, soil.c1, soil.c2))
        (rear, w_rear), (front, w_front) = (stress.region_grid(theta2, thetam),
                                            stress.region_grid(thetam, theta1))
        theta = np.concatenate([rear, front], axis=-1)
        cos_theta, sin_theta = np.cos(theta), np.sin(theta)
        sigma = stress.normal_stress(rear, cos_theta[..., rear.shape[-1]:], theta1, theta2,
                                     thetam, self.k_reece, self.n, r_c, self.width)
        j = self._shear_displacement(theta, sin_theta, theta1, thetat, r_s)
        tau = stress.shear_stress(sigma, j, soil.cohesion_pa, soil.phi_rad, soil.shear_modulus_m)
        return {"r_c": r_c, "r_s": r_s, "theta1": theta1, "theta2": theta2, "thetat": thetat,
                "thetam": thetam, "theta": theta, "cos_theta": cos_theta, "sin_theta": sin_theta,
                "sigma": sigma, "tau": tau, "weights": np.concatenate([w_rear, w_front], axis=-1)}

    @staticmethod
    def _fz(st: dict[str, np.ndarray], width_m: float) -> np.ndarray:
        return width_m * (st["r_c"] * _integral(st["sigma"] * st["cos_theta"], st)
                          + st["r_s"] * _integral(st["tau"] * st["sin_theta"], st))

    def fz_n(self, sinkage_m: np.ndarray, at: np.ndarray | None = None) -> np.ndarray:
        """The vertical soil force alone (what the sinkage solve needs), at the conditions
        ``at`` (indices; None: all)."""
        forces = self if at is None else _ContactForces(
            *(_elements(state, at) for state in (self.soil, self.geo, self.cond)),
            self.braked_law)
        return forces._fz(forces._stresses(sinkage_m), forces.width)

    def __call__(self, sinkage_m: np.ndarray) -> dict[str, np.ndarray]:
        st, geo, b = self._stresses(sinkage_m), self.geo, self.width
        r_c, r_s, tau = st["r_c"], st["r_s"], st["tau"]
        thrust = b * r_s * _integral(tau * st["cos_theta"], st)
        compaction = b * r_c * _integral(st["sigma"] * st["sin_theta"], st)
        exit_angle = st["theta2"][..., None]
        j_exit = self._shear_displacement(exit_angle, np.sin(exit_angle), st["theta1"],
                                          st["thetat"], r_s)[..., 0]
        return {
            "fz_n": self._fz(st, b),
            "dp_soil_n": thrust - compaction,
            "torque_soil_nm": ((geo.arm_radius_m + geo.shear_offset_m) * b * r_s
                               * _integral(tau, st)),
            "thrust_n": thrust, "compaction_resistance_n": compaction,
            "theta1_rad": st["theta1"], "theta2_rad": st["theta2"], "thetam_rad": st["thetam"],
            "exit_shear_displacement_m": j_exit,
        }

    def _shear_displacement(self, theta, sin_theta, theta1, thetat, r_s):
        """j (m): part I for driven, part II for braked or towed conditions (part I at the
        kinematic slip for every condition under the ``signed_slip`` braked law)."""
        if not self.skid.any():  # only the branch the conditions need (most campaigns: one)
            return stress.shear_displacement(theta, sin_theta, theta1, r_s, self.driven_slip)
        braked = stress.skid_shear_displacement(theta, sin_theta, theta1, thetat, r_s,
                                                np.minimum(self.slip, 0.0))
        if self.skid.all():
            return braked
        driven = stress.shear_displacement(theta, sin_theta, theta1, r_s, self.driven_slip)
        return np.where(self.skid[..., None], braked, driven)


def _elements(state, at: np.ndarray):
    """``state`` (a dataclass of per-condition arrays, 1-D) at the conditions ``at``."""
    return replace(state, **{f.name: value[at] for f in dataclasses.fields(state)
                             if np.ndim(value := getattr(state, f.name)) == 1})


def _integral(f: np.ndarray, st: dict[str, np.ndarray]) -> np.ndarray:
    """Gauss quadrature of ``f`` over the contact (the grid of ``_ContactForces._stresses``)."""
    return np.sum(f * st["weights"], axis=-1)
