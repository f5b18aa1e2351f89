"""The gap report as a person reads it (campaign_report.gap): gap.html and the campaign
report's section come from one renderer; the page has units everywhere, reasons in plain
words, no raw JSON, no empty table, no code names, a labelled heatmap."""

from __future__ import annotations

import copy
import math
import re
from html.parser import HTMLParser
from types import SimpleNamespace

import pytest

from campaign_report.figures import gap_heatmap
from campaign_report.gap import (_folds_text, candidate_text, decisive_test_text, gap_page,
                                 gap_section, plain, significant_regions, write_gap_page)
from campaign_report.html import Heading, Image, render_page
from campaign_report.style import EFFECTS, PARAMETERS, value_text
import terramechanics as tm
from sim_gap.candidates import effect_params, soil_params
from sim_gap.diagnose import diagnose
from sim_gap.report import build_report
from sim_gap.simulated import Simulated
from test_report_browser import CHROMIUM, probe
from test_sim_gap_decide import BASE, FAST, synthetic_points

#: numeric columns that count things and so have no unit
COUNTS = {"rank", "multipass", "free parameters"}
#: code names of the JSON that must not reach the page
CODE_NAMES = re.compile(r"\b(dp_n|torque_nm|sinkage_m|resistance_n|soil_only|mp\d|"
                        r"soil\.\w+|effects\.\w+|slip_sinkage|reduced_gravity|wheel_flexibility|"
                        r"held_out\w*|shrink_pct)\b|m/s\^2|\bsigma\b")


@pytest.fixture(scope="module")
def report() -> dict:
    """A real diagnosis: hidden slip sinkage, one gravity (reduced gravity untestable)."""
    truth = BASE.with_soil(kphi=2.3e7).with_effects(slip_sinkage={"n1": 0.7})
    points = synthetic_points(truth, loads=(80.0, 300.0), slips=(0.1, 0.4, 0.7))
    diagnosis = diagnose(points, Simulated(BASE), ["slip_sinkage", "reduced_gravity",
                                                   "bulldozing"], FAST)
    return build_report(diagnosis, "lab.sqlite", "sim.toml")


