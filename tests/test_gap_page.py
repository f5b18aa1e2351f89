"""The gap report as a person reads it (campaign_report.gap): gap.html and the campaign
report's section come from one renderer; the page has units everywhere, no raw JSON, no
empty table, no code names outside the reason (shown as written), and its numbers are the
JSON's.

The schema-2 report is a real diagnosis of published data (Ding et al. 2011, the smooth
and the 10 mm lug wheel on one soil, against the simulation calibrated on the smooth wheel;
docs/gap-report.md); its verdict is not asserted here (that is sim_gap's), only that the page
says what the JSON says. The wording of each kind of verdict is checked on decisions
``sim_gap.decide.decide`` makes from that report's hypotheses with other probabilities. The
schema-1 report (tests/data/gap_report_v1_ding2011.json) was written by swtlab 0.13.0
(``swtlab gap --measured sim_gap/data/ding2011_points.csv --sim
sim_gap/models/ding2011_smooth_calibrated.toml --json ...`` at commit bf683d5)."""

from __future__ import annotations

import base64
import copy
import io
import json
import math
import re
from html import escape
from html.parser import HTMLParser
from pathlib import Path
from types import SimpleNamespace

import pytest
from matplotlib.container import ErrorbarContainer
from PIL import Image as PILImage

import terramechanics as tm
from campaign_report.figures import gap_curves, gap_heatmap, gap_probabilities
from campaign_report.gap import (_folds_text, _verdict_blocks, candidate_text, set_text,
                                 decisive_test_text, gap_blocks, gap_page, gap_section,
                                 law_text, significant_regions, write_gap_page)
from campaign_report.html import Heading, Image, Note
from campaign_report.style import EFFECTS, PARAMETERS, QUANTITIES, Palette, value_text
from sim_gap.api import gap_report
from sim_gap.candidates import effect_params, soil_params
from sim_gap.decide import by_effect_set, decide
from sim_gap.diagnose import Settings
from sim_gap.hypotheses import OUTSIDE
from sim_gap.measured import load_measured
from sim_gap.report import READABLE_SCHEMAS
from sim_gap.report_types import EffectSet, GapReport, Hypothesis, Law, RankedCandidate
from sim_gap.simulated import Simulated
from test_report_browser import CHROMIUM, probe

ROOT = Path(__file__).resolve().parents[1]
DING_POINTS = ROOT / "sim_gap" / "data" / "ding2011_points.csv"
DING_SMOOTH_CALIBRATED = ROOT / "sim_gap" / "models" / "ding2011_smooth_calibrated.toml"
SCHEMA_1_REPORT = Path(__file__).parent / "data" / "gap_report_v1_ding2011.json"
#: numeric columns without a unit: counts, probabilities, natural-log evidence
UNITLESS = {"rank", "multipass", "free parameters", "probability", "log evidence"}
#: code names of the JSON that must not reach the page (outside the reason, shown as written)
CODE_NAMES = re.compile(r"\b(dp_n|torque_nm|sinkage_m|resistance_n|soil_only|mp\d|"
                        r"outside_candidates|soil\.\w+|effects\.\w+|slip_sinkage|"
                        r"reduced_gravity|wheel_flexibility|held_out\w*|shrink_pct|"
                        r"[a-z]+\d{4})\b|m/s\^2|\bsigma\b")
REASON = "Reason, as the diagnosis writes it: "
OUTSIDE_WORDS = ("outside the candidate effects", "No candidate effect explains the gap")


@pytest.fixture(scope="module")
def report() -> dict:
    """A real schema-2 diagnosis: Ding 2011's smooth and lug wheel against the simulation
    calibrated on the smooth wheel (fewer fit evaluations than the CLI's, for speed)."""
    points = load_measured(str(DING_POINTS))
    sim = Simulated(tm.load_model(DING_SMOOTH_CALIBRATED))
    return json.loads(json.dumps(gap_report(  # as read back from the JSON file
        points, sim, "ding2011_points.csv", "ding2011_smooth_calibrated.toml",
        settings=Settings(max_nfev=20, fold_nfev=2, n_boot=10))))


@pytest.fixture(scope="module")
def page_file(report, tmp_path_factory) -> Path:
    """The page of :func:`report`, written once."""
    return write_gap_page(GapReport.from_json(report),
                          tmp_path_factory.mktemp("gap") / "gap.html")


