"""Sections fed by pipeline stages whose data may not be in the database.

A stage that stores new data (planned: softflow velocity maps and α(β), image slip against
encoder slip, the gap heatmap with its ranked explanations) adds its section here, not in
the page code::

    from campaign_report.extensions import Extension, register

    def _image_slip(session, data, palette):
        rows = ...  # query the stage's table for data.name's runs
        if not rows:
            return None  # no data: the page has no such section
        return Section("image-slip", "Image slip against encoder slip", [Image(...), ...])

    register(Extension("image-slip", _image_slip))

``build(session, data, palette)`` gets the open database session, the gathered
:class:`~campaign_report.data.CampaignData` and the campaign's
:class:`~campaign_report.style.Palette` (use it so loads and multipasses look as in every
other figure) and returns a :class:`~campaign_report.html.Section`, or None when its data
does not exist for this campaign. Sections appear after the built-in ones, in registration
order. Registered: the soil flow under the wheel (:mod:`campaign_report.flow`), image slip
(:mod:`campaign_report.image_slip`), the sim-to-real gap (:mod:`campaign_report.gap`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from sqlalchemy.orm import Session

from campaign_report.data import CampaignData
from campaign_report.html import Section
from campaign_report.style import Palette

Builder = Callable[[Session, CampaignData, Palette], Section | None]


@dataclass(frozen=True)
class Extension:
    """An optional section: its name and the function that builds it (None: no data)."""

    name: str
    build: Builder


EXTENSIONS: list[Extension] = []


def register(extension: Extension) -> None:
    """Add (or, under the same name, replace) an optional section."""
    EXTENSIONS[:] = [e for e in EXTENSIONS if e.name != extension.name] + [extension]


def unregister(name: str) -> None:
    EXTENSIONS[:] = [e for e in EXTENSIONS if e.name != name]


def optional_sections(session: Session, data: CampaignData, palette: Palette) -> list[Section]:
    """The sections of every registered extension that has data for this campaign."""
    return [s for e in EXTENSIONS if (s := e.build(session, data, palette)) is not None]
