"""Write a campaign's report page: gather, draw, assemble, write."""

from __future__ import annotations

import re
from datetime import UTC, datetime
from pathlib import Path

from sqlalchemy.engine import make_url
from sqlalchemy.orm import Session

from campaign_report import sections
from campaign_report.data import CampaignData, campaign_names, gather
from campaign_report.extensions import optional_sections
from campaign_report.html import Page, render_page
from campaign_report.style import Palette
from swtlab_cli.progress import progress
from traceability import open_database
from traceability.provenance import swtlab_version


def page_paths(path: str | Path, names: list[str]) -> dict[str, Path]:
    """Where each campaign's page goes: ``path`` itself for one campaign; for several,
    ``<stem>-<campaign>.html`` beside it (campaign name reduced to letters, digits, ``._-``)."""
    path = Path(path)
    if len(names) == 1:
        return {names[0]: path}
    out = {}
    for name in names:
        slug = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "campaign"
        candidate = path.with_name(f"{path.stem}-{slug}{path.suffix or '.html'}")
        while candidate in out.values():
            candidate = candidate.with_name(candidate.stem + "_" + candidate.suffix)
        out[name] = candidate
    return out


def build_page(session: Session, data: CampaignData, db_url: str, quiet: bool = False) -> Page:
    """Every section of one campaign's page (figures drawn here; a bar over the runs)."""
    palette = Palette(data.loads, data.multipasses)
    images = []
    for i, run in progress(list(enumerate(data.runs)), desc=f"report {data.name}",
                           quiet=quiet):
        images.append(sections.timeseries_image(i, run, palette))
    parts = [sections.runs_section(data), sections.timeseries_section(images)]
    if data.fits:
        parts.append(sections.curves_section(data, palette))
    parts += [s for s in (sections.interpolation_section(data, palette),
                          sections.wpm_section(data, palette)) if s is not None]
    parts += optional_sections(session, data, palette)
    meta = [("database", make_url(db_url).render_as_string(hide_password=True)),
            ("wheel / soil", ", ".join(sorted({f"{r.wheel} / {r.soil}" for r in data.runs}))),
            ("loads", ", ".join(f"{x:g} N" for x in data.loads)),
            ("multipass", ", ".join(str(m) for m in data.multipasses)),
            ("generated", datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
             + f" by swtlab {swtlab_version()}")]
    return Page(f"SWT campaign {data.name}", meta, parts,
                footer="Self-contained page written by swtlab report: every figure is "
                       "embedded, nothing is fetched from the network.")


def write_report(db_url: str, path: str | Path, quiet: bool = False,
                 campaign: str | None = None) -> Path:
    """Write the page of ``campaign`` (default: the database's only campaign) to ``path``.

    Raises ``LookupError`` (one line, what to do) when the database has no processed run,
    no such campaign, or several campaigns and none was named."""
    with open_database(db_url)() as session:
        names = campaign_names(session)
        if not names:
            raise LookupError(f"{db_url}: no processed runs (run swtlab process first)")
        if campaign is None and len(names) > 1:
            raise LookupError(f"{len(names)} campaigns in {db_url}; name one with --campaign "
                              f"({', '.join(names)}) or leave it out for one page each")
        name = campaign or names[0]
        if name not in names:
            raise LookupError(f"no campaign {name!r} in {db_url}; it has {', '.join(names)}")
        page = build_page(session, gather(session, name), db_url, quiet)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(render_page(page), encoding="utf-8")
    return path


def write_reports(db_url: str, path: str | Path, quiet: bool = False) -> dict[str, Path]:
    """One page per campaign of the database, named by :func:`page_paths`: campaign -> page."""
    with open_database(db_url)() as session:
        names = campaign_names(session)
    if not names:
        raise LookupError(f"{db_url}: no processed runs (run swtlab process first)")
    return {name: write_report(db_url, p, quiet, name)
            for name, p in page_paths(path, names).items()}