class Page(HTMLParser):
    """Visible text, tables (header, rows, numeric columns) and images of a page."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.text, self.tables, self.images, self._skip, self._cell = [], [], [], 0, None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("style", "script", "title"):
            self._skip += 1
        elif tag == "table":
            self.tables.append({"header": [], "rows": [], "numeric": set()})
        elif tag == "tr" and self.tables:
            self.tables[-1]["rows"].append([])
        elif tag in ("th", "td"):
            self._cell = [tag, "num" in (a.get("class") or "")]
            self._cell_text = []
        elif tag == "img":
            self.images.append(a)

    def handle_endtag(self, tag):
        if tag in ("style", "script", "title"):
            self._skip -= 1
        elif tag in ("th", "td") and self._cell:
            kind, numeric = self._cell
            table, text = self.tables[-1], "".join(self._cell_text).strip()
            if kind == "th":
                table["header"].append(text)
            else:
                if numeric:
                    table["numeric"].add(len(table["rows"][-1]))
                table["rows"][-1].append(text)
            self._cell = None

    def handle_data(self, data):
        if not self._skip:
            self.text.append(data)
            if self._cell:
                self._cell_text.append(data)


def sig3(x: float) -> str:
    """``x`` rounded to three significant digits, as plain decimals."""
    decimals = 2 - math.floor(math.log10(abs(x)))
    text = f"{round(x, decimals):.{max(0, decimals)}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def check_page(html: str) -> Page:
    page = Page(html)
    text = " ".join(page.text)
    assert '{"' not in text and "{'" not in text, "raw JSON on the page"
    assert not CODE_NAMES.search(text), CODE_NAMES.search(text).group(0)
    assert page.tables
    for table in page.tables:
        rows = [r for r in table["rows"] if r]  # the header row holds no td
        assert rows, f"empty table {table['header']}"
        for j in table["numeric"]:
            header = table["header"][j]
            assert header in COUNTS or re.search(r"\[[^\]]+\]", header), header
    heatmaps = [i for i in page.images if "Residual map" in (i.get("alt") or "")]
    assert heatmaps and all(i["src"].startswith("data:image/png;base64,") for i in heatmaps)
    return page


def test_gap_page_reads_as_plain_words_with_units(report, tmp_path):
    assert report["untestable_effects"].keys() == {"reduced_gravity"}
    path = write_gap_page(report, tmp_path / "gap.html")
    page = check_page(path.read_text(encoding="utf-8"))
    text = " ".join(page.text)
    assert "Reduced gravity: not testable with this campaign; it changes no prediction" in text
    assert "gravity level other than standard gravity (9.80665 m/s²)" in text
    # the fitted soil of the best explanation, in display units (kN, mm), 3 significant digits
    best = report["candidates"][0]["parameters"]
    assert f"k_φ (frictional modulus) = {sig3(best['soil.kphi'] / 1000)} kN/m^(n+2)" in text
    assert f"K (shear deformation modulus) = {sig3(best['soil.shear_modulus_m'] * 1000)} mm" \
        in text
    # hidden slip sinkage: significant regions against the simulation as given, tabled
    assert any(r["significant"] for r in report["regions"])
    assert any("load [N]" in t["header"] for t in page.tables)
    # the held-out RMSE table: drawbar pull before, in N
    (rmse,) = [t for t in page.tables if t["header"][0] == "held-out RMSE"]
    assert rmse["header"][1:] == ["drawbar pull [N]", "torque [N·m]", "sinkage [mm]",
                                  "motion resistance [N]"]
    before = next(r for r in rmse["rows"] if r and r[0].endswith("soil recalibration only"))
    assert before[1] == sig3(report["held_out_rmse_before"]["dp_n"])
    assert before[3] == sig3(report["held_out_rmse_before"]["sinkage_m"] * 1000)

def test_no_empty_table_and_region_sentence(report):
    """No significant region: a sentence instead of a table; an unexplained gap is told by
    its region in words and units."""
    quiet = copy.deepcopy(report)
    for r in quiet["regions"]:
        r["significant"] = r["significant_soil_recalibrated"] = False
    region = dict(quiet["regions"][0], quantity="dp_n", slip_band="[0.2,0.4)",
                  mean_residual_soil_recalibrated=3.7, z_soil_recalibrated=9.8)
    quiet["regions"][0] = region
    quiet["verdict"], quiet["reason"] = "inconclusive", (
        "the best explanation (soil_only) leaves a held-out gap of 7.2 sigma RMS: an effect "
        "outside the candidate set, or more than two missing effects")
    quiet["separating_test"] = {"test": "largest residual dp_n ...", "separation_sigma": None,
                                "region": {k: region[k] for k in (
                                    "slip_band", "load_n", "multipass", "gravity_mps2",
                                    "quantity")}}
    page = check_page(render_page(gap_page(quiet)))
    assert [t for t in page.tables if "load [N]" in t["header"]] == []  # no regions table
    text = " ".join(page.text)
    assert "0 of" in text and "differ significantly" in text
    assert ("misses most in drawbar pull at slips 20 to 40 %, "
            f"{region['load_n']:g} N, multipass 0, 9.81 m/s²: mean residual +3.7 N "
            "(z = 9.8)") in text
    assert "leaves a held-out gap of 7.2 σ RMS" in text and "(soil recalibration only)" in text


def test_campaign_section_and_gap_page_share_the_renderer(report):
    data = SimpleNamespace(extras={"gap": {"sim_source": "sim.toml", "report": report}})
    section = gap_section(data, palette=None)
    page = gap_page(report)
    assert section.blocks[1:] == page.sections[0].blocks  # the same blocks, PNGs included
    assert isinstance(section.blocks[1], Heading) and section.blocks[1].text.startswith(
        "Verdict: ")
    assert sum(isinstance(b, Image) for b in section.blocks) == 2  # as given, recalibrated


def test_heatmap_axes_and_colour_in_percent_of_load(report):
    fig = gap_heatmap(report["regions"])
    panels = [ax for ax in fig.axes if ax.get_images()]
    titles = [ax.get_title() for ax in panels]
    assert titles == ["Drawbar pull", "Torque", "Sinkage", "Motion resistance"]
    assert all(ax.get_xlabel() == "slip band [%]" for ax in panels)
    assert panels[0].get_ylabel() == "load, multipass"
    bars = [ax.get_ylabel() for ax in fig.axes if not ax.get_images()]
    assert bars == ["measured − simulated [% of W]", "measured − simulated [% of W·r]",
                    "measured − simulated [% of r]", "measured − simulated [% of W]"]
    # top-left cell: lowest load, multipass 0, lowest slip band; 100 * residual / load
    cell = next(r for r in report["regions"] if r["quantity"] == "dp_n" and r["load_n"] == 80
                and r["multipass"] == 0 and r["slip_band"] == "[0.0,0.2)")
    grid = panels[0].get_images()[0].get_array()
    assert grid[0, 0] == pytest.approx(100 * cell["mean_residual"] / 80.0, rel=1e-9)
    assert [t.get_text() for t in panels[0].get_xticklabels()] == ["0 to 20", "40 to 60",
                                                                   "60 to 100"]


def test_plain_words_and_display_units():
    assert candidate_text("slip_sinkage+grousers") == "slip sinkage + grousers"
    assert plain("slip_sinkage+grousers improves on soil-only recalibration by only 3.1 SE "
                 "(40 % of the held-out loss)", ["slip_sinkage+grousers"]) == (
        "Slip sinkage + grousers improves on soil-only recalibration by only 3.1 standard "
        "errors (40 % of the held-out loss).")
    # candidates with their laws, effect sets and law keys in a law-dependent reason
    assert candidate_text("grousers(ding2011)+reduced_gravity(wong_kobayashi2012)") == (
        "grousers (Ding 2011) + reduced gravity (Wong & Kobayashi 2012)")
    assert candidate_text("grousers(bekker1956~slip)+bulldozing(rankine_terzaghi1943~depth)") == (
        "grousers (Bekker 1956, with the lugs' slip-sinkage) + bulldozing (Rankine & Terzaghi "
        "1943, resistance varying with rut depth)")
    keys = ["slip_sinkage(ding2011)", "grousers(ding2011)+slip_sinkage(lyasko2010)"]
    assert plain("under the best-fitting laws the verdict is slip_sinkage (slip_sinkage"
                 "(ding2011)), but with slip_sinkage under lyasko2010 it is grousers+slip_sinkage "
                 "(grousers(ding2011)+slip_sinkage(lyasko2010)) on ding2011_lug10", keys) == (
        "Under the best-fitting laws the verdict is slip sinkage (slip sinkage (Ding 2011)), "
        "but with slip sinkage under Lyasko 2010 it is grousers + slip sinkage (grousers "
        "(Ding 2011) + slip sinkage (Lyasko 2010)) on ding2011_lug10.")
    # a level-contrast reason (sim_gap.contrast_check) names a quantity and an effect
    assert plain("the residuals of sinkage_m at multipass level 1 differ from their twin runs' "
                 "at multipass level 0 by -4.44 sigma (11.0 SE over 24 pairs), which no effect "
                 "of the call explains: an effect tied to the multipass level (multipass, or "
                 "another) may be missing", ["reduced_gravity(reece1965)"]) == (
        "The residuals of sinkage at multipass level 1 differ from their twin runs' at "
        "multipass level 0 by -4.44 σ (11.0 standard errors over 24 pairs), which no effect "
        "of the call explains: an effect tied to the multipass level (multipass, or another) "
        "may be missing.")
    for effect, laws in tm.LAWS.items():
        for law in laws:
            assert "_" not in candidate_text(f"{effect}({law})")
    two = {"candidates": [], "decision": {"leaders": ["grousers", "slip_sinkage"]},
           "separating_test": {
        "test": "test at another gravity (3.71 m/s^2, gravity-offload rig or parabolic flight)",
        "separation_sigma": 5.25}}
    assert decisive_test_text(two) == (
        "Test that would decide: test at another gravity (3.71 m/s², gravity-offload rig or "
        "parabolic flight); grousers and slip sinkage differ there by 5.25 σ (of the "
        "repeatability floor).")
    assert _folds_text(["load=70", "load=120", "multipass=0", "multipass=1", "multipass=2"]) \
        == "each load (70 N, 120 N); each multipass (0, 1, 2)"
    assert _folds_text(["slip band 0", "slip band 4"]) == \
        "each slip band (-100 to 0 %, 60 to 100 %)"
    # 1.8e7 N/m^(n+2) = 18 000 kN/m^(n+2); K 0.0096 m = 9.6 mm; 30e3 N/m = 30 kN/m
    assert value_text(PARAMETERS["soil.kphi"], 1.8e7) == "18000 kN/m^(n+2)"
    assert value_text(PARAMETERS["soil.shear_modulus_m"], 0.0096) == "9.6 mm"
    assert value_text(PARAMETERS["effects.wheel_flexibility.radial_stiffness_n_m"],
                      3e4) == "30 kN/m"
    assert value_text(PARAMETERS["soil.friction_angle_deg"], 36.604) == "36.6°"
    # every parameter a candidate can free (each law of each effect), and every effect, has a
    # plain name
    fitted = {p.name for p in soil_params(BASE)} | {
        p.name for effect, laws in tm.LAWS.items() for law in laws
        for p in effect_params(effect, law)}
    assert fitted - set(PARAMETERS) == set() and set(tm.LAWS) <= set(EFFECTS)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (.ci/chromium.sh)")
def test_gap_page_opens_in_chromium_and_every_image_decodes(report, tmp_path):
    page = write_gap_page(report, tmp_path / "gap.html")
    found, console = probe(page, tmp_path)
    assert found["images"] == 2 and found["decoded"] == ["ok", "ok"]
    assert found["faults"] == [] and console == []


def test_significant_regions_keeps_the_strongest_twelve():
    """20 regions, drawbar pull at |z| = 0.5 and sinkage at |z| = region index in each, every
    cell with z != 0 significant: kept are the regions of largest |z|, 19 down to 8."""
    regions = [{"slip_band": "[0.0,0.2)", "load_n": float(i), "multipass": 0,
                "gravity_mps2": 9.807, "quantity": q, "z": z, "significant": z != 0}
               for i in range(20) for q, z in (("dp_n", 0.5), ("sinkage_m", -float(i)))]
    keys = significant_regions(regions, "")
    assert [k[1] for k in keys] == [float(i) for i in range(19, 7, -1)]
