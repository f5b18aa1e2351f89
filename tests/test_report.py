"""swtlab report: the page's content and self-containment, the figures' labels and colours,
curves with and without a WPM export, optional sections, the command line."""

from __future__ import annotations

import base64
import json
import re
import shutil
import xml.etree.ElementTree as ET
from dataclasses import replace
from html import unescape
from pathlib import Path

import cv2
import numpy as np
import pytest
from sqlalchemy import select, update

from campaign_report import extensions, figures, page_paths, sections, timeseries, write_report
from campaign_report.data import campaign_names, gather
from campaign_report.extensions import Extension, optional_sections, register, unregister
from campaign_report.html import Image, Note, Section
from campaign_report.style import Palette
from swtlab_cli import exit_codes
from test_report_campaign import FLAG, FLAGGED_RUN, NO_STABLE_RUN, build_small_campaign
from test_report_timeseries import _maps
from traceability import open_database
from traceability.models import Campaign, Run, TestCondition, WpmExport
from traceability.queries import latest_results
from wpm_export import WheelPerformanceModule

pytestmark = [pytest.mark.slow,  # campaigns processed and rendered into pages
              pytest.mark.slow_campaign]

UNIT = re.compile(r"\[[^\]]+\]$")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """(database URL, report path, page text) of the small campaign, exported and reported."""
    folder = tmp_path_factory.mktemp("report")
    url = build_small_campaign(folder)
    page = write_report(url, folder / "report.html")
    return url, page, page.read_text(encoding="utf-8")


@pytest.fixture
def fast_timeseries(monkeypatch):
    """Per-run figures replaced by a tiny image, for tests about the page around them."""
    png = cv2.imencode(".png", np.full((4, 6, 3), 200, np.uint8))[1].tobytes()
    monkeypatch.setattr(sections, "timeseries_image",
                        lambda i, run, palette: Image(sections.run_anchor(i), run.run_id, png,
                                                      png, run.status))


def _copy_db(url: str, folder: Path) -> str:
    target = folder / "copy.sqlite"
    shutil.copy2(url.removeprefix("sqlite:///"), target)
    return f"sqlite:///{target}"


def _cli(argv: list[str]) -> int:
    """``swtlab report ...`` as the command line runs it (database errors are main()'s)."""
    from swtlab_cli.main import main

    return main(["report", *argv])


def test_page_is_self_contained_and_every_image_decodes(small):
    _, _, text = small
    assert "<script" not in text and "<link" not in text and "@import" not in text
    references = re.findall(r'(?:src|href)="([^"]*)"', text)
    assert references and not [r for r in references if re.match(r"[a-z]+:(?!image/png)", r)
                                and not r.startswith("data:image/png;base64,")]
    assert "http://" not in text and "https://" not in text
    sources = re.findall(r'<img src="([^"]+)"', text)
    widths = []
    for src in sources:
        assert src.startswith("data:image/png;base64,")
        image = cv2.imdecode(np.frombuffer(base64.b64decode(src.split(",", 1)[1]), np.uint8),
                             cv2.IMREAD_COLOR)
        assert image is not None and image.shape[0] > 0 and image.std() > 5
        widths.append(image.shape[1])
    # one thumbnail per run: its time series inline, a well-formed SVG drawing
    drawings = re.findall(r'<figure id="run-(\d+)"[^>]*><a href="#full-run-\1">(<svg .*?</svg>)'
                          r'</a><figcaption>', text)
    assert len(drawings) == 20
    for index, svg in drawings:
        root = ET.fromstring(svg)
        assert root.find(f".//g[@id='run-{index}-drawing']") is not None
        assert f'<use href="#run-{index}-drawing"/>' in text  # shown again full size
    ids = set(re.findall(r'id="([^"]+)"', text))
    fragments = {h[1:] for h in references if h.startswith("#")}
    assert fragments <= ids  # every thumbnail and run link opens something on the page


