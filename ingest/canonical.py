"""Canonical channel names (docs/channels.md) and which ones can stand in for which."""

from __future__ import annotations

WRENCH_COLUMNS = {"fx": "fx_n", "fy": "fy_n", "fz": "fz_n",
                  "tx": "tx_nm", "ty": "ty_nm", "tz": "tz_nm"}

#: measured channels of the spec form; True = required there
MEASURED: dict[str, bool] = {
    **{c: True for c in WRENCH_COLUMNS.values()},
    "dp_n": True, "wheel_angle_rad": True, "sled_position_m": True,
    "tether_position_m": False, "suspension_angle_rad": True,
}

#: rate/height channels a channel map may feed directly instead of angles and positions
DIRECT: tuple[str, ...] = ("wheel_surface_speed_mps", "wheel_omega_radps",
                           "sled_velocity_mps", "hub_height_m")

#: a required measured channel is covered when the map feeds one of these instead
SUBSTITUTES: dict[str, tuple[str, ...]] = {
    "wheel_angle_rad": ("wheel_omega_radps", "wheel_surface_speed_mps"),
    "sled_position_m": ("sled_velocity_mps",),
    "suspension_angle_rad": ("hub_height_m",),
}

DERIVED: tuple[str, ...] = ("wheel_omega_radps", "wheel_surface_speed_mps", "sled_velocity_mps",
                            "slip", "hub_height_m", "sinkage_m")

CANONICAL: tuple[str, ...] = tuple(MEASURED) + DIRECT

#: what the stable phase gates on (``stable_phase.gate``: the wheel's and the sled's speeds),
#: each with the channels a source may give it from
STABLE_PHASE_NEEDS: dict[str, tuple[str, ...]] = {
    "wheel_surface_speed_mps": ("wheel_angle_rad", "wheel_omega_radps", "wheel_surface_speed_mps"),
    "sled_velocity_mps": ("sled_position_m", "sled_velocity_mps"),
}
