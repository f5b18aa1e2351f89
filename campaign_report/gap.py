"""The sim-to-real gap report in words, tables and the residual map: one renderer for the
page ``swtlab gap --html`` writes and for the section of the campaign report.

The section appears in the campaign report when ``swtlab gap --measured <this database>``
has recorded a report (docs/gap-report.md); it is registered as an optional section
(:mod:`campaign_report.extensions`), its data (``data.extras["gap"]``) being
``{"sim_source": ..., "report": ...}`` as ``gap_report`` stores them. Code names of the
JSON (``dp_n``, ``soil.kphi``, ``slip_sinkage+grousers``) are shown by their plain names
and units (:mod:`campaign_report.style`).
"""

from __future__ import annotations

import re
from datetime import UTC, datetime
from pathlib import Path

from sqlalchemy import select
from sqlalchemy.orm import Session

from campaign_report.data import CampaignData
from campaign_report.extensions import Extension, register
from campaign_report.figures import condition_text, gap_heatmap, slip_band_text, varying_factors
from campaign_report.html import Block, Heading, Image, Note, Page, Section, Table, render_page
from campaign_report.images import to_png
from swtlab.atomic import write_atomically
from swtlab.rounding import to_decimal_of
from terramechanics.effects.depth_varying import SUFFIX as DEPTH_VARYING
from terramechanics.effects.load_varying import SUFFIX as LOAD_VARYING
from terramechanics.effects.lug_slip_sinkage import SUFFIX as LUG_SLIP_SINKAGE
from campaign_report.style import EFFECTS, PARAMETERS, QUANTITIES, Palette, value_text
from sim_gap.vocabulary import slip_band_labels
from traceability.models import GapReport
from traceability.provenance import swtlab_version

CANDIDATES_SHOWN = 8
#: rows of a significant-regions table (the strongest; the heatmap shows every region)
REGIONS_SHOWN = 12
NAME = "gap"
SOIL_ONLY = "soil_only"
SOIL_ONLY_TEXT = "soil recalibration only"


#: a generalised law's suffix in words
VARYING_TEXT = {LOAD_VARYING: ", strength varying with load",
                DEPTH_VARYING: ", resistance varying with rut depth",
                LUG_SLIP_SINKAGE: ", with the lugs' slip-sinkage"}
_SUFFIX = "(" + "|".join(map(re.escape, VARYING_TEXT)) + ")?"


def law_text(law: str) -> str:
    """A law's key (``wong_kobayashi2012``) as its authors and year (Wong & Kobayashi 2012);
    a generalised law (``ding2011~load``) says so (Ding 2011, strength varying with load)."""
    match = re.fullmatch(r"([a-z_]+?)(\d{4})" + _SUFFIX, law)
    if not match:
        return law
    text = " & ".join(n.capitalize() for n in match.group(1).split("_")) + " " + match.group(2)
    return text + VARYING_TEXT.get(match.group(3) or "", "")


def _effect_text(part: str) -> str:
    """``slip_sinkage`` or ``slip_sinkage(lyasko2010)`` in plain words."""
    effect, _, law = part.partition("(")
    name = EFFECTS.get(effect, effect)
    return f"{name} ({law_text(law.rstrip(')'))})" if law else name


def candidate_text(label: str) -> str:
    """A candidate label (``soil_only``, ``slip_sinkage+grousers``, with laws
    ``grousers(ding2011)+slip_sinkage(lyasko2010)``) in plain words."""
    if label == SOIL_ONLY:
        return SOIL_ONLY_TEXT
    return " + ".join(_effect_text(e) for e in label.split("+"))