def test_page_lists_every_run_with_its_status_and_reasons(small):
    url, page, text = small
    with open_database(url)() as session:
        results = latest_results(session)
    rows = {re.search(r">([^<]+)</a>", row).group(1): row + reasons  # reasons: under the row
            for row, reasons in re.findall(r"<tr class=\"(?:ok|flagged|no_stable_phase)\">(.*?)"
                                           r"</tr>(?:<tr class=\"\w+ reasons\">(.*?)</tr>)?",
                                           text)}
    assert set(results["run_id"]) <= set(rows) and len(results) == 20
    assert 'class="status flagged"' in rows[FLAGGED_RUN] and FLAG in unescape(rows[FLAGGED_RUN])
    reason = results.set_index("run_id").loc[NO_STABLE_RUN, "no_window_reason"]
    assert "no_stable_phase" in rows[NO_STABLE_RUN] and reason in unescape(rows[NO_STABLE_RUN])
    for title in ("Runs", "Time series per run", "Performance curves",
                  "Load interpolation check", "WPM curves as exported"):
        assert f"<h2>{title}</h2>" in text
    assert len(re.findall(r'<div class="lightbox" id="full-run-\d+"', text)) == 20
    assert "120 N: 4 distinct slips, no curve" in unescape(text)
    assert page.stat().st_size < 3_000_000


def test_figures_label_every_axis_with_a_unit_and_share_load_colours(small):
    url, _, _ = small
    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample")
    palette = Palette(data.loads, data.multipasses)
    run = next(r for r in data.runs if r.run_id == "L180_MP0_SC_s+020")
    nsp = next(r for r in data.runs if r.run_id == NO_STABLE_RUN)
    key = ("BB2-like", "ES-3-like sand", 0)
    tested = {}
    for f in data.fits:
        tested.setdefault(f.quantity, []).append(f.load_n)
    figs = {
        "curves": figures.performance_curves(data.points, data.fits, *key[:2],
                                             data.source.statuses, palette),
        "interpolation": figures.load_validation(data.points, data.fits, key, 120.0,
                                                 data.validation[key][1], palette),
        "wpm": figures.wpm_curves(WheelPerformanceModule(data.fits), tested, key[1], key[0],
                                  0, palette),
    }
    for name, fig in figs.items():
        for ax in (a for a in fig.axes if a.axison):
            assert UNIT.search(ax.get_ylabel()), (name, ax.get_ylabel())
            if ax.get_xlabel() or ax is fig.axes[-1]:
                assert UNIT.search(ax.get_xlabel()), (name, ax.get_xlabel())
    # the time series (SVG): every axis with its unit; a run with no stable phase shows its
    # stored traces and the reason
    for record in (run, nsp):
        root = ET.fromstring(timeseries.timeseries_svg(record, palette, "d"))
        labels = [t.text for t in root.iter("text")
                  if t.get("class") in ("ylabel", "xlabel")]
        assert len(labels) == 5 and all(UNIT.search(label) for label in labels), labels
    legend = [t.text for t in root.findall(".//g[@class='legend']/text")]
    assert legend == ["stored trace"]
    title = " ".join(t.text for t in root.findall(".//g[@class='title']/text"))
    assert "digs in" in title
    legend = [t.get_text() for t in figs["curves"].legends[0].get_texts()]
    # the stored fits carry their covariance: the curves' bands are in the legend
    assert legend == ["70 N", "120 N", "180 N", "95 % confidence band", "95 % prediction band",
                      "flagged, not fitted"]
    colour_180 = palette.colour(180.0)
    curve_colours = {line.get_color() for line in figs["curves"].axes[0].lines
                     if len(line.get_xdata()) == figures.CURVE_POINTS}
    assert colour_180 in curve_colours and len(curve_colours) == 2  # 70 and 180 N
    assert palette.colour(70.0) != colour_180 != palette.colour(120.0)
    # the interpolated 120 N curve wears 120 N's colour, its runs' points too
    thick = [line for line in figs["interpolation"].axes[0].lines if line.get_linewidth() >= 3]
    assert [line.get_color() for line in thick] == [palette.colour(120.0)]


