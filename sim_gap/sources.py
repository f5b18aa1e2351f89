"""Several measured sources in one diagnosis (docs/gap-report.md, "Several sources"): what
each source is (wheel, conditions) and which sources each tested effect can be seen on, so
that an effect is tied to the wheel or condition that has its feature while the soil is
fitted on all of them."""

from __future__ import annotations

import pandas as pd

from sim_gap.candidates import allowed_laws
from sim_gap.diagnose import testable
from sim_gap.simulated import Simulated

#: the feature of a source that lets an effect change its prediction
FEATURE = {"grousers": "grousers", "slip_sinkage": "sinkage at several slips",
           "reduced_gravity": "a gravity level other than g0",
           "wheel_flexibility": "a load the wheel deflects under",
           "multipass": "a later pass", "bulldozing": "measurable sinkage"}


def _subset(points: pd.DataFrame, mask) -> pd.DataFrame:
    out = points[mask].reset_index(drop=True)
    out.attrs = dict(points.attrs)
    return out


def describe_sources(points: pd.DataFrame, sim: Simulated, effects: list[str],
                     laws: dict[str, tuple[str, ...]] | None = None) -> dict:
    """``sources``: per source its wheel, point count and condition levels; ``effects``:
    per tested effect the sources whose prediction it changes under one of its ``laws``
    (those the diagnosis may use; default every law) by the untestable threshold of
    :func:`sim_gap.diagnose.testable`, and a sentence saying so."""
    source = (points["source"] if "source" in points
              else pd.Series(points.attrs.get("source", "measured"), index=points.index))
    names = list(dict.fromkeys(source))
    wheels = points.attrs.get("wheels", {})
    sources, seen_on = [], {e: [] for e in effects}
    for name in names:
        mask = (source == name).to_numpy()
        rows = points[mask]
        wheel = wheels.get(name)
        sources.append({
            "name": name, "n_points": int(mask.sum()),
            "wheel": None if wheel is None else {"name": wheel.name, **wheel.geometry()},
            "loads_n": sorted(float(v) for v in rows["load_set_n"].unique()),
            "multipass": sorted(int(v) for v in rows["multipass"].unique()),
            "gravity_mps2": sorted(float(v) for v in rows["gravity_mps2"].unique())})
        shown = effects if len(names) == 1 else testable(
            sim, _subset(points, mask), allowed_laws(sim.model, effects, laws))[0]
        for effect in shown:
            seen_on[effect].append(name)
    return {"sources": sources,
            "effects": {e: {"sources": on, "text": _sentence(e, on, len(names))}
                        for e, on in seen_on.items()}}


def _sentence(effect: str, on: list[str], n_sources: int) -> str:
    if not on:
        return (f"{effect}: no single source shows it alone; it is tested only on the "
                f"sources together")
    if len(on) == n_sources:
        return (f"{effect}: every source shows it; tested on all {n_sources} sources with "
                "one soil")
    which = ", ".join(on)
    return (f"{effect}: only {which} {'has' if len(on) == 1 else 'have'} "
            f"{FEATURE[effect]}; its effect is tested on {which} with the soil fitted on all "
            f"{n_sources} sources")
