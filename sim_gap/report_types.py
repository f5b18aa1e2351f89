"""The gap report as typed objects (docs/gap-report.md): what :mod:`campaign_report.gap` and
``swtlab gap`` read, converted from the JSON at the boundary (a stored file, a database
record) by :meth:`GapReport.from_json`; :meth:`GapReport.to_json` gives the JSON back as
:func:`sim_gap.report.build_report` writes it. Both schemas of
:data:`sim_gap.report.READABLE_SCHEMAS` are read: schema 2 (posterior probabilities,
:class:`PosteriorReport`) and schema 1 (held-out scores, swtlab 0.13, :class:`HeldOutReport`).
The parts the page reads field by field are typed, a law by its authors, year and
generalisation (:class:`Law`); the free-form tables (regions, points, shrink, wheel,
sources, next tests, the separating test) stay mappings."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar, Protocol, TypeVar

import terramechanics as tm
from sim_gap.candidates import is_free_form, law_beside
from sim_gap.hypotheses import OUTSIDE
from sim_gap.report import READABLE_SCHEMAS, SCHEMA
from swtlab_base.errors import InputError

SCHEMA_1 = READABLE_SCHEMAS[0]
SOIL_ONLY = "soil_only"
#: digits of the year that ends a published law's key (``wong_kobayashi2012``)
_YEAR_DIGITS = 4

Json = dict[str, Any]


class UnknownSchema(InputError, ValueError):
    """A gap report of a schema this swtlab does not read (a newer swtlab wrote it)."""

    def __init__(self, schema: str) -> None:
        super().__init__(f"gap report schema {schema!r}; this swtlab reads "
                         f"{', '.join(READABLE_SCHEMAS)}")
        self.schema = schema


@dataclass(frozen=True)
class Law:
    """A law of an effect by its parts: ``key`` as the report writes it
    (``lyasko2010~load``), the ``authors`` and ``year`` of the published law it is or
    extends, and ``varying``, the suffix of a generalised law (``~load``, ``~depth``,
    ``~slip``: :mod:`terramechanics.effects`), None for a published law. A free-form law
    (:data:`sim_gap.candidates.FREE_FORM`) and a law this swtlab does not know have no
    authors and no year."""

    key: str
    authors: tuple[str, ...] = ()
    year: int | None = None
    varying: str | None = None

    @property
    def free_form(self) -> bool:
        return is_free_form(self.key)

    @classmethod
    def of(cls, effect: str, key: str) -> Law:
        """The parts of law ``key`` of ``effect``: the published law it is or extends from
        the law's class (``relaxes``; :func:`terramechanics.published_law`), whose key is
        its authors' surnames and its year (one module per law, named after its source:
        ``terramechanics/effects``)."""
        beside = law_beside(key)
        if beside is not None:  # a law beside the free form: that law's parts
            return replace(cls.of(effect, beside), key=key)
        try:
            published = tm.published_law(effect, key)
        except KeyError:  # free form, or a law of an older swtlab: shown by its key
            return cls(key)
        names, year = published[:-_YEAR_DIGITS], published[-_YEAR_DIGITS:]
        if not (names and year.isdigit()):
            return cls(key)
        return cls(key, tuple(n.capitalize() for n in names.split("_")), int(year),
                   key[len(published):] or None)


def _laws(laws: Mapping[str, str]) -> dict[str, Law]:
    return {e: Law.of(e, law) for e, law in laws.items()}


class Explained(Protocol):
    """An explanation of the gap: no missing effect, effects (with their laws for a
    hypothesis, without for an effect set), or an effect outside the candidates."""

    @property
    def effects(self) -> tuple[str, ...]: ...

    @property
    def laws(self) -> Mapping[str, Law]: ...

    @property
    def outside(self) -> bool: ...


@dataclass(frozen=True)
class Hypothesis:
    """One hypothesis of a schema-2 report: ``key`` (effects with their laws), ``label``
    (its effect set), the evidence it rests on and its probabilities; ``parameters``: the
    fitted values by dotted model name (``soil.kphi``, ``effects.bulldozing.coefficient``)."""

    key: str
    label: str
    effects: tuple[str, ...]
    laws: Mapping[str, Law]
    n_params: int
    log_evidence: float
    prior: float
    probability: float
    discrepancy_tau: float
    chi2: float
    parameters: Mapping[str, float]

    @property
    def outside(self) -> bool:
        return self.key == OUTSIDE

    @classmethod
    def from_json(cls, d: Json) -> Hypothesis:
        return cls(d["key"], d["label"], tuple(d["effects"]), _laws(d["laws"]),
                   d["n_params"], d["log_evidence"], d["prior"], d["probability"],
                   d["discrepancy_tau"], d["chi2"], dict(d["parameters"]))

    def to_json(self) -> Json:
        return {"key": self.key, "label": self.label, "effects": list(self.effects),
                "laws": {e: law.key for e, law in self.laws.items()},
                "n_params": self.n_params, "log_evidence": self.log_evidence,
                "prior": self.prior, "probability": self.probability,
                "discrepancy_tau": self.discrepancy_tau, "chi2": self.chi2,
                "parameters": dict(self.parameters)}


@dataclass(frozen=True)
class EffectSet:
    """An effect set with its probability (its laws summed): ``soil_only``, effects, or
    ``outside_candidates``."""

    label: str
    effects: tuple[str, ...]
    probability: float

    @property
    def outside(self) -> bool:
        return self.label == OUTSIDE

    @property
    def laws(self) -> Mapping[str, Law]:
        """None: an effect set stands for each of its laws."""
        return {}

    @classmethod
    def from_json(cls, d: Json) -> EffectSet:
        return cls(d["label"], tuple(d["effects"]), d["probability"])

    def to_json(self) -> Json:
        return {"label": self.label, "effects": list(self.effects),
                "probability": self.probability}


@dataclass(frozen=True)
class Leader:
    """One of the two leading effect sets (by ``label``) with its probability."""

    label: str
    probability: float

    def to_json(self) -> Json:
        return {"label": self.label, "probability": self.probability}


@dataclass(frozen=True)
class SiblingContrast:
    """What one feature changes at matched conditions (:mod:`sim_gap.siblings`): the
    measured ``contrast`` (SI unit of ``quantity``) with its standard uncertainty ``u`` and
    95 % interval, and each prediction's contrast by prediction key."""

    feature: str
    contrast_of: str
    load_n: float
    quantity: str
    contrast: float
    u: float
    ci95: tuple[float, float]
    n: int
    slips: tuple[float, ...]
    predicted: Mapping[str, float]

    @classmethod
    def from_json(cls, d: Json) -> SiblingContrast:
        low, high = d["ci95"]
        return cls(d["feature"], d["contrast_of"], d["load_n"], d["quantity"], d["contrast"],
                   d["u"], (low, high), d["n"], tuple(d["slips"]), dict(d["predicted"]))

    def to_json(self) -> Json:
        return {"ci95": list(self.ci95), "contrast": self.contrast,
                "contrast_of": self.contrast_of, "feature": self.feature,
                "load_n": self.load_n, "n": self.n, "predicted": dict(self.predicted),
                "quantity": self.quantity, "slips": list(self.slips), "u": self.u}


