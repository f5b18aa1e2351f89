"""One self-contained HTML page: inline CSS, every image a base64 PNG ``data:`` URI or an
inline SVG drawing, no script, font or link that would need a network. Thumbnails open full
size through a CSS ``:target`` lightbox (a plain ``#fragment`` link; back or the close link
returns); a drawing's lightbox shows the thumbnail's own drawing again (``<use>``), so it is
in the page once."""

from __future__ import annotations

import base64
from dataclasses import dataclass, field
from html import escape

CSS = """
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;
 margin:0;color:#1d1d1f;background:#fff}
header,main{max-width:1280px;margin:0 auto;padding:0 20px}
header{padding-top:18px;border-bottom:1px solid #ddd}
h1{font-size:1.6em;margin:.2em 0}h2{font-size:1.25em;margin:1.6em 0 .5em;
 border-bottom:2px solid #0072B2;padding-bottom:.15em}h3{font-size:1.05em;margin:1.2em 0 .4em}
dl.meta{display:grid;grid-template-columns:max-content 1fr;gap:2px 14px;margin:.6em 0}
dl.meta dt{color:#555}dl.meta dd{margin:0}
nav{margin:.6em 0 1em}nav a{margin-right:1em}
table{border-collapse:collapse;font-size:13px;width:100%}table+table{margin-top:1em}
th,td{border-bottom:1px solid #e3e3e3;padding:3px 5px;text-align:left;vertical-align:top}
tr:has(+tr.reasons) td{border-bottom:none}
tr.reasons td{padding:0 6px 4px 2.5em;color:#444;font-size:12.5px}
th{background:#f3f5f8;position:sticky;top:0}td.num{text-align:right;white-space:nowrap}
tr.flagged td{background:#fff6df}tr.no_stable_phase td,tr.failed td{background:#fde8e8}
.status{font-weight:600;white-space:nowrap}.status.ok{color:#1a7f37}
.status.flagged{color:#9a6700}.status.no_stable_phase,.status.failed{color:#b42318}
.note{padding:6px 10px;border-left:4px solid #0072B2;background:#f3f8fc;margin:.6em 0}
.note.warning{border-color:#D55E00;background:#fdf1e9}
.gallery{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:12px}
.gallery figure{margin:0;border:1px solid #e3e3e3;padding:4px;background:#fff}
.gallery figure.no_stable_phase{border-color:#b42318}.gallery figure.flagged{border-color:#9a6700}
.gallery img,.gallery svg{width:100%;height:auto;display:block}
figcaption{font-size:12px;color:#333;margin-top:2px}
figure.full{margin:.5em 0}figure.full img{max-width:100%;height:auto}
.lightbox{display:none;position:fixed;inset:0;background:rgba(20,20,20,.82);z-index:10;
 align-items:center;justify-content:center}
.lightbox:target{display:flex}.lightbox a{display:block;max-width:96vw;max-height:96vh}
.lightbox img{max-width:96vw;max-height:92vh;background:#fff;display:block}
.lightbox svg{width:min(800px,96vw,115vh);height:auto;background:#fff;display:block}
.lightbox span{color:#fff;font-size:13px}
footer{max-width:1280px;margin:2em auto;padding:0 20px;color:#666;font-size:12px}
"""


@dataclass(frozen=True)
class Image:
    """A PNG figure; with ``thumb`` it shows as a thumbnail that opens ``png`` full size."""

    anchor: str
    caption: str
    png: bytes
    thumb: bytes | None = None
    css_class: str = ""


@dataclass(frozen=True)
class Drawing:
    """An inline SVG figure (``svg``: one ``<svg>`` element whose drawing is the group of id
    :meth:`drawing_id`, with ``viewBox`` 0 0 ``width`` ``height``), shown as a thumbnail
    that opens it full size."""

    anchor: str
    caption: str
    svg: str
    width: int
    height: int
    css_class: str = ""

    @property
    def drawing_id(self) -> str:
        return f"{self.anchor}-drawing"


@dataclass(frozen=True)
class Table:
    """Rows of already formatted cells; ``numeric`` columns align right, ``row_classes``
    style whole rows (e.g. by status), ``html_columns`` hold trusted markup (links);
    ``row_notes``: a text shown under its row across the whole table (flags and reasons,
    readable at any width), none where empty."""

    header: list[str]
    rows: list[list[str]]
    numeric: frozenset[int] = frozenset()
    row_classes: list[str] = field(default_factory=list)
    html_columns: frozenset[int] = frozenset()
    row_notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Note:
    text: str
    warning: bool = False


@dataclass(frozen=True)
class Heading:
    text: str


Block = Image | Drawing | Table | Note | Heading


@dataclass(frozen=True)
class Section:
    """One titled part of the page; thumbnail images are gathered into a gallery."""

    anchor: str
    title: str
    blocks: list[Block]