def test_embedded_curves_keep_every_load_colour(small):
    """The palette PNG must not merge two loads' colours (e.g. orange into vermilion)."""
    _, _, text = small
    src = re.search(r'<figure class="full" id="curves-\d+"><img src="data:image/png;base64,'
                    r'([^"]+)"', text).group(1)
    image = cv2.imdecode(np.frombuffer(base64.b64decode(src), np.uint8), cv2.IMREAD_COLOR)
    present = {"#%02x%02x%02x" % tuple(int(v) for v in bgr[::-1])
               for bgr in np.unique(image.reshape(-1, 3), axis=0)}
    palette = Palette([70.0, 120.0, 180.0], [0])
    assert {palette.colour(x).lower() for x in (70.0, 120.0, 180.0)} <= present


def test_time_series_shades_the_stable_window(small):
    url, _, _ = small
    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample")
    run = next(r for r in data.runs if r.run_id == "L070_MP0_SC_s+020")
    root = ET.fromstring(timeseries.timeseries_svg(run, Palette(data.loads, data.multipasses),
                                                   "d"))
    # each panel's time axis read back from its printed tick labels (test_report_timeseries)
    for key, m in _maps(root).items():
        windows = m["panel"].findall("rect[@class='window']")
        assert len(windows) == 1, key
        x0 = float(windows[0].get("x"))
        x1 = x0 + float(windows[0].get("width"))
        assert (x0, x1) == pytest.approx(tuple(np.polyval(m["x"], [run.window_start_s,
                                                                      run.window_end_s])),
                                         abs=1.0)


def test_a_run_processed_before_traces_were_stored_is_said_so(small):
    url, _, _ = small
    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample")
    palette = Palette(data.loads, data.multipasses)
    nsp = replace(next(r for r in data.runs if r.run_id == NO_STABLE_RUN), traces=None)
    image = sections.timeseries_image(0, nsp, palette)
    assert image.caption.endswith("trace not stored; re-run swtlab process")
    root = ET.fromstring(image.svg)
    # its DP trace stored by processing (runs with no stable phase always had one) is shown
    legend = [t.text for t in root.findall(".//g[@class='legend']/text")]
    assert legend == ["stored DP trace"]
    maps = _maps(root)
    assert maps["dp_n"]["panel"].find("path[@class='trace']") is not None
    torque = [t.text for t in maps["torque_nm"]["panel"].iter("text")]
    assert torque == [timeseries.NOT_STORED]


def test_without_an_export_the_curves_are_fitted_here_from_ok_runs(small, tmp_path):
    url = _copy_db(small[0], tmp_path)
    with open_database(url).begin() as session:
        for export in session.scalars(select(WpmExport)):
            session.delete(export)
    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample")
    assert not data.source.exported and data.source.statuses == ("ok",)
    dp70 = next(f for f in data.fits if f.quantity == "dp_n" and f.load_n == 70.0)
    at_70 = data.points[data.points["load_n"] == 70.0]
    assert len(at_70) == 8 and dp70.n_points == 7  # the flagged run left out
    assert sections.wpm_section(data, Palette(data.loads, data.multipasses)) is None
    notes = [b.text for b in sections.curves_section(
        data, Palette(data.loads, data.multipasses)).blocks if isinstance(b, Note)]
    assert any("No WPM export" in n for n in notes)


