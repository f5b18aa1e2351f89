"""Typed, validated run metadata (spec: "Metadata records").

Records arrive as ``{record: {key: value}}`` with the ``swt.`` prefix dropped;
values are strings (MCAP metadata) or JSON numbers (CSV ``run.json``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any, Callable, Literal, Mapping, overload

from ingest.errors import IngestError, Problem
from swtlab_base.domain import G0_MPS2, MODES, TestCondition, Wheel
from swtlab_base.domain.ranges import METADATA

#: longest text of a bad value an error message quotes
MAX_SHOWN_CHARS = 40
WRENCH_FIELDS = ("fx", "fy", "fz", "tx", "ty", "tz")
RECORDS = ("run", "wheel", "suspension", "camera", "camera_track", "zero", "calibration")
#: where the spec's MCAP form keeps a record (errors name the form of the user's file)
SPEC_FORM = "the swt.{record} metadata record"

_RUN_KEYS = {"run_id", "campaign", "wheel", "soil", "multipass", "mode", "load_N",
             "slip_setpoint", "velocity_mps", "gravity_mps2", "steer_deg", "started_at",
             "wheel_surface_speed_setpoint_mps"}
_WHEEL_KEYS = {"radius_m", "width_m", "grouser_count", "grouser_height_m",
               "stiffness_N_per_mm", "mass_kg"}
_SUSPENSION_KEYS = {"arm_length_m", "angle_zero_rad"}
_CAMERA_KEYS = {"px_per_m", "travel_direction", "wheel_center_px", "wheel_radius_px"}


@dataclass(frozen=True)
class RunInfo:
    """``swt.run``: which run, of which campaign, wheel and soil, and its set point
    ``condition`` (the spec's ``load_N`` is its ``load_set_n``, ``velocity_mps`` its
    ``velocity_set_mps``)."""

    run_id: str
    campaign: str
    wheel: str
    soil: str
    condition: TestCondition
    started_at: datetime | None = None
    #: set wheel surface speed r*omega, for rigs that impose it instead of slip (channel map)
    wheel_surface_speed_setpoint_mps: float | None = None


@dataclass(frozen=True)
class SuspensionInfo:
    """``swt.suspension``: h = arm_length_m * (sin(angle) - sin(angle_zero_rad))."""

    arm_length_m: float
    angle_zero_rad: float


@dataclass(frozen=True)
class CameraInfo:
    """``swt.camera`` (side camera riding on the sled)."""

    px_per_m: float
    travel_direction: str = "+x"
    wheel_center_px: tuple[float, float] | None = None
    wheel_radius_px: float | None = None


@dataclass(frozen=True)
class CameraTrackInfo:
    """``swt.camera_track`` (top view of the track)."""

    px_per_m: float


@dataclass(frozen=True)
class RunMetadata:
    """All metadata records of one run, typed and checked against each other."""

    run: RunInfo
    wheel: Wheel
    suspension: SuspensionInfo | None = None
    camera: CameraInfo | None = None
    camera_track: CameraTrackInfo | None = None
    zero: dict[str, float] = field(default_factory=dict)
    calibration: dict[tuple[str, str], tuple[float, float]] = field(default_factory=dict)
    #: (topic, field) -> (relative standard uncertainty of the gain, standard uncertainty of
    #: the offset in SI units), where ``swt.calibration`` states them (0 where it states one)
    calibration_u: dict[tuple[str, str], tuple[float, float]] = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Plain JSON-ready dict (datetimes as ISO strings, calibration keys as 'topic.field')."""
        from dataclasses import asdict

        out: dict[str, Any] = {"run": _run_record(self.run)}
        for name in ("wheel", "suspension", "camera", "camera_track"):
            part = getattr(self, name)
            out[name] = None if part is None else asdict(part)
        out["zero"] = dict(self.zero)
        out["calibration"] = {f"{t}.{f}": {"gain": g, "offset": o}
                              for (t, f), (g, o) in self.calibration.items()}
        out["calibration_u"] = {f"{t}.{f}": {"gain_rel_u": g, "offset_u": o}
                                for (t, f), (g, o) in self.calibration_u.items()}
        return out


def _shown(value: Any) -> str:
    """``repr`` of a bad value for an error line, cut to :data:`MAX_SHOWN_CHARS`."""
    text = repr(value) if not isinstance(value, int) or abs(value) < 10**30 else "a huge integer"
    return text if len(text) <= MAX_SHOWN_CHARS else text[:MAX_SHOWN_CHARS - 3] + "..."