def words(text: str, labels: list[str]) -> str:
    """``text`` (written with the JSON's candidate labels, effect names and law keys) in plain
    words: each label by its plain name, each law by its authors and year, each quantity by
    its name, standard errors and sigmas spelt out."""
    sets = {re.sub(r"\([^)]*\)", "", n) for n in labels}  # the effect sets, laws dropped
    names = sorted({n for n in {*labels, *sets, *EFFECTS, SOIL_ONLY}
                    if "_" in n or "+" in n or "(" in n}, key=len, reverse=True)
    pattern = re.compile(r"(?<![\w+])(" + "|".join(map(re.escape, names)) + r")(?![\w+])")
    text = pattern.sub(lambda m: candidate_text(m.group(1)), text)
    text = re.sub(r"\b[a-z_]+?\d{4}" + _SUFFIX + r"\b", lambda m: law_text(m.group(0)),
                  text)  # a law's key
    text = re.sub(r"\b(" + "|".join(q for q in QUANTITIES if "_" in q) + r")\b",
                  lambda m: QUANTITIES[m.group(1)].label, text)  # a quantity's column
    text = re.sub(r"(\d) SE\b", r"\1 standard errors", text)
    return re.sub(r"\bsigma\b", "σ", text).replace("m/s^2", "m/s²").strip()


def plain(text: str, labels: list[str]) -> str:
    """A reason of the report as a sentence (:func:`words`, a capital, a full stop)."""
    text = words(text, labels)
    return text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")


def verdict_text(verdict) -> str:
    if isinstance(verdict, str):
        return verdict
    if not verdict:
        return "no missing effect"
    return "the simulation lacks " + " and ".join(EFFECTS.get(e, e) for e in verdict)


def _parameters_text(values: dict[str, float]) -> str:
    return "; ".join(f"{PARAMETERS[k].label} = {value_text(PARAMETERS[k], v)}"
                     if k in PARAMETERS else f"{k} = {v:.3g}" for k, v in values.items())


def _region_of(report: dict, where: dict) -> dict | None:
    keys = ("slip_band", "load_n", "multipass", "gravity_mps2", "quantity")
    return next((r for r in report["regions"] if all(r[k] == where[k] for k in keys)), None)


def _residual_text(quantity: str, si_value: float) -> str:
    return f"{'+' if si_value > 0 else ''}{value_text(QUANTITIES[quantity], si_value)}"


def decisive_test_text(report: dict) -> str | None:
    """The test that would decide (or, for an unexplained gap, where it is largest)."""
    test = report.get("separating_test")
    if not test:
        return None
    labels = [c["label"] for c in report["candidates"]]
    if test.get("region"):
        region = _region_of(report, test["region"])
        if region is None:
            return None
        varying = varying_factors(report["regions"]) | {"multipass", "gravity_mps2"}
        return (f"No candidate effect explains the gap. After soil recalibration the "
                f"simulation misses most in {QUANTITIES[region['quantity']].label} at slips "
                f"{slip_band_text(region['slip_band'])} %, "
                f"{condition_text(region, varying)}: mean residual "
                f"{_residual_text(region['quantity'], region['mean_residual_soil_recalibrated'])}"
                f" (z = {region['z_soil_recalibrated']:.1f}).")
    if not test.get("test"):
        return None
    sigma = test.get("separation_sigma")
    leaders = report.get("decision", {}).get("leaders") or []
    who = (" and ".join(candidate_text(x) for x in leaders) if len(leaders) == 2
           else "the two leading explanations")
    return (f"Test that would decide: {words(test['test'], labels)}"
            + (f"; {who} differ there by {sigma:.3g} σ (of the repeatability floor)."
               if sigma is not None else "."))


def _untestable_notes(report: dict) -> list[Note]:
    return [Note(plain(f"{EFFECTS.get(effect, effect)}: not testable with this campaign; "
                       f"{why}", []))
            for effect, why in report["untestable_effects"].items()]


def _wheel_and_source_notes(report: dict) -> list[Note]:
    """The wheel differences allowed (``--allow-wheel-mismatch``) and, with several measured
    sources, which source each tested effect is seen on."""
    labels = [c["label"] for c in report["candidates"]]
    notes = [Note(f"Wheel MISMATCH allowed: {line} (measured vs simulated).", warning=True)
             for line in (report.get("wheel") or {}).get("mismatches", [])]
    if len(report.get("sources") or []) > 1:
        notes += [Note(plain(e["text"], labels)) for e in report["effect_sources"].values()]
    return notes


