"""Write a campaign's report page: data in (:class:`~campaign_report.data.CampaignData`, from
the database or from in-memory results), figures drawn, page assembled, file written."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from datetime import UTC, datetime
from pathlib import Path

from matplotlib import rc_context

from campaign_report import sections
from campaign_report.replicates import replicates_section
from campaign_report.data import CampaignData, campaign_names, gather
from campaign_report.extensions import optional_sections
from campaign_report.html import Page, render_page
from campaign_report.images import RENDER_RC
from campaign_report.style import Palette
from swtlab_base.atomic import write_atomically
from traceability import open_database
from traceability.provenance import swtlab_version

#: ``progress(items, desc)`` -> the same items, e.g. shown as a bar by the caller (the CLI)
Progress = Callable[[list, str], Iterable]


def _no_progress(items: list, desc: str) -> Iterable:
    return items


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


def build_page(data: CampaignData, progress: Progress = _no_progress) -> Page:
    """Every section of one campaign's page, drawn from ``data`` alone."""
    with rc_context(RENDER_RC):
        return _build_page(data, progress)


def _build_page(data: CampaignData, progress: Progress) -> Page:
    palette = Palette(data.loads, data.multipasses)
    images = [sections.timeseries_image(i, run, palette)
              for i, run in progress(list(enumerate(data.runs)), f"report {data.name}")]
    parts = [s for s in (sections.runs_section(data), replicates_section(data, palette))
             if s is not None]
    parts.append(sections.timeseries_section(images))
    if data.fits:
        parts.append(sections.curves_section(data, palette))
    parts += [s for s in (sections.interpolation_section(data, palette),
                          sections.wpm_section(data, palette)) if s is not None]
    parts += optional_sections(data, palette)
    meta = [data.provenance,
            ("wheel / soil", ", ".join(sorted({f"{r.wheel} / {r.soil}" for r in data.runs}))),
            ("loads", ", ".join(f"{x:g} N" for x in data.loads)),
            ("multipass", ", ".join(str(m) for m in data.multipasses)),
            ("generated", datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
             + f" by swtlab {swtlab_version()}")]
    return Page(f"SWT campaign {data.name}", meta, parts,
                footer="Self-contained page written by swtlab report: every figure is "
                       "embedded, nothing is fetched from the network.")


def render_report(data: CampaignData, path: str | Path,
                  progress: Progress = _no_progress) -> Path:
    """Write the page of ``data`` to ``path`` (atomically: a reader never sees half a page)."""
    return write_atomically(path, render_page(build_page(data, progress)))


def write_report(db_url: str, path: str | Path, campaign: str | None = None,
                 progress: Progress = _no_progress) -> Path:
    """Write the page of ``campaign`` (default: the database's only campaign) to ``path``.

    Raises ``LookupError`` (one line, what to do) when the database has no processed run,
    no such campaign, or several campaigns and none was named."""
    with open_database(db_url, read_only=True)() as session:
        names = campaign_names(session)
        if not names:
            raise LookupError(f"{db_url}: no processed runs (run swtlab process first)")
        if campaign is None and len(names) > 1:
            raise LookupError(f"{len(names)} campaigns in {db_url}; name one with "
                              f"campaign={names[0]!r} ({', '.join(names)}) or leave it out "
                              "for one page each")
        name = campaign or names[0]
        if name not in names:
            raise LookupError(f"no campaign {name!r} in {db_url}; it has {', '.join(names)}")
        data = gather(session, name, db_url)
    return render_report(data, path, progress)


def write_reports(db_url: str, path: str | Path,
                  progress: Progress = _no_progress) -> dict[str, Path]:
    """One page per campaign of the database, named by :func:`page_paths`: campaign -> page."""
    with open_database(db_url, read_only=True)() as session:
        names = campaign_names(session)
    if not names:
        raise LookupError(f"{db_url}: no processed runs (run swtlab process first)")
    return {name: write_report(db_url, p, name, progress)
            for name, p in page_paths(path, names).items()}