@dataclass(frozen=True)
class RankedCandidate:
    """A candidate of a schema-1 report, ranked by its held-out score (RMS held-out
    residual in units of its uncertainty); ``other``: the rest of its JSON as written."""

    label: str
    effects: tuple[str, ...]
    laws: Mapping[str, Law]
    held_out_score: float
    z_vs_best: float
    n_params: int
    parameters: Mapping[str, float]
    other: Mapping[str, Any]

    _TYPED = ("label", "effects", "laws", "held_out_score", "z_vs_best", "n_params",
              "parameters")

    @property
    def outside(self) -> bool:
        return False

    @classmethod
    def from_json(cls, d: Json) -> RankedCandidate:
        return cls(d["label"], tuple(d["effects"]), _laws(d["laws"]), d["held_out_score"],
                   d["z_vs_best"], d["n_params"], dict(d["parameters"]),
                   {k: v for k, v in d.items() if k not in cls._TYPED})

    def to_json(self) -> Json:
        return {"label": self.label, "effects": list(self.effects),
                "laws": {e: law.key for e, law in self.laws.items()},
                "held_out_score": self.held_out_score, "z_vs_best": self.z_vs_best,
                "n_params": self.n_params, "parameters": dict(self.parameters),
                **self.other}


#: keys a schema-2 report written before they existed lacks, with the value it is read with
_SCHEMA_2_DEFAULTS: dict[str, Any] = {"learning_rate": None, "next_tests": [],
                                      "admissible_tests": [], "points": [],
                                      "leaders_separation_sigma": None, "base_model": {}}