def _key(region: dict) -> tuple:
    return region["slip_band"], region["load_n"], region["multipass"], region["gravity_mps2"]


def significant_regions(regions: list[dict], tag: str) -> list[tuple]:
    """Keys of the regions with a significant cell, at most :data:`REGIONS_SHOWN`: those
    with the largest significant |z|."""
    strongest: dict[tuple, float] = {}
    for r in regions:
        if r[f"significant{tag}"]:
            strongest[_key(r)] = max(strongest.get(_key(r), 0.0), abs(r[f"z{tag}"]))
    return sorted(strongest, key=strongest.get, reverse=True)[:REGIONS_SHOWN]


def _regions_table(report: dict, tag: str) -> Table | None:
    """Regions with a significant residual (the strongest :data:`REGIONS_SHOWN`): their
    conditions and each quantity's mean residual in its unit (``*``: significant); None
    when none is significant."""
    regions = report["regions"]
    hits = set(significant_regions(regions, tag))
    if not hits:
        return None
    quantities = list(dict.fromkeys(r["quantity"] for r in regions))
    cells: dict[tuple, dict[str, str]] = {}
    for r in regions:
        if (key := _key(r)) in hits:
            q = QUANTITIES[r["quantity"]]
            cells.setdefault(key, {})[r["quantity"]] = (
                f"{r[f'mean_residual{tag}'] * q.scale:+.3g}"
                + (" *" if r[f"significant{tag}"] else ""))
    varying = varying_factors(regions)
    order = sorted(hits, key=lambda k: (k[3], k[2], k[1], slip_band_labels().index(k[0])))
    rows = [[slip_band_text(k[0]), f"{k[1]:g}"]
            + ([str(k[2])] if "multipass" in varying else [])
            + ([f"{k[3]:.3g}"] if "gravity_mps2" in varying else [])
            + [cells[k].get(q, "") for q in quantities] for k in order]
    header = (["slip band [%]", "load [N]"] + (["multipass"] if "multipass" in varying else [])
              + (["gravity [m/s²]"] if "gravity_mps2" in varying else [])
              + [QUANTITIES[q].axis_label for q in quantities])
    return Table(header, rows, numeric=frozenset(range(1, len(header))))


def _where_blocks(report: dict) -> list[Block]:
    regions = report["regions"]
    blocks: list[Block] = [Heading("Where: residuals measured − simulated")]
    if report.get("sinkage_relative"):
        blocks.append(Note("Sinkage was measured relative to an unknown zero: the mean sinkage "
                           "residual is removed before every comparison."))
    for tag, what in (("", "the simulation as given"),
                      ("_soil_recalibrated", "the simulation after soil-only recalibration")):
        n_sig = sum(r[f"significant{tag}"] for r in regions)
        n_keys = len({_key(r) for r in regions if r[f"significant{tag}"]})
        blocks.append(Image(f"gap-heatmap{tag.replace('_', '-')}",
                            f"Residual map of {what}: mean residual per slip band and "
                            "condition, in % of the wheel load (torque: of load × radius; "
                            "sinkage: of the wheel radius); * significant",
                            to_png(gap_heatmap(regions, tag))[0]))
        table = _regions_table(report, tag)
        listed = "."
        if table is not None:
            which = ("listed below" if n_keys == len(table.rows) else
                     f"below the {len(table.rows)} of their {n_keys} regions with the largest "
                     "residual in σ")
            listed = f": {which}, * marks the significant quantities."
        blocks.append(Note(f"{n_sig} of {len(regions)} region-quantity cells differ "
                           f"significantly for {what} (chi-square test of the standardised "
                           "residuals, Benjamini-Hochberg at a 5 % false discovery rate)"
                           + listed))
        if table:
            blocks.append(table)
    return blocks