class _Reader:
    """Typed access to one record; every failure is an IngestError naming record.key."""

    def __init__(self, path: Path, name: str, values: Mapping[str, Any], form: str = SPEC_FORM):
        self.path, self.name, self.values, self.form = path, name, values, form

    def fail(self, key: str, problem: str) -> IngestError:
        return IngestError(self.path, f"swt.{self.name}.{key}", problem)

    def _get(self, key: str, required: bool, conv: Callable[[Any], Any], kind: str):
        value = self.values.get(key)
        if value is None or (isinstance(value, str) and not value.strip()):
            if required:
                raise self.fail(key, f"missing; add {self.name}.{key} to "
                                     f"{self.form.format(record=self.name)}")
            return None
        if isinstance(value, (bool, list, dict)):
            raise self.fail(key, f"{_shown(value)} is not {kind}")
        try:
            return conv(value)
        except (TypeError, ValueError, OverflowError):
            raise self.fail(key, f"{_shown(value)} is not {kind}") from None

    @overload
    def text(self, key: str, required: Literal[True] = True) -> str: ...
    @overload
    def text(self, key: str, required: Literal[False]) -> str | None: ...
    @overload
    def text(self, key: str, required: bool) -> str | None: ...

    def text(self, key: str, required: bool = True) -> str | None:
        return self._get(key, required, lambda v: str(v).strip(), "text")

    @overload
    def number(self, key: str, required: Literal[True] = True) -> float: ...
    @overload
    def number(self, key: str, required: Literal[False]) -> float | None: ...
    @overload
    def number(self, key: str, required: bool) -> float | None: ...

    def number(self, key: str, required: bool = True) -> float | None:
        value = self._get(key, required, float, "a number")
        if value is not None and not math.isfinite(value):
            raise self.fail(key, f"{_shown(value)} is not a finite number")
        return value

    @overload
    def integer(self, key: str, required: Literal[True] = True) -> int: ...
    @overload
    def integer(self, key: str, required: Literal[False]) -> int | None: ...
    @overload
    def integer(self, key: str, required: bool) -> int | None: ...

    def integer(self, key: str, required: bool = True) -> int | None:
        value = self.number(key, required)
        if value is not None and value != int(value):
            raise self.fail(key, f"{value!r} is not a whole number")
        return None if value is None else int(value)

    @overload
    def positive(self, key: str, required: Literal[True] = True) -> float: ...
    @overload
    def positive(self, key: str, required: Literal[False]) -> float | None: ...
    @overload
    def positive(self, key: str, required: bool) -> float | None: ...

    def positive(self, key: str, required: bool = True) -> float | None:
        value = self.number(key, required)
        if value is not None and value <= 0:
            raise self.fail(key, f"{value:g} must be > 0")
        return value


def _run_record(info: RunInfo) -> dict[str, Any]:
    """``swt.run`` as a flat record with the spec's key names in lower case (``load_n``,
    ``velocity_mps``), the start time as ISO text: what ``swtlab inspect --json`` shows."""
    c = info.condition
    return {"run_id": info.run_id, "campaign": info.campaign, "wheel": info.wheel,
            "soil": info.soil, "multipass": c.multipass, "mode": c.mode, "load_n": c.load_set_n,
            "slip_setpoint": c.slip_setpoint, "velocity_mps": c.velocity_set_mps,
            "gravity_mps2": c.gravity_mps2, "steer_deg": c.steer_deg,
            "started_at": None if info.started_at is None else info.started_at.isoformat(),
            "wheel_surface_speed_setpoint_mps": info.wheel_surface_speed_setpoint_mps}


def _unknown_keys(name: str, values: Mapping[str, Any], known: set[str]) -> list[Problem]:
    return [Problem("warning", f"swt.{name}.{k}", "unknown metadata key, ignored")
            for k in sorted(set(values) - known)]