def test_optional_sections_appear_only_with_data(small, tmp_path, fast_timeseries, monkeypatch):
    url = small[0]
    calls = []
    # the registered image-slip section shows on the small campaign (three photographed runs)
    assert '<section id="image-slip"><h2>Image slip against encoder slip</h2>' in small[2]
    monkeypatch.setattr(extensions, "EXTENSIONS", [])  # only this test's extensions below

    def with_data(data, palette):
        calls.append(data.name)
        return Section("image-slip", "Image slip against encoder slip",
                       [Note(f"{len(data.runs)} runs")])

    with open_database(url)() as session:
        data = gather(session, "bb2_sand_sample")
    palette = Palette(data.loads, data.multipasses)
    assert optional_sections(data, palette) == []  # nothing registered
    register(Extension("no-data", lambda data, palette: None))
    register(Extension("image-slip", with_data))
    try:
        found = optional_sections(data, palette)
        assert [s.anchor for s in found] == ["image-slip"] and calls == ["bb2_sand_sample"]
        text = write_report(url, tmp_path / "r.html").read_text()
    finally:
        unregister("no-data")
        unregister("image-slip")
    assert '<section id="image-slip"><h2>Image slip against encoder slip</h2>' in text
    assert "20 runs" in text and '<a href="#image-slip">' in text


def test_page_paths_one_campaign_keeps_the_name_several_get_a_suffix():
    assert page_paths("out/report.html", ["c1"]) == {"c1": Path("out/report.html")}
    paths = page_paths("out/report.html", ["lab A/2026", "lab A 2026", "b"])
    assert paths["b"] == Path("out/report-b.html")
    assert paths["lab A/2026"] == Path("out/report-lab_A_2026.html")
    assert len(set(paths.values())) == 3


def test_cli_writes_one_page_per_campaign(small, tmp_path, capsys, fast_timeseries):
    url = _copy_db(small[0], tmp_path)
    with open_database(url).begin() as session:
        second = Campaign(name="second run-in")
        session.add(second)
        session.flush()
        moved = [r.id for r in session.scalars(select(Run).where(Run.run_id.like("L120%")))]
        session.execute(update(Run).where(Run.id.in_(moved)).values(campaign_id=second.id))
        session.execute(update(TestCondition).where(TestCondition.id.in_(
            select(Run.condition_id).where(Run.id.in_(moved)))).values(campaign_id=second.id))
        assert campaign_names(session) == ["bb2_sand_sample", "second run-in"]
    assert _cli(["--db", url, "-o", str(tmp_path / "r.html"), "--json", "--quiet"]) == 0
    out, err = capsys.readouterr()
    pages = json.loads(out)
    assert [p["campaign"] for p in pages] == ["bb2_sand_sample", "second run-in"]
    assert [Path(p["path"]).name for p in pages] == ["r-bb2_sand_sample.html",
                                                     "r-second_run-in.html"]
    assert all(Path(p["path"]).stat().st_size == p["bytes"] for p in pages) and err == ""
    second_page = Path(pages[1]["path"]).read_text()
    assert "L120_MP0_SC_s+003" in second_page and "L070_MP0_FS" not in second_page
    # --campaign: that page only, to -o itself
    assert _cli(["--db", url, "-o", str(tmp_path / "one.html"), "--campaign",
                 "second run-in"]) == 0
    assert "second run-in" in capsys.readouterr().out and (tmp_path / "one.html").is_file()
    with pytest.raises(LookupError, match="name one with campaign='"):
        write_report(url, tmp_path / "x.html")


@pytest.mark.parametrize("case", ["missing file", "unknown campaign", "empty database"])
def test_cli_errors_are_one_line_with_what_to_do(small, tmp_path, capsys, case):
    url = {"missing file": f"sqlite:///{tmp_path / 'none.sqlite'}",
           "unknown campaign": small[0], "empty database": None}[case]
    if url is None:
        url = f"sqlite:///{tmp_path / 'empty.sqlite'}"
        open_database(url)
    argv = ["--db", url, "-o", str(tmp_path / "r.html")]
    if case == "unknown campaign":
        argv += ["--campaign", "nope"]
    assert _cli(argv) == exit_codes.BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("swtlab report: ")
    assert {"missing file": "run swtlab process", "unknown campaign": "bb2_sand_sample",
            "empty database": "run swtlab process first"}[case] in err
    assert not (tmp_path / "r.html").exists() and not (tmp_path / "none.sqlite").exists()


