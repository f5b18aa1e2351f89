"""The gap report as typed objects (sim_gap.report_types): a report read from its JSON gives
the JSON back key for key (schema 2: the sample campaign's stored report; schema 1: the
report swtlab 0.13.0 wrote, tests/data/gap_report_v1_ding2011.json), and a law's parts are
those of the law it names."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

import terramechanics as tm
from sim_gap.candidates import BESIDE_LAW, FREE_FORM
from sim_gap.report_types import GapReport, HeldOutReport, Law, PosteriorReport, UnknownSchema

DATA = Path(__file__).parent
SCHEMA_2_REPORT = DATA / "reference" / "sample_campaign" / "gap.json"
SCHEMA_1_REPORT = DATA / "data" / "gap_report_v1_ding2011.json"


def _load(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("path", [SCHEMA_2_REPORT, SCHEMA_1_REPORT], ids=["schema2", "schema1"])
def test_a_report_read_from_its_json_gives_it_back(path):
    written = _load(path)
    report = GapReport.from_json(copy.deepcopy(written))
    assert report.to_json() == written
    assert json.dumps(report.to_json(), sort_keys=True) == json.dumps(written, sort_keys=True)


def test_build_reports_json_without_the_wheel_gives_it_back_without_the_wheel():
    """``build_report`` alone writes no wheel, sources or effect sources (``gap_report`` adds
    them): none is read, none written."""
    written = {k: v for k, v in _load(SCHEMA_2_REPORT).items()
               if k not in ("wheel", "sources", "effect_sources")}
    report = GapReport.from_json(written)
    assert (report.wheel, report.sources, report.effect_sources) == (None, None, None)
    assert report.to_json() == written


def test_the_typed_fields_are_the_jsons():
    written = _load(SCHEMA_2_REPORT)
    report = GapReport.from_json(written)
    assert isinstance(report, PosteriorReport)
    assert report.verdict == () and report.chosen == "soil_only"
    assert report.probability == written["probability"] > 0.9
    h = report.hypotheses[1]
    assert h.key == "bulldozing(rankine_terzaghi1943)" and h.effects == ("bulldozing",)
    assert h.laws == {"bulldozing": Law("rankine_terzaghi1943", ("Rankine", "Terzaghi"), 1943)}
    assert h.log_evidence == written["hypotheses"][1]["log_evidence"]
    assert [s.label for s in report.effect_sets] == ["soil_only", "bulldozing",
                                                      "outside_candidates"]
    assert report.effect_set("bulldozing").effects == ("bulldozing",)
    assert report.explanation("soil_only") is report.hypotheses[0]
    assert report.leading() == [report.hypotheses[0], report.hypotheses[1]]
    c = report.sibling_contrasts[0]
    assert c.ci95 == tuple(written["sibling_contrasts"][0]["ci95"]) and c.feature == "multipass"
    v1 = GapReport.from_json(_load(SCHEMA_1_REPORT))
    assert isinstance(v1, HeldOutReport) and v1.verdict == "inconclusive"
    assert [x.label for x in v1.leading()] == ["grousers(ding2011)", "soil_only"]
    assert v1.candidates[0].laws["wheel_flexibility"] == Law("wong2010", ("Wong",), 2010)


def test_a_laws_parts_are_those_of_the_law_it_names():
    assert Law.of("reduced_gravity", "wong_kobayashi2012") == Law(
        "wong_kobayashi2012", ("Wong", "Kobayashi"), 2012, None)
    assert Law.of("slip_sinkage", "lyasko2010~load") == Law("lyasko2010~load", ("Lyasko",),
                                                             2010, "~load")
    assert Law.of("grousers", "bekker1956~slip").varying == "~slip"
    assert Law.of("grousers", FREE_FORM) == Law(FREE_FORM) and Law(FREE_FORM).free_form
    assert Law.of("grousers", "smith1999") == Law("smith1999")  # not a law of this swtlab
    beside = Law.of("multipass", f"krenn_hirzinger2009{BESIDE_LAW}{FREE_FORM}")
    assert beside.free_form and (beside.authors, beside.year) == (("Krenn", "Hirzinger"), 2009)
    for effect, laws in tm.LAWS.items():  # every law's key names its authors and year
        for key, cls in laws.items():
            law = Law.of(effect, key)
            assert law.authors and 1900 < law.year < 2100, key
            assert (law.varying is None) == (cls.relaxes is None), key


def test_a_report_it_cannot_read_is_said_in_one_line():
    with pytest.raises(UnknownSchema, match="'swtlab.gap-report/9'; this swtlab reads "):
        GapReport.from_json(dict(_load(SCHEMA_2_REPORT), schema="swtlab.gap-report/9"))
    lacking = _load(SCHEMA_2_REPORT)
    del lacking["hypotheses"]
    with pytest.raises(ValueError, match=r"gap report \(swtlab.gap-report/2\): no 'hypotheses'"):
        GapReport.from_json(lacking)
    with pytest.raises(ValueError, match="^gap report: 'grousers' is none of its hypotheses$"):
        GapReport.from_json(dict(_load(SCHEMA_2_REPORT), chosen="grousers"))
    with pytest.raises(ValueError, match="'grousers' is none of its effect sets"):
        GapReport.from_json(dict(_load(SCHEMA_2_REPORT),
                                 leaders=[{"label": "grousers", "probability": 0.5}]))