@pytest.fixture(scope="module")
def report_v1() -> dict:
    return json.loads(SCHEMA_1_REPORT.read_text(encoding="utf-8"))


class Page(HTMLParser):
    """Visible text (per paragraph), tables (header, rows, numeric columns) and images."""

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

    @property
    def words(self) -> str:
        """The visible text but the reason (shown as the JSON writes it)."""
        return " ".join(t for t in self.text if not t.startswith(REASON))

    def table(self, first_header: str) -> dict:
        (found,) = [t for t in self.tables if t["header"][0] == first_header]
        return found


def check_page(html: str) -> Page:
    page = Page(html)
    text = page.words
    assert '{"' not in text and "{'" not in text, "raw JSON on the page"
    assert not CODE_NAMES.search(text), CODE_NAMES.search(text).group(0)
    assert page.tables
    for table in page.tables:
        rows = [r for r in table["rows"] if r]  # the header row holds no td
        assert rows, f"empty table {table['header']}"
        for j in table["numeric"]:
            header = table["header"][j]
            assert header in UNITLESS or re.search(r"\[[^\]]+\]", header), header
    for image in page.images:  # every figure a PNG that decodes, with its alt text
        assert image["alt"] and image["src"].startswith("data:image/png;base64,")
        png = PILImage.open(io.BytesIO(base64.b64decode(image["src"].split(",", 1)[1])))
        png.load()
        assert png.width > 300 and png.height > 150
    return page


def cut3(p: float) -> str:
    """``p`` to three decimals, cut (never rounded up to the call probability)."""
    return f"{math.floor(p * 1000.0 + 1e-9) / 1000.0:.3f}"


def probability_shown(cell: str, p: float) -> bool:
    """A page's probability equals the JSON's: cut to three decimals, or ``< 0.001``."""
    if cell == "< 0.001":
        return p < 0.001
    return float(cell) <= p < float(cell) + 0.001 + 1e-12


def test_schema2_page_says_what_the_json_says(report, page_file):
    page = check_page(page_file.read_text("utf-8"))
    text = " ".join(page.text)
    heading = next(t for t in page.text if t.startswith("Verdict: "))
    if report["verdict"] == "inconclusive":
        assert heading == "Verdict: inconclusive"
    else:
        shown = re.fullmatch(r"Verdict: .* \(probability (\S+)\)", heading).group(1)
        assert probability_shown(shown, report["probability"])
    assert ("A verdict names a hypothesis only when its probability is at least "
            f"{report['call_probability']:g}.") in text
    assert REASON + report["reason"] in page.text  # as written
    # the hypotheses table: each row's probability and log evidence are the JSON's
    table = page.table("rank")
    assert table["header"] == ["rank", "effect set", "laws", "probability", "log evidence",
                               "fitted strengths"]
    for row, h in zip(table["rows"][1:], report["hypotheses"]):
        assert probability_shown(row[3], h["probability"])
        assert float(row[4]) == pytest.approx(h["log_evidence"], abs=0.05)
        for name, value in h["parameters"].items():
            if name.startswith("effects."):
                assert f"{PARAMETERS[name].label} = {value_text(PARAMETERS[name], value)}" \
                    in row[5]
        for effect, law in h["laws"].items():
            assert f"{EFFECTS[effect]}: {law_text(Law.of(effect, law))}" in row[2]
    assert len(table["rows"]) - 1 == min(8, len(report["hypotheses"]))
    # the noise: where it came from, per quantity
    noise = next(t for t in page.text if t.startswith("Noise (the error bars, σ): "))
    for q, source in report["noise"].items():
        assert source.partition(":")[0] in noise and QUANTITIES[q].label in noise
    # the sibling contrasts: the lugged wheel minus its smooth twin, measured and predicted
    contrasts = report["sibling_contrasts"]
    assert {c["feature"] for c in contrasts} == {"grousers"}
    table = page.table("contrast")
    measured = table["rows"][1]
    assert measured[:3] == ["the lugged wheel minus its smooth twin", "80", "measured (± 95 %)"]
    for c in contrasts:
        q = QUANTITIES[c["quantity"]]
        j = table["header"].index(q.axis_label)
        value, half = (float(x) for x in measured[j].split(" ± "))
        decimals = len(measured[j].split(" ± ")[1].partition(".")[2])
        assert value == pytest.approx(c["contrast"] * q.scale, abs=0.51 * 10 ** -decimals)
        assert half == pytest.approx((c["ci95"][1] - c["ci95"][0]) / 2 * q.scale,
                                     abs=0.51 * 10 ** -decimals)
        chosen_row = next(r for r in table["rows"] if r and r[2].startswith("with "))
        assert float(chosen_row[j]) == pytest.approx(
            c["predicted"][report["chosen"]] * q.scale, abs=0.51 * 10 ** -decimals)
    sentence = next(t for t in page.text if t.startswith("The lugged wheel minus its smooth "
                                                         "twin: ") and "drawbar pull" in t)
    dp = next(c for c in contrasts if c["quantity"] == "dp_n")
    assert f"of drawbar pull at 80 N (95 % interval; slips 0 to 60 %, {dp['n']} matched runs)" \
        in sentence
    chosen = GapReport.from_json(report).explanation(report["chosen"])
    assert f"predicted by {candidate_text(chosen)}: " in sentence
    # the figures: probabilities, curves, two residual maps
    alts = [i["alt"] for i in page.images]
    assert alts[0].startswith("Posterior probability of each effect set")
    assert alts[1].startswith("Measured values ± σ against slip per load (rows: "
                              "ding2011_smooth, ding2011_lug10), beside the simulation as given")
    assert sum(a.startswith("Residual map") for a in alts) == 2 and len(alts) == 4