def _which_blocks(report: dict) -> list[Block]:
    rows = [[str(i + 1), candidate_text(c["label"]), f"{c['held_out_score']:.3g}",
             f"{c['z_vs_best']:.3g}", str(c["n_params"]), _parameters_text(c["parameters"])]
            for i, c in enumerate(report["candidates"][:CANDIDATES_SHOWN])]
    more = len(report["candidates"]) - CANDIDATES_SHOWN
    rest = f" {more} more explanations in the JSON report." if more > 0 else ""
    return [Heading("Which: explanations ranked by their held-out score"),
            Note("Each explanation frees the soil and the strength of its effects, is fitted "
                 f"with {_folds_text(report['folds'])} held out in turn, and is scored by the "
                 "RMS of its held-out residuals in units of their uncertainty (σ: standard "
                 "error and repeatability floor); the difference from the best is a paired "
                 "z over runs." + rest),
            Table(["rank", "explanation", "held-out RMS residual [σ]",
                   "difference from the best [standard errors]", "free parameters",
                   "fitted values (all data)"], rows, numeric=frozenset({0, 2, 3, 4}))]


def _how_far_blocks(report: dict) -> list[Block]:
    per = report["shrink"]["per_quantity"]
    chosen = candidate_text(report["chosen"])
    keys = list(per)
    first = SOIL_ONLY_TEXT if report["chosen"] == SOIL_ONLY else f"before: {SOIL_ONLY_TEXT}"
    rmse = [[first] + [_number(QUANTITIES[k], per[k]["before"]) for k in keys]]
    if report["chosen"] != SOIL_ONLY:
        rmse.append([f"after: {chosen}"] + [_number(QUANTITIES[k], per[k]["after"])
                                            for k in keys])
        title = f"How far: held-out RMSE, {SOIL_ONLY_TEXT} against {chosen}"
    else:
        title = f"How far: held-out RMSE of {SOIL_ONLY_TEXT} (no effect chosen)"
    blocks: list[Block] = [
        Heading(title),
        Note("Root-mean-square held-out error in each quantity's unit, before and after from "
             "the same folds; shrink = 100 (1 − after / before), its 95 % interval from a "
             f"bootstrap over runs ({report['shrink']['n_boot']} replicates)."),
        Table(["held-out RMSE"] + [QUANTITIES[k].axis_label for k in keys], rmse,
              numeric=frozenset(range(1, len(keys) + 1)))]
    if report["chosen"] != SOIL_ONLY:
        rows = [[QUANTITIES[k].label, *_shrink(per[k])] for k in keys]
        blocks.append(Table(["quantity", "shrink [%]", "shrink 95 % interval [%]"], rows,
                            numeric=frozenset({1, 2})))
    return blocks + _per_band_blocks(report, keys)


def _per_band_blocks(report: dict, keys: list[str]) -> list[Block]:
    """Held-out RMSE per slip band: where the gap remains (before → after with an effect)."""
    bands = report["shrink"]["per_slip_band"]
    if not bands:
        return []
    arrow = report["chosen"] != SOIL_ONLY
    rows = []
    for band, per in bands.items():
        cells = []
        for k in keys:
            v, q = per.get(k, {}), QUANTITIES[k]
            before, after = _number(q, v.get("before")), _number(q, v.get("after"))
            cells.append(f"{before} → {after}" if arrow and before else before)
        rows.append([slip_band_text(band)] + cells)
    what = (f"before → after ({SOIL_ONLY_TEXT} → {candidate_text(report['chosen'])})" if arrow
            else SOIL_ONLY_TEXT)
    return [Note(f"Held-out RMSE per slip band, {what}: where the gap remains."),
            Table(["slip band [%]"] + [QUANTITIES[k].axis_label for k in keys], rows,
                  numeric=frozenset(range(1, len(keys) + 1)))]