@dataclass(frozen=True)
class Page:
    title: str
    meta: list[tuple[str, str]]
    sections: list[Section]
    footer: str


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _table(t: Table) -> str:
    head = "".join(f"<th>{escape(h)}</th>" for h in t.header)
    rows = []
    for i, row in enumerate(t.rows):
        css = t.row_classes[i] if i < len(t.row_classes) else ""
        cells = "".join(
            f'<td{" class=num" if j in t.numeric else ""}>'
            f"{cell if j in t.html_columns else escape(cell)}</td>"
            for j, cell in enumerate(row))
        rows.append(f'<tr class="{escape(css)}">{cells}</tr>')
        note = t.row_notes[i] if i < len(t.row_notes) else ""
        if note:
            rows.append(f'<tr class="{escape(css)} reasons"><td colspan="{len(t.header)}">'
                        f"{escape(note)}</td></tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def _thumbnail(img: Image) -> str:
    alt = escape(img.caption)
    return (f'<figure id="{img.anchor}" class="{escape(img.css_class)}">'
            f'<a href="#full-{img.anchor}"><img src="{data_uri(img.thumb)}" alt="{alt}" '
            f'width="300"></a><figcaption>{alt}</figcaption></figure>')


def _lightbox(img: Image) -> str:
    return (f'<div class="lightbox" id="full-{img.anchor}"><a href="#{img.anchor}" '
            f'title="close"><img src="{data_uri(img.png)}" alt="{escape(img.caption)}">'
            f"<span>{escape(img.caption)} (click to close)</span></a></div>")


def _drawing_thumbnail(d: Drawing) -> str:
    caption = escape(d.caption)
    return (f'<figure id="{d.anchor}" class="{escape(d.css_class)}">'
            f'<a href="#full-{d.anchor}">{d.svg}</a><figcaption>{caption}</figcaption></figure>')


def _drawing_lightbox(d: Drawing) -> str:
    caption = escape(d.caption)
    return (f'<div class="lightbox" id="full-{d.anchor}"><a href="#{d.anchor}" title="close">'
            f'<svg viewBox="0 0 {d.width} {d.height}" width="{d.width}" height="{d.height}" '
            f'role="img" aria-label="{caption}"><use href="#{d.drawing_id}"/></svg>'
            f"<span>{caption} (click to close)</span></a></div>")


def _full(img: Image) -> str:
    return (f'<figure class="full" id="{img.anchor}"><img src="{data_uri(img.png)}" '
            f'alt="{escape(img.caption)}"><figcaption>{escape(img.caption)}</figcaption></figure>')


def _section(section: Section) -> tuple[str, list[str]]:
    """The section's markup and the lightboxes of its thumbnails (placed at the page end)."""
    parts, gallery, lightboxes = [f'<section id="{section.anchor}"><h2>'
                                  f"{escape(section.title)}</h2>"], [], []

    def flush() -> None:
        if gallery:
            parts.append('<div class="gallery">' + "".join(gallery) + "</div>")
            gallery.clear()

    for block in section.blocks:
        if isinstance(block, Drawing):
            gallery.append(_drawing_thumbnail(block))
            lightboxes.append(_drawing_lightbox(block))
            continue
        if isinstance(block, Image) and block.thumb is not None:
            gallery.append(_thumbnail(block))
            lightboxes.append(_lightbox(block))
            continue
        flush()
        if isinstance(block, Image):
            parts.append(_full(block))
        elif isinstance(block, Table):
            parts.append(_table(block))
        elif isinstance(block, Note):
            parts.append(f'<p class="note{" warning" if block.warning else ""}">'
                         f"{escape(block.text)}</p>")
        else:
            parts.append(f"<h3>{escape(block.text)}</h3>")
    flush()
    parts.append("</section>")
    return "".join(parts), lightboxes


def render_page(page: Page) -> str:
    """The whole page as one HTML string."""
    bodies, lightboxes = [], []
    for section in page.sections:
        body, boxes = _section(section)
        bodies.append(body)
        lightboxes.extend(boxes)
    meta = "".join(f"<dt>{escape(k)}</dt><dd>{escape(v)}</dd>" for k, v in page.meta)
    nav = " ".join(f'<a href="#{s.anchor}">{escape(s.title)}</a>' for s in page.sections)
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width,initial-scale=1">'
            f"<title>{escape(page.title)}</title><style>{CSS}</style></head><body>"
            f'<header><h1>{escape(page.title)}</h1><dl class="meta">{meta}</dl>'
            f"<nav>{nav}</nav></header><main>{''.join(bodies)}</main>"
            f"<footer>{escape(page.footer)}</footer>{''.join(lightboxes)}</body></html>\n")