def test_probability_chart_bars_are_the_effect_sets(report):
    sets = [(candidate_text(EffectSet.from_json(s)), s["probability"])
            for s in report["effect_sets"]]
    fig = gap_probabilities(sets, 0.9)
    (ax,) = fig.axes
    widths = [p.get_width() for p in ax.patches]
    assert widths == pytest.approx([s["probability"] for s in report["effect_sets"]])
    assert [t.get_text() for t in ax.get_yticklabels()] == [s[0] for s in sets]
    assert [line.get_xdata()[0] for line in ax.lines] == [0.9]


def test_curves_are_the_measured_points_and_the_predictions(report):
    """The lug wheel's drawbar pull panel: the error bars are the points' measured values ±
    σ, the lines each prediction at the points' slips, in N against slip in %."""
    rows = [p for p in report["points"] if p["source"] == "ding2011_lug10"]
    names = {"simulation": "as given", "soil_only": "soil", report["chosen"]: "chosen"}
    fig = gap_curves([("lug", rows)], ["dp_n", "sinkage_m"], names,
                     Palette([80.0], [0]))
    dp_ax, sinkage_ax = fig.axes[:2]
    (bars,) = [c for c in dp_ax.containers if isinstance(c, ErrorbarContainer)]
    line, _, (segments,) = bars.lines
    mine = sorted((p for p in rows if "dp_n" in p), key=lambda p: p["slip"])
    assert line.get_xdata() == pytest.approx([100 * p["slip"] for p in mine])
    assert line.get_ydata() == pytest.approx([p["dp_n"]["measured"] for p in mine])
    half = [abs(s[1][1] - s[0][1]) / 2 for s in segments.get_segments()]
    assert half == pytest.approx([p["dp_n"]["sigma"] for p in mine])
    drawn = [ln.get_ydata() for ln in dp_ax.lines if ln.get_linestyle() != "None"]
    assert len(drawn) == len(names)
    for key, ydata in zip(names, drawn):
        assert ydata == pytest.approx([p["dp_n"][key] for p in mine])
    sinkage = [ln.get_ydata() for ln in sinkage_ax.lines if ln.get_linestyle() != "None"][-1]
    assert sinkage == pytest.approx([1000 * p["sinkage_m"][report["chosen"]] for p in
                                     sorted(rows, key=lambda p: p["slip"])])
    assert (dp_ax.get_xlabel(), dp_ax.get_ylabel()) == ("slip [%]", "drawbar pull [N]")
    assert sinkage_ax.get_ylabel() == "sinkage [mm]"