#: keys :func:`sim_gap.api.gap_report` adds to :func:`sim_gap.report.build_report`'s
_ADDED = ("wheel", "sources", "effect_sources")


@dataclass(frozen=True)
class GapReport(ABC):
    """What a gap report of either schema holds (docs/gap-report.md): a
    :class:`PosteriorReport` (schema 2) or a :class:`HeldOutReport` (schema 1).
    ``verdict``: the missing effects (``()`` for none), ``"inconclusive"`` or
    ``"outside_candidates"``; ``chosen``: the key of the most probable named hypothesis
    (schema 1: the chosen candidate's label); ``wheel``, ``sources`` and ``effect_sources``
    None where the report has none (:func:`sim_gap.report.build_report` alone writes none,
    :func:`sim_gap.api.gap_report` adds them)."""

    schema: ClassVar[str]

    measured: str
    simulated: str
    verdict: tuple[str, ...] | str
    reason: str
    separating_test: Mapping[str, Any] | None
    chosen: str
    held_out_rmse_before: Mapping[str, float | None]
    held_out_rmse_after: Mapping[str, float | None]
    shrink_pct: Mapping[str, float | None]
    shrink: Mapping[str, Any]
    regions: tuple[Mapping[str, Any], ...]
    untestable_effects: Mapping[str, str]
    contrasts: Mapping[str, int]
    folds: tuple[str, ...]
    n_points: int
    quantities: tuple[str, ...]
    sinkage_relative: bool
    settings: Mapping[str, Any]
    wheel: Mapping[str, Any] | None
    sources: tuple[Mapping[str, Any], ...] | None
    effect_sources: Mapping[str, Any] | None

    @abstractmethod
    def explanation(self, key: str) -> Explained:
        """The hypothesis (schema 1: the candidate) of key ``key``; KeyError naming it."""

    @abstractmethod
    def leading(self) -> Sequence[Explained]:
        """The two leading named explanations the separating test is about."""

    def check(self) -> None:
        """KeyError naming what the report names but lacks."""
        self.explanation(self.chosen)
        self.leading()

    @abstractmethod
    def _middle(self) -> Json:
        """The keys of the JSON that are the schema's own, in their place."""

    @staticmethod
    def from_json(d: Mapping[str, Any]) -> GapReport:
        """The report of its JSON ``d`` (schema 1 or 2; without ``schema``: 1).
        :class:`UnknownSchema` for another schema, ``ValueError`` naming the key for a report
        that lacks one or the hypothesis, candidate or effect set it names but lacks."""
        schema = d.get("schema", SCHEMA_1)
        kinds: dict[str, type[PosteriorReport] | type[HeldOutReport]] = {
            SCHEMA: PosteriorReport, SCHEMA_1: HeldOutReport}
        if schema not in kinds:
            raise UnknownSchema(schema)
        try:
            report = kinds[schema].read(d, _common(d))
        except KeyError as exc:
            raise ValueError(f"gap report ({schema}): no {exc} where the schema has one"
                             ) from None
        try:
            report.check()
        except KeyError as exc:
            raise ValueError(exc.args[0]) from None
        return report

    def to_json(self) -> Json:
        """The JSON of the report, key for key as :func:`sim_gap.report.build_report` (and
        :func:`sim_gap.api.gap_report`) wrote it."""
        head = {"schema": self.schema, "measured": self.measured,
                "simulated": self.simulated, "verdict": _plain(self.verdict)}
        tail = {
            "held_out_rmse_before": _plain(self.held_out_rmse_before),
            "held_out_rmse_after": _plain(self.held_out_rmse_after),
            "shrink_pct": _plain(self.shrink_pct), "shrink": _plain(self.shrink),
            "regions": _plain(self.regions),
            "untestable_effects": _plain(self.untestable_effects),
            "contrasts": _plain(self.contrasts), "folds": list(self.folds),
            "n_points": self.n_points, "quantities": list(self.quantities),
            "sinkage_relative": self.sinkage_relative, "settings": _plain(self.settings)}
        added = {k: _plain(getattr(self, k)) for k in _ADDED if getattr(self, k) is not None}
        return {**head, **self._middle(), **tail, **added}


