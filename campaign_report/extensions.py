"""Sections fed by pipeline stages whose data may not exist for a campaign.

A stage that stores new data (the soil flow, image slip, the gap report) adds its section
here, not in the page code: a ``build(data, palette)`` that draws the section from the
gathered :class:`~campaign_report.data.CampaignData` alone (None: no such section), and,
when its data lives in tables of its own, a ``gather(session, data)`` that reads them from
the database into ``data.extras[name]`` (None: nothing stored). An in-memory pipeline puts
the same plain data into ``extras`` itself::

    from campaign_report.extensions import Extension, register

    def _gather(session, data):
        rows = ...  # query the stage's table for data.name's runs, as plain objects
        return rows or None

    def _build(data, palette):
        rows = data.extras.get("my-stage")
        if not rows:
            return None  # no data: the page has no such section
        return Section("my-stage", "My stage", [Image(...), ...])

    register(Extension("my-stage", _build, _gather))

Use ``palette`` (:class:`~campaign_report.style.Palette`) so loads and multipasses look as
in every other figure. Sections appear after the built-in ones, in registration order.
Registered: the soil flow under the wheel (:mod:`campaign_report.flow`), image slip
(:mod:`campaign_report.image_slip`), the sim-to-real gap (:mod:`campaign_report.gap`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from sqlalchemy.orm import Session

from campaign_report.html import Section
from campaign_report.style import Palette

if TYPE_CHECKING:
    from campaign_report.data import CampaignData

Builder = Callable[["CampaignData", Palette], Section | None]
Gatherer = Callable[[Session, "CampaignData"], Any]


@dataclass(frozen=True)
class Extension:
    """An optional section: its name, the function that draws it from the campaign's data
    (None: no data), and the one that reads its data from the database (None: it needs
    nothing beyond the results table)."""

    name: str
    build: Builder
    gather: Gatherer | None = None


EXTENSIONS: list[Extension] = []


def register(extension: Extension) -> None:
    """Add (or, under the same name, replace) an optional section."""
    EXTENSIONS[:] = [e for e in EXTENSIONS if e.name != extension.name] + [extension]


def unregister(name: str) -> None:
    EXTENSIONS[:] = [e for e in EXTENSIONS if e.name != name]


def gather_extras(session: Session, data: CampaignData) -> dict[str, Any]:
    """Each registered extension's stored data for this campaign (name -> data; none: left out)."""
    found = {e.name: e.gather(session, data) for e in EXTENSIONS if e.gather is not None}
    return {name: value for name, value in found.items() if value is not None}


def optional_sections(data: CampaignData, palette: Palette) -> list[Section]:
    """The sections of every registered extension that has data for this campaign."""
    return [s for e in EXTENSIONS if (s := e.build(data, palette)) is not None]