def verdict_words(report: dict) -> Page:
    """The verdict's part of the page (heading, rule, reason, next test) as the page shows
    it, checked like the whole page (no JSON, no code name but in the reason)."""
    blocks = _verdict_blocks(GapReport.from_json(report))
    html = "".join(f"<p>{escape(b.text)}</p>" for b in blocks)
    page = Page(html)
    assert not CODE_NAMES.search(page.words), CODE_NAMES.search(page.words).group(0)
    return page


def _redecided(report: dict, probabilities: dict[str, float], separation=None) -> dict:
    """``report`` with its hypotheses given other probabilities (by key, the rest shared
    equally) and the decision ``sim_gap.decide.decide`` makes of them."""
    out = copy.deepcopy(report)
    rest = [h for h in out["hypotheses"] if h["key"] not in probabilities]
    left = (1.0 - sum(probabilities.values())) / len(rest)
    for h in out["hypotheses"]:
        h["probability"] = probabilities.get(h["key"], left)
    out["hypotheses"].sort(key=lambda h: -h["probability"])
    decision = decide(out["hypotheses"], separation)
    out.update({k: decision[k] for k in ("verdict", "probability", "reason", "leaders",
                                         "chosen", "call_probability")})
    out["effect_sets"] = by_effect_set(out["hypotheses"])
    return out


def test_inconclusive_names_the_leaders_and_never_the_outside(report):
    """Two named hypotheses the points cannot tell apart: the page gives both with their
    probabilities, the reason as written (that these points cannot tell them apart) and
    the next test; nothing about a gap outside the candidates, although the real report's
    test points there."""
    named = [h for h in report["hypotheses"] if h["key"] != OUTSIDE]
    first = named[0]
    second = next(h for h in named if h["label"] != first["label"])
    tied = _redecided(report, {first["key"]: 0.48, second["key"]: 0.47}, separation=0.4)
    assert tied["verdict"] == "inconclusive" and "cannot tell them apart" in tied["reason"]
    tied["separating_test"] = {"test": "add skid (braked) slips (-0.5, -0.2)",
                               "separation_sigma": 2.5}
    page = verdict_words(tied)
    text = " ".join(page.text)
    assert "Verdict: inconclusive" in page.text
    sets = {s["label"]: EffectSet.from_json(s) for s in tied["effect_sets"]}
    leaders = ", ".join(f"{set_text(sets[x['label']])} {cut3(x['probability'])}"
                        for x in tied["leaders"])
    assert f"None reaches it here; the most probable: {leaders}." in text
    assert REASON + tied["reason"] in page.text
    who = (f"{candidate_text(Hypothesis.from_json(first))} and "
           f"{candidate_text(Hypothesis.from_json(second))}")
    assert (f"Next test: add skid (braked) slips (-0.5, -0.2); {who} differ there by up to "
            "2.5 σ (σ: the repeatability floor).") in page.text
    tied["separating_test"] = None
    tied["next_tests"] = [
        {"kind": "smooth wheel", "test": "a smooth wheel (same rim, no grousers) on the same "
         "soil at 80 N, slips 0.2, 0.4 (2 runs)", "gain_bits": 0.52, "n_runs": 2},
        {"kind": "gravity", "test": "another gravity level (3.71 m/s^2: a gravity-offload rig "
         "or a parabolic flight) at 80 N, slips 0.2 (1 run)", "gain_bits": 0.314, "n_runs": 1}]
    entropy = -sum(s["probability"] * math.log2(s["probability"])
                   for s in tied["effect_sets"] if s["probability"] > 0)
    assert (f"Next test, by the information it is expected to give about which explanation is "
            f"right (the probabilities above leave {entropy:.2f} bit uncertain): 1. a smooth "
            "wheel (same rim, no grousers) on the same soil at 80 N, slips 0.2, 0.4 (2 runs): "
            "expected gain 0.52 bit; 2. another gravity level (3.71 m/s²: a gravity-offload "
            "rig or a parabolic flight) at 80 N, slips 0.2 (1 run): expected gain 0.31 bit."
            ) in verdict_words(tied).text
    assert not any(w in text for w in OUTSIDE_WORDS)
    region = report["regions"][0]  # a region test (written for an outside verdict) is not told
    tied["separating_test"] = {"test": "no candidate test separates: the gap lies outside the "
                               "candidate effects", "separation_sigma": None,
                               "region": {k: region[k] for k in (
                                   "slip_band", "load_n", "multipass", "gravity_mps2",
                                   "quantity")}}
    text = " ".join(verdict_words(tied).text)
    assert not any(w in text for w in OUTSIDE_WORDS)