def _common(d: Mapping[str, Any]) -> dict[str, Any]:
    """The fields of :class:`GapReport` from the JSON ``d``."""
    verdict, sources = d["verdict"], d.get("sources")
    return dict(
        measured=d["measured"], simulated=d["simulated"],
        verdict=verdict if isinstance(verdict, str) else tuple(verdict),
        reason=d["reason"], separating_test=d.get("separating_test"), chosen=d["chosen"],
        held_out_rmse_before=d["held_out_rmse_before"],
        held_out_rmse_after=d["held_out_rmse_after"], shrink_pct=d["shrink_pct"],
        shrink=d["shrink"], regions=tuple(d["regions"]),
        untestable_effects=d["untestable_effects"], contrasts=d["contrasts"],
        folds=tuple(d["folds"]), n_points=d["n_points"], quantities=tuple(d["quantities"]),
        sinkage_relative=d["sinkage_relative"], settings=d["settings"], wheel=d.get("wheel"),
        sources=None if sources is None else tuple(sources),
        effect_sources=d.get("effect_sources"))


@dataclass(frozen=True)
class PosteriorReport(GapReport):
    """A schema-2 report: the posterior probability of each hypothesis
    (:mod:`sim_gap.decide`), the verdict's ``probability`` and the ``call_probability`` it
    needs, the next tests by expected information gain, the sibling contrasts, the noise's
    source per quantity, the base model's braked branch (``base_model``: the law chosen and
    the soil-only log evidence of each; empty without braked runs) and each measured point
    beside the predictions."""

    schema: ClassVar[str] = SCHEMA

    probability: float
    call_probability: float
    learning_rate: float | None
    next_tests: tuple[Mapping[str, Any], ...]
    admissible_tests: tuple[Mapping[str, Any], ...]
    leaders: tuple[Leader, ...]
    leaders_separation_sigma: float | None
    effect_sets: tuple[EffectSet, ...]
    effect_probabilities: Mapping[str, float]
    hypotheses: tuple[Hypothesis, ...]
    sibling_contrasts: tuple[SiblingContrast, ...]
    noise: Mapping[str, str]
    base_model: Mapping[str, Any]
    points: tuple[Mapping[str, Any], ...]

    def explanation(self, key: str) -> Hypothesis:
        """The hypothesis of key ``key``; KeyError naming it."""
        return _one(self.hypotheses, "key", key, "hypotheses")

    def effect_set(self, label: str) -> EffectSet:
        """The effect set of label ``label``; KeyError naming it."""
        return _one(self.effect_sets, "label", label, "effect sets")

    def leading(self) -> list[Hypothesis]:
        """The two most probable hypotheses but the outside one."""
        return [h for h in self.hypotheses if not h.outside][:2]

    def check(self) -> None:
        super().check()
        for x in self.leaders:
            self.effect_set(x.label)

    @classmethod
    def read(cls, d: Mapping[str, Any], common: dict[str, Any]) -> PosteriorReport:
        g = {**_SCHEMA_2_DEFAULTS, **d}
        return cls(
            **common, probability=g["probability"], call_probability=g["call_probability"],
            learning_rate=g["learning_rate"], next_tests=tuple(g["next_tests"]),
            admissible_tests=tuple(g["admissible_tests"]),
            leaders=tuple(Leader(x["label"], x["probability"]) for x in g["leaders"]),
            leaders_separation_sigma=g["leaders_separation_sigma"],
            effect_sets=tuple(EffectSet.from_json(s) for s in g["effect_sets"]),
            effect_probabilities=g["effect_probabilities"],
            hypotheses=tuple(Hypothesis.from_json(h) for h in g["hypotheses"]),
            sibling_contrasts=tuple(SiblingContrast.from_json(c)
                                    for c in g["sibling_contrasts"]),
            noise=g["noise"], base_model=g["base_model"], points=tuple(g["points"]))

    def _middle(self) -> Json:
        return {
            "probability": self.probability, "call_probability": self.call_probability,
            "learning_rate": self.learning_rate, "reason": self.reason,
            "separating_test": _plain(self.separating_test),
            "next_tests": _plain(self.next_tests),
            "admissible_tests": _plain(self.admissible_tests), "chosen": self.chosen,
            "leaders": [x.to_json() for x in self.leaders],
            "leaders_separation_sigma": self.leaders_separation_sigma,
            "effect_sets": [s.to_json() for s in self.effect_sets],
            "effect_probabilities": _plain(self.effect_probabilities),
            "hypotheses": [h.to_json() for h in self.hypotheses],
            "sibling_contrasts": [c.to_json() for c in self.sibling_contrasts],
            "noise": _plain(self.noise),
            **({"base_model": _plain(self.base_model)} if self.base_model else {}),
            "points": _plain(self.points)}


