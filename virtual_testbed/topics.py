"""Topics and fields of the raw-run spec (``/work/shared/spec/raw-run-format.md``)."""

from __future__ import annotations

TOPIC_FIELDS: dict[str, tuple[str, ...]] = {
    "/hub/wrench": ("fx", "fy", "fz", "tx", "ty", "tz"),
    "/tether/force": ("dp",),
    "/wheel/encoder": ("angle",),
    "/sled/encoder": ("position",),
    "/tether/encoder": ("position",),
    "/suspension/angle": ("angle",),
}


def csv_name(topic: str) -> str:
    """``/hub/wrench`` -> ``hub_wrench.csv`` (spec, CSV form)."""
    return topic.lstrip("/").replace("/", "_") + ".csv"