def test_a_call_and_the_outside_verdict_in_words(report):
    pair = next(h for h in report["hypotheses"] if len(h["effects"]) == 2)
    called = _redecided(report, {pair["key"]: 0.93})
    assert called["verdict"] == pair["effects"]
    page = verdict_words(called)
    assert ("Verdict: the simulation lacks "
            + " and ".join(EFFECTS[e] for e in pair["effects"])
            + f" (probability {cut3(called['probability'])})") in page.text
    assert not any(w in page.words for w in OUTSIDE_WORDS)
    outside = _redecided(report, {OUTSIDE: 0.95})
    region = report["regions"][0]
    outside["separating_test"] = {"test": "(the report's words)", "separation_sigma": None,
                                  "region": {k: region[k] for k in (
                                      "slip_band", "load_n", "multipass", "gravity_mps2",
                                      "quantity")}}
    page = verdict_words(outside)
    assert ("Verdict: the gap lies outside the candidate effects (probability "
            f"{cut3(outside['probability'])})") in page.text
    q = QUANTITIES[region["quantity"]]
    assert (f"No candidate effect explains the gap. After soil recalibration the simulation "
            f"misses most in {q.label} at slips 0 to 20 %, 80 N, multipass 0, 9.81 m/s²: "
            "mean residual ") in " ".join(page.text)


def test_schema1_report_still_renders(report_v1, tmp_path):
    assert report_v1["schema"] == READABLE_SCHEMAS[0]
    page = check_page(write_gap_page(GapReport.from_json(report_v1),
                                     tmp_path / "gap.html").read_text("utf-8"))
    text = " ".join(page.text)
    assert "Verdict: inconclusive" in page.text
    assert REASON + report_v1["reason"] in page.text
    assert ("Next test: more slips above 0.5 (0.6, 0.75, 0.9); grousers (Ding 2011) and soil "
            "recalibration only differ there by up to 39.8 σ") in text
    table = page.table("rank")
    for row, c in zip(table["rows"][1:], report_v1["candidates"]):
        assert row[1] == candidate_text(RankedCandidate.from_json(c))
        assert float(row[2]) == pytest.approx(c["held_out_score"], rel=5e-3)
    rmse = page.table("held-out RMSE")
    before = next(r for r in rmse["rows"] if r and r[0] == "before: soil recalibration only")
    assert float(before[1]) == pytest.approx(report_v1["held_out_rmse_before"]["dp_n"],
                                             rel=5e-3)
    assert float(before[3]) == pytest.approx(
        report_v1["held_out_rmse_before"]["sinkage_m"] * 1000, rel=5e-3)
    assert sum("Residual map" in i["alt"] for i in page.images) == len(page.images) == 2


def test_an_unknown_schema_is_said_not_guessed(report):
    newer = dict(report, schema="swtlab.gap-report/9")
    data = SimpleNamespace(extras={"gap": {"sim_source": "sim.toml", "report": newer}})
    (note,) = gap_section(data, palette=None).blocks
    assert isinstance(note, Note) and note.warning
    assert note.text.startswith("This gap report has schema swtlab.gap-report/9")


def test_campaign_section_and_gap_page_share_the_renderer(report, monkeypatch):
    """The same blocks in both; each figure stands for its drawn data (titles, lines) instead
    of its PNG, which takes seconds to encode (the page's PNGs are checked above)."""
    def drawn(fig):
        return repr([(ax.get_title(), [list(ln.get_ydata()) for ln in ax.lines])
                     for ax in fig.axes]).encode(), None

    monkeypatch.setattr("campaign_report.gap.to_png", drawn)
    data = SimpleNamespace(extras={"gap": {"sim_source": "sim.toml", "report": report}})
    section = gap_section(data, palette=None)
    page = gap_page(GapReport.from_json(report))
    assert section.blocks[1:] == page.sections[0].blocks
    assert isinstance(section.blocks[1], Heading) and section.blocks[1].text.startswith(
        "Verdict: ")
    assert sum(isinstance(b, Image) for b in section.blocks) == 4


