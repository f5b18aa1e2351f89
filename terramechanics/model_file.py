"""Model file (TOML): wheel, soil, gravity, effects. Format in ``docs/model-file.md``."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

from swtlab_base.atomic import write_atomically
from swtlab_base.errors import InputError
from terramechanics.effects import EFFECTS, make_effect
from terramechanics.model import BRAKED_LAWS, WheelModel
from terramechanics.soil import SOILS, SoilParams
from terramechanics.state import EARTH_GRAVITY_MPS2
from terramechanics.wheel import Wheel

SHIPPED_MODELS = Path(__file__).parent / "models"


class ModelFileError(InputError, ValueError):
    """A model file that cannot be used; the message names the table and key."""


def _build(cls, table: dict, where: str):
    try:
        return cls(**table)
    except TypeError as exc:
        known = [f.name for f in dataclasses.fields(cls)]
        raise ModelFileError(f"[{where}]: {exc}; known keys: {known}") from None
    except ValueError as exc:
        raise ModelFileError(f"[{where}]: {exc}") from None


def model_from_dict(data: dict) -> WheelModel:
    """Build a model from the parsed TOML tables."""
    unknown = set(data) - {"model", "wheel", "soil", "effects"}
    if unknown:
        raise ModelFileError(f"unknown table(s) {sorted(unknown)}")
    for table in ("wheel", "soil"):
        if table not in data:
            raise ModelFileError(f"missing table [{table}]")
    wheel = _build(Wheel, data["wheel"], "wheel")
    soil_table = dict(data["soil"])
    preset = soil_table.pop("preset", None)
    if preset is not None:
        if preset not in SOILS:
            raise ModelFileError(f"[soil] preset {preset!r} unknown; known: {sorted(SOILS)}")
        soil_table = {**dataclasses.asdict(SOILS[preset]), **soil_table}
    soil = _build(SoilParams, soil_table, "soil")
    effects = {}
    for name, table in data.get("effects", {}).items():
        if name not in EFFECTS:
            raise ModelFileError(f"[effects.{name}] unknown effect; known: {sorted(EFFECTS)}")
        params = dict(table)
        law = params.pop("law", None)
        if params.pop("enabled", True):
            try:
                effects[name] = make_effect(name, law, **params)
            except (TypeError, KeyError) as exc:
                raise ModelFileError(f"[effects.{name}]: {exc}") from None
    table = data.get("model", {})
    gravity = table.get("gravity_mps2", EARTH_GRAVITY_MPS2)
    try:
        return WheelModel(wheel=wheel, soil=soil, gravity_mps2=float(gravity), effects=effects,
                          braked_law=table.get("braked_law", BRAKED_LAWS[0]))
    except ValueError as exc:
        raise ModelFileError(f"[model] {exc}") from None


def load_model(path: str | Path) -> WheelModel:
    """Read a model file."""
    try:
        data = tomllib.loads(Path(path).read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ModelFileError(f"{path}: not valid TOML: {exc}") from None
    return model_from_dict(data)


def shipped_model(name: str) -> WheelModel:
    """A model file shipped with swtlab (``terramechanics/models/<name>.toml``)."""
    path = SHIPPED_MODELS / f"{name}.toml"
    if not path.exists():
        known = sorted(p.stem for p in SHIPPED_MODELS.glob("*.toml"))
        raise ModelFileError(f"no shipped model {name!r}; shipped: {known}")
    return load_model(path)


def model_to_dict(model: WheelModel) -> dict:
    """The tables of a model file; effects that are off are written with enabled = false
    (with their default law); an unset (None) law parameter and the default braked law are
    left out."""
    effects = {}
    for name, cls in EFFECTS.items():
        effect = model.effects.get(name) or cls()
        effects[name] = {"enabled": name in model.effects, "law": effect.law,
                         **{k: v for k, v in dataclasses.asdict(effect).items()
                            if v is not None}}
    braked = {} if model.braked_law == BRAKED_LAWS[0] else {"braked_law": model.braked_law}
    return {"model": {"gravity_mps2": model.gravity_mps2, **braked},
            "wheel": {k: v for k, v in dataclasses.asdict(model.wheel).items()
                      if v is not None and v != ""},
            "soil": dataclasses.asdict(model.soil),
            "effects": effects}


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'


def save_model(model: WheelModel, path: str | Path) -> None:
    """Write a model file that :func:`load_model` reads back to an equal model."""
    lines: list[str] = []
    for table, content in model_to_dict(model).items():
        if table == "effects":
            for name, params in content.items():
                lines += ["", f"[effects.{name}]"]
                lines += [f"{k} = {_toml_value(v)}" for k, v in params.items()]
        else:
            lines += ["", f"[{table}]"] + [f"{k} = {_toml_value(v)}" for k, v in content.items()]
    write_atomically(path, "\n".join(lines).lstrip() + "\n")