def test_run_table_shows_each_runs_stored_standard_uncertainty(small):
    url, _, text = small
    with open_database(url)() as session:
        stored = latest_results(session).set_index("run_id")
    header = re.search(r"<section id=\"runs\">.*?<thead><tr>(.*?)</tr>", text).group(1)
    columns = [unescape(h) for h in re.findall(r"<th>(.*?)</th>", header)]
    for name, unit in (("slip", "%"), ("DP", "N"), ("torque", "N·m"), ("sinkage", "mm")):
        assert f"u({name}) [{unit}]" in columns
    row = re.search(r'<tr class="ok"><td><a href="#full-run-\d+">L180_MP0_SC_s\+020</a>(.*?)</tr>',
                    text).group(1)
    cells = ["L180_MP0_SC_s+020", *re.findall(r"<td[^>]*>(.*?)</td>", row)]
    for column, key, scale in (("u(DP) [N]", "dp_n", 1.0), ("u(sinkage) [mm]", "sinkage_m", 1e3),
                               ("u(slip) [%]", "slip", 100.0)):
        assert float(cells[columns.index(column)]) == pytest.approx(
            stored.loc["L180_MP0_SC_s+020", f"{key}_u"] * scale, rel=0.05)  # 2 digits shown
    # GUM 7.2.6 in every row: u with two significant digits, its mean to the same decimal
    body = re.search(r"<section id=\"runs\">.*?<tbody>(.*?)</tbody>", text).group(1)
    checked = 0
    for row in re.findall(r'<tr class="(?:ok|flagged)">(.*?)</tr>', body):
        cells = re.findall(r"<td[^>]*>(.*?)</td>", row)
        for name in ("slip", "DP", "torque", "sinkage"):
            i = next(j for j, c in enumerate(columns) if c.startswith(f"{name} ["))
            mean, u = cells[i], cells[i + 1]
            digits = u.lstrip("0.")
            assert len(digits) == 2 or (len(digits) == 3 and "." not in u), (name, u)
            assert len(mean.partition(".")[2]) == len(u.partition(".")[2]), (name, mean, u)
            checked += 1
    assert checked == 4 * 19
    # beside u( ): what the budgets left out (the sample has no replicates, no calibration keys)
    note = re.search(r"Not measured, so not in u\( \): (.*?)\.", unescape(text)).group(1)
    assert "run-to-run repeatability (" in note and "calibration (" in note


def test_hidden_error_bars_get_a_note_and_repeatability_follows_the_run_table(small):
    _, _, text = small
    page = unescape(text)
    # the sample's U95(DP) is about 0.4 N on an axis of some 200 N: under a marker
    note = re.search(r"Error bars smaller than the markers: U\(drawbar pull\) ≤ ([0-9.]+) N",
                     page)
    assert note and 0.2 < float(note.group(1)) < 1.0
    titles = re.findall(r"<h2>(.*?)</h2>", text)
    assert titles[:3] == ["Runs", "Repeatability", "Time series per run"]
    assert "This campaign has no replicate runs" in page


def test_bands_on_the_interpolation_check_and_a_note_for_curves_without_them(small):
    _, _, text = small
    page = unescape(text)
    section = page[page.index('<section id="interpolation">'):]
    section = section[:section.index("</section>")]
    assert "<th>inside the 95 % prediction band</th>" in section
    inside = re.findall(r"<td class=num>(\d+) of (\d+)</td>", section)
    assert inside and all(int(k) <= int(n) for k, n in inside)
    # the small campaign's curves come from its export: the store keeps each fit's
    # covariance, scatter and factor, so the exported curves have their bands
    assert "These curves carry no uncertainty" not in page
    widths = re.search(r"their largest half-widths: drawbar pull ± ([0-9.e-]+) / ± ([0-9.e-]+) N",
                       page)
    assert widths and 0 < float(widths.group(1)) < float(widths.group(2))