def test_heatmap_axes_and_colour_in_percent_of_load(report):
    fig = gap_heatmap(report["regions"])
    panels = [ax for ax in fig.axes if ax.get_images()]
    assert [ax.get_title() for ax in panels] == ["Drawbar pull", "Torque", "Sinkage"]
    assert all(ax.get_xlabel() == "slip band [%]" for ax in panels)
    assert panels[0].get_ylabel() == "load"
    bars = [ax.get_ylabel() for ax in fig.axes if not ax.get_images()]
    assert bars == ["measured − simulated [% of W]", "measured − simulated [% of W·r]",
                    "measured − simulated [% of r]"]
    # first cell: the load's lowest slip band; 100 * residual / load
    cell = next(r for r in report["regions"] if r["quantity"] == "dp_n"
                and r["slip_band"] == "[0.0,0.2)")
    grid = panels[0].get_images()[0].get_array()
    assert grid[0, 0] == pytest.approx(100 * cell["mean_residual"] / 80.0, rel=1e-9)
    assert [t.get_text() for t in panels[0].get_xticklabels()] == [
        "0 to 20", "20 to 40", "40 to 60", "60 to 100"]


REFERENCE_REPORT = ROOT / "tests" / "reference" / "sample_campaign" / "gap.json"


def test_the_reference_reports_name_their_laws_as_the_pattern_matching_did(monkeypatch):
    """The hypotheses, laws and chosen explanation in words, from the typed report's fields,
    as the regular expression over the law keys wrote them (swtlab 0.15.0): the sample
    campaign's stored report (schema 2) and the 0.13.0 report (schema 1)."""
    monkeypatch.setattr("campaign_report.gap.to_png", lambda fig: (b"", None))
    blocks = gap_blocks(GapReport.from_json(json.loads(REFERENCE_REPORT.read_text("utf-8"))))
    texts = [b.text for b in blocks if isinstance(b, (Heading, Note))]
    (table,) = [b for b in blocks if getattr(b, "header", [""])[0] == "rank"]
    assert {tuple(row[1:3]) for row in table.rows} == {
        ("no missing effect", "—"), ("an effect outside the candidates", "—"),
        ("bulldozing", "bulldozing: Rankine & Terzaghi 1943"),
        ("bulldozing", "bulldozing: Rankine & Terzaghi 1943, resistance varying with rut "
                       "depth"),
        ("bulldozing", "bulldozing: Bekker 1969"),
        ("bulldozing", "bulldozing: Bekker 1969, resistance varying with rut depth")}
    cut = math.floor(json.loads(REFERENCE_REPORT.read_text("utf-8"))["probability"] * 1000)
    assert f"Verdict: no missing effect (probability {cut / 1000:.3f})" in texts
    assert any(t.startswith("Soil fitted under the most probable named hypothesis (soil "
                            "recalibration only): ") for t in texts)
    assert "How far: held-out RMSE of soil recalibration only (no effect chosen)" in texts
    assert any("; predicted by soil recalibration only: " in t for t in texts)
    v1 = GapReport.from_json(json.loads(SCHEMA_1_REPORT.read_text(encoding="utf-8")))
    blocks = gap_blocks(v1)
    texts = [b.text for b in blocks if isinstance(b, (Heading, Note))]
    (table,) = [b for b in blocks if getattr(b, "header", [""])[0] == "rank"]
    assert [row[1] for row in table.rows] == [
        "grousers (Ding 2011) + wheel flexibility (Wong 2010)",
        "grousers (Ding 2011) + wheel flexibility (Bekker 1969)",
        "grousers (Ding 2011) + bulldozing (Rankine & Terzaghi 1943)",
        "grousers (Ding 2011) + bulldozing (Bekker 1969)", "grousers (Ding 2011)",
        "grousers (Bekker 1956) + wheel flexibility (Wong 2010)", "grousers (Bekker 1956)",
        "grousers (Bekker 1956) + bulldozing (Bekker 1969)"]
    assert "How far: held-out RMSE, soil recalibration only against grousers (Ding 2011)" \
        in texts
    assert ("Held-out RMSE per slip band, before → after (soil recalibration only → grousers "
            "(Ding 2011)): where the gap remains.") in texts