def _run_info(path: Path, values: Mapping[str, Any], form: str) -> RunInfo:
    r = _Reader(path, "run", values, form)
    mode = r.text("mode")
    if mode not in MODES:
        raise r.fail("mode", f"unknown mode {mode!r}; use one of {', '.join(MODES)}")
    load_n = r.number("load_N")
    if load_n <= 0:
        raise r.fail("load_N", f"{load_n:g} N: the set wheel load must be > 0")
    slip = r.number("slip_setpoint", required=False)
    velocity = r.number("velocity_mps")
    if velocity < 0:
        raise r.fail("velocity_mps", f"{velocity:g} m/s: the set travel velocity must be >= 0")
    surface_speed = r.number("wheel_surface_speed_setpoint_mps", required=False)
    if slip is None and mode in ("speed_control", "steered") and surface_speed is not None:
        slip = _slip_from_speeds(surface_speed, velocity)
    if mode in ("free_sled", "towed") and slip is not None:
        raise r.fail("slip_setpoint", f"a {mode} run has no slip set-point; remove it or fix mode")
    if mode == "speed_control" and slip is None:
        raise r.fail("slip_setpoint", "missing; a speed_control run needs its slip set-point")
    if slip is not None and not -1.0 <= slip <= 1.0:
        raise r.fail("slip_setpoint", f"{slip:g} is outside [-1, 1] (a fraction, not percent)")
    steer = r.number("steer_deg", required=False)
    if mode == "steered" and steer is None:
        raise r.fail("steer_deg", "missing; a steered run needs its steering angle")
    if mode != "steered" and steer is not None:
        raise r.fail("steer_deg", f"given for a {mode} run; only steered runs have one")
    multipass = r.integer("multipass")
    if multipass < 0:
        raise r.fail("multipass", f"{multipass} must be >= 0 (0 = undisturbed soil)")
    gravity = r.positive("gravity_mps2", required=False)
    started = r.text("started_at", required=False)
    try:
        started_at = None if started is None else datetime.fromisoformat(started)
    except ValueError:
        raise r.fail("started_at", f"{started!r} is not an ISO 8601 date-time") from None
    condition = TestCondition(mode=mode, load_set_n=load_n, multipass=multipass,
                              velocity_set_mps=velocity, slip_setpoint=slip,
                              gravity_mps2=G0_MPS2 if gravity is None else gravity,
                              steer_deg=steer)
    return RunInfo(run_id=r.text("run_id"), campaign=r.text("campaign"), wheel=r.text("wheel"),
                   soil=r.text("soil"), condition=condition, started_at=started_at,
                   wheel_surface_speed_setpoint_mps=surface_speed)


def _slip_from_speeds(surface_speed_mps: float, velocity_mps: float) -> float | None:
    """Spec slip from set speeds: driving (rw - v)/rw, skid (rw - v)/v."""
    denominator = max(surface_speed_mps, velocity_mps)
    return None if denominator <= 0 else (surface_speed_mps - velocity_mps) / denominator


def _wheel_info(path: Path, values: Mapping[str, Any], name: str, form: str) -> Wheel:
    r = _Reader(path, "wheel", values, form)
    grousers = r.integer("grouser_count")
    if grousers < 0:
        raise r.fail("grouser_count", f"{grousers} must be >= 0")
    height = r.number("grouser_height_m")
    if height < 0:
        raise r.fail("grouser_height_m", f"{height:g} must be >= 0")
    return Wheel(radius_m=r.positive("radius_m"), width_m=r.positive("width_m"),
                 grouser_count=grousers, grouser_height_m=height,
                 stiffness_n_per_mm=r.positive("stiffness_N_per_mm", required=False),
                 mass_kg=r.positive("mass_kg", required=False), name=name)


def _camera_info(path: Path, values: Mapping[str, Any], form: str) -> CameraInfo:
    r = _Reader(path, "camera", values, form)
    direction = r.text("travel_direction", required=False) or "+x"
    if direction not in ("+x", "-x"):
        raise r.fail("travel_direction", f"{direction!r}: use +x or -x")
    centre_text = r.text("wheel_center_px", required=False)
    centre = None
    if centre_text is not None:
        try:
            cx, cy = (float(v) for v in centre_text.strip("[]() ").split(","))
        except ValueError:
            raise r.fail("wheel_center_px", f"{centre_text!r} is not 'x,y'") from None
        centre = (cx, cy)
    return CameraInfo(px_per_m=r.positive("px_per_m"), travel_direction=direction,
                      wheel_center_px=centre,
                      wheel_radius_px=r.positive("wheel_radius_px", required=False))


def _zero(path: Path, values: Mapping[str, Any], form: str) -> dict[str, float]:
    r = _Reader(path, "zero", values, form)
    unknown = set(values) - set(WRENCH_FIELDS)
    if unknown:
        key = sorted(unknown)[0]
        raise r.fail(key, f"not a wrench field; swt.zero takes {' '.join(WRENCH_FIELDS)}")
    return {k: r.number(k) for k in WRENCH_FIELDS if k in values}


CALIBRATION_PARTS = ("gain", "offset", "gain_rel_u", "offset_u")  # raw-run spec, swt.calibration