@dataclass(frozen=True)
class HeldOutReport(GapReport):
    """A schema-1 report (swtlab 0.13): the candidates ranked by their held-out score;
    ``decision``: the decision's details as written (its ``leaders``: the two leading
    candidates' labels)."""

    schema: ClassVar[str] = SCHEMA_1

    candidates: tuple[RankedCandidate, ...]
    decision: Mapping[str, Any]

    def explanation(self, key: str) -> RankedCandidate:
        """The candidate of label ``key``; KeyError naming it."""
        return _one(self.candidates, "label", key, "candidates")

    def leading(self) -> list[RankedCandidate]:
        """The candidates of the decision's ``leaders``."""
        return [self.explanation(k) for k in self.decision.get("leaders") or []]

    @classmethod
    def read(cls, d: Mapping[str, Any], common: dict[str, Any]) -> HeldOutReport:
        return cls(**common, decision=d["decision"],
                   candidates=tuple(RankedCandidate.from_json(c) for c in d["candidates"]))

    def _middle(self) -> Json:
        return {"reason": self.reason, "separating_test": _plain(self.separating_test),
                "chosen": self.chosen, "candidates": [c.to_json() for c in self.candidates],
                "decision": _plain(self.decision)}


_T = TypeVar("_T")


def _one(items: Sequence[_T], field: str, value: str, what: str) -> _T:
    """The first of ``items`` whose ``field`` is ``value``; KeyError naming it and ``what``
    the report holds."""
    for item in items:
        if getattr(item, field) == value:
            return item
    raise KeyError(f"gap report: {value!r} is none of its {what}")


def _plain(value: Any) -> Any:
    """A copy of ``value`` as JSON holds it: mappings to dicts, sequences to lists."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, Sequence) and not isinstance(value, str):
        return [_plain(v) for v in value]
    return value