def explained(laws: dict[str, str], outside: bool = False) -> SimpleNamespace:
    """A hypothesis as the page reads it: its effects with their laws."""
    return SimpleNamespace(effects=tuple(laws), laws={e: Law.of(e, law) for e, law in
                                                      laws.items()}, outside=outside)


def test_plain_words_and_display_units(report_v1):
    assert candidate_text(EffectSet("slip_sinkage+grousers", ("slip_sinkage", "grousers"),
                                    0.5)) == "slip sinkage + grousers"
    assert candidate_text(explained({}, outside=True)) == "an effect outside the candidates"
    assert candidate_text(explained({})) == "soil recalibration only"
    assert candidate_text(explained({"grousers": "ding2011",
                                     "reduced_gravity": "wong_kobayashi2012"})) == (
        "grousers (Ding 2011) + reduced gravity (Wong & Kobayashi 2012)")
    assert candidate_text(explained({"grousers": "bekker1956~slip",
                                     "bulldozing": "rankine_terzaghi1943~depth"})) == (
        "grousers (Bekker 1956, with the lugs' slip-sinkage) + bulldozing (Rankine & Terzaghi "
        "1943, resistance varying with rut depth)")
    assert law_text(Law.of("grousers", "free_form")) == (
        "a shape none of its laws has: what differs between the levels")
    assert law_text(Law.of("slip_sinkage", "lyasko2010~load/free_form")) == (
        "Lyasko 2010, strength varying with load and what differs between the levels beyond it")
    for effect, laws in tm.LAWS.items():
        for law in laws:
            assert "_" not in candidate_text(explained({effect: law}))
    two = GapReport.from_json(dict(report_v1, separating_test={
        "test": "test at another gravity (3.71 m/s^2, gravity-offload rig or parabolic flight)",
        "separation_sigma": 5.25}))
    assert decisive_test_text(two) == (
        "Next test: test at another gravity (3.71 m/s², gravity-offload rig or parabolic "
        "flight); grousers (Ding 2011) and soil recalibration only differ there by up to "
        "5.25 σ (σ: the repeatability floor).")
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
    # every parameter a hypothesis can free (each law of each effect), and every effect, has
    # a plain name
    base = tm.shipped_model("bb2_sand")
    fitted = {p.name for p in soil_params(base)} | {
        p.name for effect, laws in tm.LAWS.items() for law in laws
        for p in effect_params(effect, law)}
    assert fitted - set(PARAMETERS) == set() and set(tm.LAWS) <= set(EFFECTS)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (.ci/chromium.sh)")
def test_gap_page_opens_in_chromium_and_every_image_decodes(page_file, tmp_path):
    found, console = probe(page_file, tmp_path)
    assert found["images"] == 4 and found["decoded"] == ["ok"] * 4
    assert found["faults"] == [] and console == []


def test_significant_regions_keeps_the_strongest_twelve():
    """20 regions, drawbar pull at |z| = 0.5 and sinkage at |z| = region index in each, every
    cell with z != 0 significant: kept are the regions of largest |z|, 19 down to 8."""
    regions = [{"slip_band": "[0.0,0.2)", "load_n": float(i), "multipass": 0,
                "gravity_mps2": 9.807, "quantity": q, "z": z, "significant": z != 0}
               for i in range(20) for q, z in (("dp_n", 0.5), ("sinkage_m", -float(i)))]
    keys = significant_regions(regions, "")
    assert [k[1] for k in keys] == [float(i) for i in range(19, 7, -1)]


def test_the_braked_branch_the_base_model_took_is_said_in_words(report, page_file, tmp_path):
    """A note where the base model took a braked branch; none on :func:`report`'s page (its
    points have no braked run)."""
    with_braked = {**report, "base_model": {
        "braked_law": "signed_slip",
        "soil_only_log_evidence": {"wong_reece1967": 80.25, "signed_slip": 92.5}}}
    page = check_page(write_gap_page(GapReport.from_json(with_braked),
                                     tmp_path / "gap.html").read_text())
    note = next(t for t in page.text if t.startswith("Braked runs: "))
    assert "part I's laws at the signed slip" in note and "12.2 nats more probable" in note
    assert "Wong & Reece's part II" in note
    assert not any(t.startswith("Braked runs: ")
                   for t in check_page(page_file.read_text("utf-8")).text)
