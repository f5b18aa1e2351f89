"""The sim-to-real gap report in words, tables and figures: one renderer for the page
``swtlab gap --html`` writes and for the section of the campaign report.

The section appears in the campaign report when ``swtlab gap --measured <this database>``
has recorded a report (docs/gap-report.md); it is registered as an optional section
(:mod:`campaign_report.extensions`), its data (``data.extras["gap"]``) being
``{"sim_source": ..., "report": ...}`` as ``gap_report`` stores them (the report's JSON,
read into a :class:`sim_gap.report_types.GapReport` by the section). Both schemas of
:data:`sim_gap.report.READABLE_SCHEMAS` are read: schema 2 (posterior probabilities) with
the verdict and its probability, the probabilities per effect set, the measured curves
beside the simulation, the sibling contrasts and the next test; schema 1 (held-out scores)
with its ranked candidates. Code names of the JSON (``dp_n``, ``soil.kphi``) are shown by
their plain names and units (:mod:`campaign_report.style`), a hypothesis by its effects and
the authors and year of each law (:class:`sim_gap.report_types.Law`); the report's
``reason`` is shown as written.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from campaign_report.data import CampaignData
from campaign_report.extensions import Extension, register
from campaign_report.figures import (condition_text, gap_curves, gap_heatmap,
                                     gap_probabilities, probability_text, slip_band_text,
                                     varying_factors)
from campaign_report.html import Block, Heading, Image, Note, Page, Section, Table, render_page
from campaign_report.images import to_png
from campaign_report.style import EFFECTS, PARAMETERS, QUANTITIES, Palette, Quantity, value_text
from sim_gap.hypotheses import OUTSIDE
from sim_gap.report import READABLE_SCHEMAS
from sim_gap.report_types import (SOIL_ONLY, Explained, GapReport, HeldOutReport, Hypothesis,
                                  Law, PosteriorReport, SiblingContrast, UnknownSchema)
from sim_gap.vocabulary import slip_band_labels
from swtlab_base.atomic import write_atomically
from swtlab_base.rounding import to_decimal_of
from terramechanics.effects.depth_varying import SUFFIX as DEPTH_VARYING
from terramechanics.effects.load_varying import SUFFIX as LOAD_VARYING
from terramechanics.effects.lug_slip_sinkage import SUFFIX as LUG_SLIP_SINKAGE
from traceability.models import GapReport as GapReportRecord
from traceability.provenance import swtlab_version

#: rows of the schema-1 candidates table and of the schema-2 hypotheses table
CANDIDATES_SHOWN = 8
#: bars of the probability chart (the most probable effect sets)
SETS_SHOWN = 12
#: sibling contrasts told in sentences (those furthest from zero in their uncertainty)
CONTRASTS_TOLD = 6
#: rows of a significant-regions table (the strongest; the heatmap shows every region)
REGIONS_SHOWN = 12
NAME = "gap"
SOIL_ONLY_TEXT = "soil recalibration only"
OUTSIDE_TEXT = "an effect outside the candidates"
#: the predictions every schema-2 point carries besides the chosen hypothesis'
SIMULATION = "simulation"
PREDICTION_TEXT = {SIMULATION: "the simulation as given", SOIL_ONLY: SOIL_ONLY_TEXT}


#: a generalised law's suffix in words
VARYING_TEXT = {LOAD_VARYING: ", strength varying with load",
                DEPTH_VARYING: ", resistance varying with rut depth",
                LUG_SLIP_SINKAGE: ", with the lugs' slip-sinkage"}


def law_text(law: Law) -> str:
    """A law by its authors and year (Wong & Kobayashi 2012); a generalised law says so
    (Ding 2011, strength varying with load), and so does one beside a free form; a law
    without them by its key."""
    if law.free_form and law.year is None:
        return "a shape none of its laws has: what differs between the levels"
    if law.year is None:
        return law.key
    return (" & ".join(law.authors) + f" {law.year}" + VARYING_TEXT.get(law.varying or "", "")
            + (" and what differs between the levels beyond it" if law.free_form else ""))


def _effects_text(x: Explained) -> str:
    """The effects of ``x`` in plain words, each with its law where ``x`` names one."""
    return " + ".join(f"{EFFECTS.get(e, e)} ({law_text(x.laws[e])})" if e in x.laws
                      else EFFECTS.get(e, e) for e in x.effects)


def candidate_text(x: Explained) -> str:
    """A hypothesis or an effect set (soil recalibration only, effects with or without
    their laws, an effect outside the candidates) in plain words."""
    if x.outside:
        return OUTSIDE_TEXT
    return _effects_text(x) if x.effects else SOIL_ONLY_TEXT


def set_text(x: Explained) -> str:
    """An effect set (a hypothesis' laws left out) as the answer to "what does the
    simulation lack"."""
    if x.outside:
        return OUTSIDE_TEXT
    return " + ".join(EFFECTS.get(e, e) for e in x.effects) or "no missing effect"


def verdict_text(verdict: tuple[str, ...] | str) -> str:
    if verdict == OUTSIDE:
        return "the gap lies outside the candidate effects"
    if isinstance(verdict, str):
        return verdict
    if not verdict:
        return "no missing effect"
    return "the simulation lacks " + " and ".join(EFFECTS.get(e, e) for e in verdict)


def _units(text: str) -> str:
    """The report's ASCII unit spelling as the page writes it."""
    return text.replace("m/s^2", "m/s²")


def _listing(items: list[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return " and ".join([", ".join(items[:-1]), items[-1]] if len(items) > 1 else items)


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")


def _parameters_text(values: Mapping[str, float]) -> str:
    return "; ".join(f"{PARAMETERS[k].label} = {value_text(PARAMETERS[k], v)}"
                     if k in PARAMETERS else f"{k} = {v:.3g}" for k, v in values.items())


def _region_of(report: GapReport, where: Mapping[str, Any]) -> Mapping[str, Any] | None:
    keys = ("slip_band", "load_n", "multipass", "gravity_mps2", "quantity")
    return next((r for r in report.regions if all(r[k] == where[k] for k in keys)), None)


def _residual_text(quantity: str, si_value: float) -> str:
    return f"{'+' if si_value > 0 else ''}{value_text(QUANTITIES[quantity], si_value)}"


def _region_text(report: GapReport, where: Mapping[str, Any]) -> str | None:
    """Where the soil-recalibrated simulation misses most, for a gap no candidate carries."""
    region = _region_of(report, where)
    if region is None:
        return None
    varying = varying_factors(report.regions) | {"multipass", "gravity_mps2"}
    return (f"No candidate effect explains the gap. After soil recalibration the "
            f"simulation misses most in {QUANTITIES[region['quantity']].label} at slips "
            f"{slip_band_text(region['slip_band'])} %, {condition_text(region, varying)}: "
            "mean residual "
            f"{_residual_text(region['quantity'], region['mean_residual_soil_recalibrated'])}"
            f" (z = {region['z_soil_recalibrated']:.1f}).")


def next_tests_text(report: PosteriorReport) -> str | None:
    """Schema 2, inconclusive: the tests that would tell most about which explanation is
    right, by their expected information gain (``next_tests``, at most three)."""
    tests = report.next_tests
    if not tests:
        return None
    parts = [f"{i}. {_units(t['test'])}: expected gain {t['gain_bits']:.2f} bit"
             for i, t in enumerate(tests, 1)]
    return ("Next test, by the information it is expected to give about which explanation is "
            f"right (the probabilities above leave {_entropy_bits(report):.2f} bit uncertain): "
            + "; ".join(parts) + ".")


def _entropy_bits(report: PosteriorReport) -> float:
    """The entropy of the effect sets' probabilities, in bits: what a test could tell."""
    p = [s.probability for s in report.effect_sets if s.probability > 0]
    return -sum(x * math.log2(x) for x in p)


def decisive_test_text(report: GapReport) -> str | None:
    """The next test in words: the extra test that would tell the two leading named
    hypotheses apart, or, for a gap outside the candidates, where it is largest."""
    test = report.separating_test
    if not test:
        return None
    if test.get("region"):  # schema 2: only for a verdict outside the candidates
        return (_region_text(report, test["region"])
                if not isinstance(report, PosteriorReport) or report.verdict == OUTSIDE
                else None)
    leaders = report.leading()
    who = (" and ".join(candidate_text(x) for x in leaders) if len(leaders) == 2
           else "the two leading explanations")
    if not test.get("test"):
        return (f"None of the extra tests the diagnosis can propose would tell {who} apart; "
                "more runs at the measured conditions narrow the noise instead.")
    sigma = test.get("separation_sigma")
    return (f"Next test: {_units(test['test'])}"
            + (f"; {who} differ there by up to {sigma:.3g} σ (σ: the repeatability floor)."
               if sigma is not None else "."))


def _untestable_note(report: GapReport) -> list[Note]:
    parts = [f"{EFFECTS.get(e, e)} ({_units(why)})"
             for e, why in report.untestable_effects.items()]
    return [Note("Not tested with this campaign, so neither found nor ruled out: "
                 + "; ".join(parts) + ".")] if parts else []


def _wheel_and_source_notes(report: GapReport) -> list[Note]:
    """The wheel differences allowed (``--allow-wheel-mismatch``) and, with several measured
    sources, on which of them each tested effect can show."""
    notes = [Note(f"Wheel MISMATCH allowed: {line} (measured vs simulated).", warning=True)
             for line in (report.wheel or {}).get("mismatches", [])]
    sources = [s["name"] for s in report.sources or ()]
    if len(sources) > 1:
        parts = [f"{EFFECTS.get(e, e)} on "
                 + ("every source" if set(v["sources"]) == set(sources)
                    else ", ".join(v["sources"]) + " only")
                 for e, v in (report.effect_sources or {}).items()]
        notes.append(Note(f"{len(sources)} measured sources ({', '.join(sources)}), one soil "
                          "fitted on all; where each tested effect can show: "
                          + "; ".join(parts) + "."))
    return notes


def _key(region: Mapping[str, Any]) -> tuple:
    return region["slip_band"], region["load_n"], region["multipass"], region["gravity_mps2"]


def significant_regions(regions: Sequence[Mapping[str, Any]], tag: str) -> list[tuple]:
    """Keys of the regions with a significant cell, at most :data:`REGIONS_SHOWN`: those
    with the largest significant |z|."""
    strongest: dict[tuple, float] = {}
    for r in regions:
        if r[f"significant{tag}"]:
            strongest[_key(r)] = max(strongest.get(_key(r), 0.0), abs(r[f"z{tag}"]))
    return sorted(strongest, key=lambda k: strongest[k], reverse=True)[:REGIONS_SHOWN]


def _regions_table(report: GapReport, tag: str) -> Table | None:
    """Regions with a significant residual (the strongest :data:`REGIONS_SHOWN`): their
    conditions and each quantity's mean residual in its unit (``*``: significant); None
    when none is significant."""
    regions = report.regions
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


def _where_blocks(report: GapReport) -> list[Block]:
    regions = report.regions
    blocks: list[Block] = [Heading("Where: residuals measured − simulated")]
    if report.sinkage_relative:
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


def _which_blocks_schema1(report: HeldOutReport) -> list[Block]:
    rows = [[str(i + 1), candidate_text(c), f"{c.held_out_score:.3g}", f"{c.z_vs_best:.3g}",
             str(c.n_params), _parameters_text(c.parameters)]
            for i, c in enumerate(report.candidates[:CANDIDATES_SHOWN])]
    more = len(report.candidates) - CANDIDATES_SHOWN
    rest = f" {more} more explanations in the JSON report." if more > 0 else ""
    return [Heading("Which: explanations ranked by their held-out score"),
            Note("Each explanation frees the soil and the strength of its effects, is fitted "
                 f"with {_folds_text(report.folds)} held out in turn, and is scored by the "
                 "RMS of its held-out residuals in units of their uncertainty (σ: standard "
                 "error and repeatability floor); the difference from the best is a paired "
                 "z over runs." + rest),
            Table(["rank", "explanation", "held-out RMS residual [σ]",
                   "difference from the best [standard errors]", "free parameters",
                   "fitted values (all data)"], rows, numeric=frozenset({0, 2, 3, 4}))]


def _how_far_blocks(report: GapReport) -> list[Block]:
    per = report.shrink["per_quantity"]
    chosen = candidate_text(report.explanation(report.chosen))
    keys = list(per)
    first = SOIL_ONLY_TEXT if report.chosen == SOIL_ONLY else f"before: {SOIL_ONLY_TEXT}"
    rmse = [[first] + [_number(QUANTITIES[k], per[k]["before"]) for k in keys]]
    if report.chosen != SOIL_ONLY:
        rmse.append([f"after: {chosen}"] + [_number(QUANTITIES[k], per[k]["after"])
                                            for k in keys])
        title = f"How far: held-out RMSE, {SOIL_ONLY_TEXT} against {chosen}"
    else:
        title = f"How far: held-out RMSE of {SOIL_ONLY_TEXT} (no effect chosen)"
    blocks: list[Block] = [
        Heading(title),
        Note("Root-mean-square held-out error in each quantity's unit, before and after from "
             "the same folds; shrink = 100 (1 − after / before), its 95 % interval from a "
             f"bootstrap over runs ({report.shrink['n_boot']} replicates)."),
        Table(["held-out RMSE"] + [QUANTITIES[k].axis_label for k in keys], rmse,
              numeric=frozenset(range(1, len(keys) + 1)))]
    if report.chosen != SOIL_ONLY:
        rows = [[QUANTITIES[k].label, *_shrink(per[k])] for k in keys]
        blocks.append(Table(["quantity", "shrink [%]", "shrink 95 % interval [%]"], rows,
                            numeric=frozenset({1, 2})))
    return blocks + _per_band_blocks(report, keys)


def _per_band_blocks(report: GapReport, keys: list[str]) -> list[Block]:
    """Held-out RMSE per slip band: where the gap remains (before → after with an effect)."""
    bands = report.shrink["per_slip_band"]
    if not bands:
        return []
    arrow = report.chosen != SOIL_ONLY
    rows = []
    for band, per in bands.items():
        cells = []
        for k in keys:
            v, q = per.get(k, {}), QUANTITIES[k]
            before, after = _number(q, v.get("before")), _number(q, v.get("after"))
            cells.append(f"{before} → {after}" if arrow and before else before)
        rows.append([slip_band_text(band)] + cells)
    what = (f"before → after ({SOIL_ONLY_TEXT} → "
            f"{candidate_text(report.explanation(report.chosen))})" if arrow
            else SOIL_ONLY_TEXT)
    return [Note(f"Held-out RMSE per slip band, {what}: where the gap remains."),
            Table(["slip band [%]"] + [QUANTITIES[k].axis_label for k in keys], rows,
                  numeric=frozenset(range(1, len(keys) + 1)))]


def _number(quantity: Quantity, si_value: float | None) -> str:
    return "" if si_value is None else f"{si_value * quantity.scale:.3g}"


def _shrink(v: Mapping[str, Any]) -> tuple[str, str]:
    """The shrink and its 95 % interval, both to the decimal the interval's half-width (its
    expanded uncertainty, two significant digits) supports (GUM 7.2.6; ``swtlab_base.rounding``)."""
    low, high = v["shrink_pct_ci95"]
    if low is None or high is None:
        return to_decimal_of(v["shrink_pct"], None), ""
    half = (high - low) / 2
    return (to_decimal_of(v["shrink_pct"], half),
            f"{to_decimal_of(low, half)} to {to_decimal_of(high, half)}")


def _folds_text(folds: Sequence[str]) -> str:
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


# --- schema 2: posterior probabilities -------------------------------------------------


def _verdict_blocks(report: PosteriorReport) -> list[Block]:
    """The verdict with its probability, the rule, the leaders when inconclusive, the
    report's reason as written and the next test."""
    verdict, call = report.verdict, report.call_probability
    heading = verdict_text(verdict)
    if verdict != "inconclusive":
        heading += f" (probability {probability_text(report.probability)})"
    rule = f"A verdict names a hypothesis only when its probability is at least {call:g}."
    if verdict == "inconclusive":
        leaders = ", ".join(f"{set_text(report.effect_set(x.label))} "
                            f"{probability_text(x.probability)}" for x in report.leaders)
        rule += f" None reaches it here; the most probable: {leaders}."
    blocks: list[Block] = [Heading(f"Verdict: {heading}"),
                           Note(rule, warning=verdict == "inconclusive"),
                           Note(f"Reason, as the diagnosis writes it: {report.reason}")]
    for test in (next_tests_text(report), decisive_test_text(report)):
        if test is not None:
            blocks.append(Note(test))
    return blocks


def _noise_note(report: PosteriorReport) -> list[Note]:
    """Where the noise came from, per quantity: measured replicates or the assumed floor."""
    kinds: dict[str, list[str]] = {}
    for q, text in report.noise.items():
        kinds.setdefault(text.partition(":")[0], []).append(QUANTITIES[q].label)
    words = {"measured": "measured (the spread of replicate runs) for {}",
             "assumed": "assumed for {}: nothing measured their repeatability, so the "
                        "repeatability floor of each quantity stands in (with each run's own "
                        "standard uncertainty)"}
    parts = [words.get(kind, kind + " for {}").format(_listing(names))
             for kind, names in kinds.items()]
    return [Note("Noise (the error bars, σ): " + "; ".join(parts) + ".",
                 warning="measured" not in kinds)] if parts else []


def _base_model_note(report: PosteriorReport) -> list[Note]:
    """Which treatment of the braked runs the base model took, and by how much."""
    chosen = report.base_model.get("braked_law")
    if not chosen:
        return []
    scores = report.base_model["soil_only_log_evidence"]
    other = max((law for law in scores if law != chosen), key=scores.__getitem__)
    words = {"wong_reece1967": "Wong & Reece's part II (a transition angle and a flow zone)",
             "signed_slip": "part I's laws at the signed slip (no step at zero slip)"}
    return [Note(f"Braked runs: the base model treats them by {words[chosen]}, whose soil "
                 f"recalibration is {scores[chosen] - scores[other]:.1f} nats more probable "
                 f"than with {words[other]} (docs/model-file.md).")]


def _laws_text(h: Hypothesis) -> str:
    return ", ".join(f"{EFFECTS.get(e, e)}: {law_text(law)}" for e, law in h.laws.items())


def _probability_blocks(report: PosteriorReport) -> list[Block]:
    """The bar chart of the effect sets' probabilities and the table of the most probable
    hypotheses (effect set, laws, probability, log evidence, fitted strengths)."""
    sets = report.effect_sets
    shown = [(set_text(s), s.probability) for s in sets[:SETS_SHOWN]]
    rest = len(sets) - len(shown)
    caption = ("Posterior probability of each effect set (its laws summed); the dashed line: "
               f"the probability a verdict needs ({report.call_probability:g})"
               + (f"; {rest} less probable sets not drawn" if rest > 0 else ""))
    chart = Image("gap-probabilities", caption,
                  to_png(gap_probabilities(shown, report.call_probability))[0])
    hypotheses = report.hypotheses[:CANDIDATES_SHOWN]
    rows = [[str(i + 1), set_text(h), _laws_text(h) or "—",
             probability_text(h.probability), f"{h.log_evidence:.1f}",
             _parameters_text({k: v for k, v in h.parameters.items()
                               if not k.startswith("soil.")}) or "—"]
            for i, h in enumerate(hypotheses)]
    effects = ", ".join(f"{EFFECTS.get(e, e)} {probability_text(p)}"
                        for e, p in sorted(report.effect_probabilities.items(),
                                           key=lambda x: -x[1]))
    chosen = next(h for h in report.hypotheses if h.key == report.chosen)
    more = len(report.hypotheses) - len(hypotheses)
    return [Heading("Which: the probability of each explanation"), chart,
            Note("Each hypothesis frees the soil and the strengths of its effects (priors: the "
                 "published soils and the ranges the laws cite) and is weighed by its evidence "
                 "(log evidence, natural log) and its prior; the outside hypothesis lets a "
                 "discrepancy no candidate shapes carry the gap (between sources and levels, "
                 "between travel velocities, or a soil drifting through the campaign), alone "
                 "or beside one candidate effect."
                 + (f" Probability that each effect is part of the explanation: {effects}."
                    if effects else "")
                 + (f" {more} less probable hypotheses in the JSON report." if more > 0
                    else "")),
            Table(["rank", "effect set", "laws", "probability", "log evidence",
                   "fitted strengths"], rows, numeric=frozenset({0, 3, 4})),
            Note(f"Soil fitted under the most probable named hypothesis "
                 f"({candidate_text(chosen)}): "
                 + _parameters_text({k: v for k, v in chosen.parameters.items()
                                     if k.startswith("soil.")}) + ".")]


def _prediction_names(report: PosteriorReport) -> dict[str, str]:
    """The predictions the points carry (key -> words): as given, soil only, chosen."""
    names = dict(PREDICTION_TEXT)
    if report.chosen not in names:
        names[report.chosen] = f"with {candidate_text(report.explanation(report.chosen))}"
    return names


def _relative_offsets(report: PosteriorReport, names: Mapping[str, str]) -> dict:
    """For a relative sinkage (unknown zero): each prediction's mean sinkage residual over
    all points, removed before it is drawn (as the diagnosis removes it)."""
    if not report.sinkage_relative:
        return {}
    rows = [p["sinkage_m"] for p in report.points if "sinkage_m" in p]
    return {k: {"sinkage_m": sum(r[k] - r["measured"] for r in rows) / len(rows)}
            for k in names} if rows else {}


def _curve_blocks(report: PosteriorReport) -> list[Block]:
    """Per source (and multipass and gravity level), the measured values against slip
    beside the simulation as given, after soil recalibration and after the chosen
    hypothesis."""
    points = report.points
    if not points:
        return []
    names = _prediction_names(report)
    palette = Palette([p["load_n"] for p in points], [p["multipass"] for p in points])
    groups: dict[tuple, list[Mapping[str, Any]]] = {}
    for p in points:
        groups.setdefault((p["source"], p["multipass"], p["gravity_mps2"]), []).append(p)
    several = [len({k[i] for k in groups}) > 1 for i in range(3)]
    titled = [(", ".join(([source.rsplit("/", 1)[-1]] if several[0] else [])
                         + ([f"multipass {mp}"] if several[1] else [])
                         + ([f"{g:.3g} m/s²"] if several[2] else [])), rows)
              for (source, mp, g), rows in groups.items()]
    offsets = _relative_offsets(report, names)
    fig = gap_curves(titled, list(report.quantities), names, palette, offsets)
    blocks: list[Block] = [
        Heading("Measured against simulated"),
        Image("gap-curves", "Measured values ± σ against slip per load"
              + (f" (rows: {', '.join(t for t, _ in titled)})" if len(titled) > 1 else "")
              + ", beside " + _listing(list(names.values())), to_png(fig)[0])]
    if offsets:
        blocks.append(Note("Sinkage was measured from an unknown zero: each prediction's "
                           "mean sinkage residual is removed before it is drawn."))
    return blocks


def _pm_text(value: float, half: float, scale: float) -> tuple[str, str, int]:
    """``value`` and a 95 % half-width in display units, both to the half-width's second
    significant digit: (value, half-width, decimals)."""
    v, h = value * scale, half * scale
    decimals = max(0, 1 - math.floor(math.log10(h))) if h > 0 else 3
    return f"{v:+.{decimals}f}", f"{h:.{decimals}f}", decimals


def _slips_text(slips: Sequence[float]) -> str:
    lo, hi = round(min(slips) * 100.0), round(max(slips) * 100.0)
    return f"slip {lo} %" if lo == hi else f"slips {lo} to {hi} %"


def _contrast_sentence(c: SiblingContrast, report: PosteriorReport) -> str:
    """``the lugged wheel minus its smooth twin: +2.1 ± 0.4 N of drawbar pull at 80 N (...);
    predicted by grousers (Ding 2011): +1.9 N (the simulation as given: +0.0 N)``."""
    q = QUANTITIES[c.quantity]
    half = (c.ci95[1] - c.ci95[0]) / 2.0
    value, pm, decimals = _pm_text(c.contrast, half, q.scale)
    predicted, chosen = c.predicted, report.chosen
    told = ""
    if chosen in predicted:
        told = f"; predicted by {candidate_text(report.explanation(chosen))}: " \
               f"{predicted[chosen] * q.scale:+.{decimals}f} {q.unit}"
        if SIMULATION in predicted:
            told += (f" ({PREDICTION_TEXT[SIMULATION]}: "
                     f"{predicted[SIMULATION] * q.scale:+.{decimals}f} {q.unit})")
    return _sentence(f"{_units(c.contrast_of)}: {value} ± {pm} {q.unit} of {q.label} at "
                     f"{c.load_n:g} N (95 % interval; {_slips_text(c.slips)}, "
                     f"{c.n} matched runs){told}")


def _contrast_blocks(report: PosteriorReport) -> list[Block]:
    """The sibling contrasts: what one feature changes at matched conditions, measured
    (with its 95 % interval) beside each prediction's contrast; sentences for those whose
    interval excludes zero (at most :data:`CONTRASTS_TOLD`), every one in the table."""
    contrasts = report.sibling_contrasts
    if not contrasts:
        return []
    names = _prediction_names(report)
    clear = sorted((c for c in contrasts if c.ci95[0] > 0 or c.ci95[1] < 0),
                   key=lambda c: -abs(c.contrast) / c.u)
    told = [Note(_contrast_sentence(c, report)) for c in clear[:CONTRASTS_TOLD]]
    if not clear:
        told = [Note("No measured contrast differs from zero at 95 %: what the sibling runs "
                     "differ in changes nothing beyond their noise here.")]
    elif len(clear) > CONTRASTS_TOLD:
        told.append(Note(f"{len(clear) - CONTRASTS_TOLD} more contrasts differ from zero at "
                         "95 %: in the table."))
    quantities = list(dict.fromkeys(c.quantity for c in contrasts))
    cells: dict[tuple, dict[str, SiblingContrast]] = {}
    for c in contrasts:
        cells.setdefault((c.contrast_of, c.load_n), {})[c.quantity] = c
    rows = []
    for (of, load), per in cells.items():
        shown = {q: _pm_text(c.contrast, (c.ci95[1] - c.ci95[0]) / 2.0,
                             QUANTITIES[q].scale) for q, c in per.items()}
        rows.append([_units(of), f"{load:g}", "measured (± 95 %)"]
                    + [f"{shown[q][0]} ± {shown[q][1]}" if q in shown else ""
                       for q in quantities])
        for key, text in names.items():
            rows.append(["", "", text] + [
                f"{per[q].predicted[key] * QUANTITIES[q].scale:+.{shown[q][2]}f}"
                if q in per and key in per[q].predicted else "" for q in quantities])
    header = (["contrast", "load [N]", ""]
              + [QUANTITIES[q].axis_label for q in quantities])
    return [Heading("Sibling contrasts: what one feature changes, at matched conditions"),
            Note("Runs that differ in one feature (a lugged wheel and its smooth twin, a later "
                 "soil pass, another gravity) are paired at the same load and slip (the other "
                 "side interpolated in slip); a base-model error common to both cancels in "
                 "the difference, so an effect must explain what is left."),
            *told,
            Table(header, rows, numeric=frozenset({1, *range(3, len(header))}))]


def _schema2_blocks(report: PosteriorReport) -> list[Block]:
    return (_verdict_blocks(report) + _noise_note(report) + _base_model_note(report)
            + _untestable_note(report)
            + _wheel_and_source_notes(report) + _probability_blocks(report)
            + _curve_blocks(report) + _contrast_blocks(report) + _where_blocks(report)
            + _how_far_blocks(report))


def _schema1_blocks(report: HeldOutReport) -> list[Block]:
    blocks: list[Block] = [Heading(f"Verdict: {verdict_text(report.verdict)}"),
                           Note(f"Reason, as the diagnosis writes it: {report.reason}",
                                warning=report.verdict == "inconclusive")]
    if (test := decisive_test_text(report)) is not None:
        blocks.append(Note(test))
    return (blocks + _untestable_note(report) + _wheel_and_source_notes(report)
            + _where_blocks(report) + _which_blocks_schema1(report) + _how_far_blocks(report))


def gap_blocks(report: GapReport) -> list[Block]:
    """Everything the gap report shows, in order. Schema 2: the verdict with its
    probability and the rule, the reason, the next test, where the noise came from, what
    could not be tested, the probabilities (chart and table), the measured curves beside the
    simulation, the sibling contrasts, where (residual maps) and how far (held-out RMSE).
    Schema 1: verdict, reason, test, where, the ranked candidates and how far."""
    if isinstance(report, PosteriorReport):
        return _schema2_blocks(report)
    assert isinstance(report, HeldOutReport)
    return _schema1_blocks(report)


def gather_gap(session: Session, data: CampaignData) -> dict | None:
    """The newest gap report recorded in the database; None without one."""
    row = session.scalars(select(GapReportRecord).order_by(GapReportRecord.id.desc())).first()
    return None if row is None else {"sim_source": row.sim_source, "report": row.report}


def gap_section(data: CampaignData, palette: Palette) -> Section | None:
    """The newest gap report of the campaign's database (its JSON, read here); None without
    one; a note for a report of a schema this swtlab does not read."""
    found = data.extras.get(NAME)
    if found is None:
        return None
    try:
        report = GapReport.from_json(found["report"])
    except UnknownSchema as exc:
        return Section(NAME, "Sim-to-real gap", [Note(
            f"This gap report has schema {exc.schema}; this swtlab reads "
            f"{', '.join(READABLE_SCHEMAS)}: a newer swtlab shows it.", warning=True)])
    intro = Note(f"Simulation {found['sim_source']} against the measurements of this database "
                 f"({report.n_points} runs).")
    return Section(NAME, "Sim-to-real gap", [intro, *gap_blocks(report)])


def gap_page(report: GapReport) -> Page:
    """The page ``swtlab gap --html`` writes: the same blocks as the campaign report's
    section, under the report's own header and style."""
    meta = [("measured", str(report.measured)), ("simulated", str(report.simulated)),
            ("runs compared", str(report.n_points)),
            ("quantities", ", ".join(QUANTITIES[q].axis_label for q in report.quantities)),
            ("generated", datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
             + f" by swtlab {swtlab_version()}")]
    return Page("Sim-to-real gap", meta, [Section(NAME, "Diagnosis", gap_blocks(report))],
                footer="Self-contained page written by swtlab gap: every figure is embedded, "
                       "nothing is fetched from the network. The numbers in full: the JSON "
                       "report (docs/gap-report.md).")


def write_gap_page(report: GapReport, path: str | Path) -> Path:
    """Write :func:`gap_page` of ``report`` to ``path`` (atomically)."""
    return write_atomically(path, render_page(gap_page(report)))


register(Extension(NAME, gap_section, gather_gap))