def _calibration(path: Path, values: Mapping[str, Any], form: str
                 ) -> tuple[dict[tuple[str, str], tuple[float, float]],
                            dict[tuple[str, str], tuple[float, float]]]:
    """``(gain, offset)`` and, where stated, ``(gain_rel_u, offset_u)`` per (topic, field)."""
    r = _Reader(path, "calibration", values, form)
    parts: dict[tuple[str, str], dict[str, float]] = {}
    for key in values:
        topic, _, rest = key.rpartition(".")
        topic, _, fld = topic.rpartition(".")
        if rest not in CALIBRATION_PARTS or not topic or not fld:
            raise r.fail(key, "expected '<topic>.<field>.' followed by one of "
                              f"{', '.join(CALIBRATION_PARTS)}")
        number = r.number(key)
        if rest.endswith("_u") and number < 0:
            raise r.fail(key, f"a standard uncertainty must be >= 0, got {number:g}")
        parts.setdefault((topic, fld), {})[rest] = number
    out, uncertainty = {}, {}
    for (topic, fld), p in parts.items():
        gain = p.get("gain", 1.0)
        if gain == 0:
            raise r.fail(f"{topic}.{fld}.gain", "a gain of 0 would erase the channel")
        out[(topic, fld)] = (gain, p.get("offset", 0.0))
        if "gain_rel_u" in p or "offset_u" in p:
            uncertainty[(topic, fld)] = (p.get("gain_rel_u", 0.0), p.get("offset_u", 0.0))
    return out, uncertainty


def parse_metadata(path: Path, records: Mapping[str, Mapping[str, Any]],
                   needs_suspension: bool = True,
                   form: str = SPEC_FORM) -> tuple[RunMetadata, list[Problem]]:
    """Typed metadata from raw records; raises IngestError on missing or contradictory values.
    ``form``: where the run's file keeps a record (``{record}`` filled in), for the errors."""
    path = Path(path)
    records = {name: values for name, values in records.items() if values}  # {} = absent
    problems: list[Problem] = []
    for name in ("run", "wheel"):
        if name not in records:
            raise IngestError(path, f"swt.{name}", f"metadata record missing; give its keys "
                              f"({name}.<key>) in {form.format(record=name)}")
    for name, known in (("run", _RUN_KEYS), ("wheel", _WHEEL_KEYS),
                        ("suspension", _SUSPENSION_KEYS), ("camera", _CAMERA_KEYS),
                        ("camera_track", {"px_per_m"})):
        problems += _unknown_keys(name, records.get(name, {}), known)
    problems += [Problem("warning", f"swt.{n}", "unknown metadata record, ignored")
                 for n in sorted(set(records) - set(RECORDS))]
    suspension = None
    if "suspension" in records:
        r = _Reader(path, "suspension", records["suspension"], form)
        suspension = SuspensionInfo(arm_length_m=r.positive("arm_length_m"),
                                    angle_zero_rad=r.number("angle_zero_rad"))
    elif needs_suspension:
        raise IngestError(path, "swt.suspension",
                          "metadata record missing; hub height needs arm_length_m and "
                          f"angle_zero_rad: add them to {form.format(record='suspension')}")
    camera_track = None
    if "camera_track" in records:
        track = _Reader(path, "camera_track", records["camera_track"], form)
        camera_track = CameraTrackInfo(px_per_m=track.positive("px_per_m"))
    run = _run_info(path, records["run"], form)
    calibration, calibration_u = _calibration(path, records.get("calibration", {}), form)
    metadata = RunMetadata(
        run=run, wheel=_wheel_info(path, records["wheel"], run.wheel, form),
        suspension=suspension,
        camera=_camera_info(path, records["camera"], form) if "camera" in records else None,
        camera_track=camera_track,
        zero=_zero(path, records.get("zero", {}), form),
        calibration=calibration, calibration_u=calibration_u)
    _check_ranges(path, metadata)
    return metadata, problems


def _check_ranges(path: Path, metadata: RunMetadata) -> None:
    """Every number of the typed metadata within its possible range (``swtlab_base.domain.ranges``;
    outside it no testbed could have measured the run)."""
    values = {f"{record}.{key}": value for record in ("run", "wheel", "suspension", "camera",
                                                      "camera_track")
              for key, value in _fields(getattr(metadata, record)).items()}
    values.update({f"zero.{k}": v for k, v in metadata.zero.items()})
    for name, value in values.items():
        limits = METADATA.get(name, METADATA.get(name.partition(".")[0]))
        if limits is None or value is None or isinstance(value, (str, bool, tuple, datetime)):
            continue
        why = limits.impossible(float(value))
        if why:
            raise IngestError(path, f"swt.{name}", why)


#: typed field names that differ from the metadata keys
_KEY_OF = {"load_n": "load_N", "stiffness_n_per_mm": "stiffness_N_per_mm"}


def _fields(part: Any) -> dict[str, Any]:
    if part is None:
        return {}
    return {_KEY_OF.get(k, k): v for k, v in vars(part).items()}