def _number(quantity, si_value: float | None) -> str:
    return "" if si_value is None else f"{si_value * quantity.scale:.3g}"


def _shrink(v: dict) -> tuple[str, str]:
    """The shrink and its 95 % interval, both to the decimal the interval's half-width (its
    expanded uncertainty, two significant digits) supports (GUM 7.2.6; ``swtlab.rounding``)."""
    low, high = v["shrink_pct_ci95"]
    if low is None or high is None:
        return to_decimal_of(v["shrink_pct"], None), ""
    half = (high - low) / 2
    return (to_decimal_of(v["shrink_pct"], half),
            f"{to_decimal_of(low, half)} to {to_decimal_of(high, half)}")


def _folds_text(folds: list[str]) -> str:
    """The held-out folds (``load=70``, ``multipass=2``, ``slip band 1``) in words."""
    units = {"load": " N", "gravity": " m/s²", "multipass": ""}
    levels: dict[str, list[str]] = {}
    for name in folds:
        factor, _, level = name.partition("=")
        if not level:  # "slip band <index>"
            factor = "slip band"
            level = slip_band_text(slip_band_labels()[int(name.rsplit(" ", 1)[1])]) + " %"
        levels.setdefault(factor, []).append(level + units.get(factor, ""))
    return "; ".join(f"each {factor} ({', '.join(v)})" for factor, v in levels.items()) or \
        "no fold"


def gap_blocks(report: dict) -> list[Block]:
    """Everything the gap report shows, in order: verdict and reason, what could not be
    tested, the test that would decide, where (residual maps and significant regions), which
    (ranked explanations with fitted values) and how far (held-out RMSE before and after)."""
    labels = [c["label"] for c in report["candidates"]]
    blocks: list[Block] = [Heading(f"Verdict: {verdict_text(report['verdict'])}"),
                           Note(plain(report["reason"], labels),
                                warning=report["verdict"] == "inconclusive")]
    if (test := decisive_test_text(report)) is not None:
        blocks.append(Note(test))
    blocks += _untestable_notes(report) + _wheel_and_source_notes(report)
    return blocks + _where_blocks(report) + _which_blocks(report) + _how_far_blocks(report)


def gather_gap(session: Session, data: CampaignData) -> dict | None:
    """The newest gap report recorded in the database; None without one."""
    row = session.scalars(select(GapReport).order_by(GapReport.id.desc())).first()
    return None if row is None else {"sim_source": row.sim_source, "report": row.report}


def gap_section(data: CampaignData, palette: Palette) -> Section | None:
    """The newest gap report of the campaign's database; None without one."""
    found = data.extras.get(NAME)
    if found is None:
        return None
    intro = Note(f"Simulation {found['sim_source']} against the measurements of this database "
                 f"({found['report']['n_points']} runs).")
    return Section(NAME, "Sim-to-real gap", [intro, *gap_blocks(found["report"])])


def gap_page(report: dict) -> Page:
    """The page ``swtlab gap --html`` writes: the same blocks as the campaign report's
    section, under the report's own header and style."""
    meta = [("measured", str(report["measured"])), ("simulated", str(report["simulated"])),
            ("runs compared", str(report["n_points"])),
            ("quantities", ", ".join(QUANTITIES[q].axis_label for q in report["quantities"])),
            ("generated", datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
             + f" by swtlab {swtlab_version()}")]
    return Page("Sim-to-real gap", meta, [Section(NAME, "Diagnosis", gap_blocks(report))],
                footer="Self-contained page written by swtlab gap: every figure is embedded, "
                       "nothing is fetched from the network. The numbers in full: the JSON "
                       "report (docs/gap-report.md).")


def write_gap_page(report: dict, path: str | Path) -> Path:
    """Write :func:`gap_page` of ``report`` to ``path`` (atomically)."""
    return write_atomically(path, render_page(gap_page(report)))


register(Extension(NAME, gap_section, gather_gap))
