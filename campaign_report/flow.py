"""Report section: the soil velocity field under the wheel, from side-camera frames (SOFT).

Registered as an optional section (:mod:`campaign_report.extensions`): it appears when runs of
the campaign carry a soil flow (``swtlab process`` on runs with ``/camera/side`` frames,
docs/softflow.md) or frames that could not be analysed. Per run: the speed map over the first
frame, the profiles with their decay fits, ``k(beta)`` and ``alpha3(beta)`` with their CIs,
and the grouser-model scores; the figures are :mod:`softflow.flow_plots`' own, drawn from the
stored result and its compact arrays (``softflow.flow_archive``), not from the raw frames.
Its data (``data.extras["soil-flow"]``): :class:`FlowData`, read from the database by
:func:`gather_flows` or built by a pipeline from its own flow results.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from matplotlib.figure import Figure
from sqlalchemy import select
from sqlalchemy.orm import Session

from campaign_report.data import CampaignData
from campaign_report.extensions import Extension, register
from campaign_report.html import Heading, Image, Note, Section, Table
from campaign_report.images import thumbnail, to_png
from campaign_report.style import Palette
from traceability.models import RawFile, Run, RunResult, SoilFlow, SoilFlowFailure


NAME = "soil-flow"


@dataclass(frozen=True)
class FlowRecord:
    """One run's soil flow as the section shows it (the ``soil_flow`` columns it reads):
    ``result`` is ``FlowResult.to_dict()``, ``field_npz`` ``softflow.flow_archive.pack_flow``."""

    frame_first: int
    frame_last: int
    t_first_s: float
    t_last_s: float
    pairs: int
    engine: str
    sled_velocity_x_mps: float
    outlier_fraction: float
    grouser_model: str | None
    grouser_margin_percent: float | None
    alpha1_per_m: float | None
    alpha2: float | None
    result: dict
    field_npz: bytes


@dataclass(frozen=True)
class FlowData:
    """(run_id, flow) of every run with a soil flow; (run_id, channel, problem) of every run
    whose frames could not be analysed."""

    flows: list[tuple[str, FlowRecord]]
    failures: list[tuple[str, str, str]]


def _newest(session: Session, data: CampaignData, model) -> list:
    """(run_id, row) of ``model`` stored with the newest result of each of the campaign's runs."""
    ids = [int(i) for i in data.results["result_id"]]
    return session.execute(
        select(Run.run_id, model)
        .join(RunResult, (RunResult.raw_file_id == model.raw_file_id)
              & (RunResult.params_sha256 == model.params_sha256))
        .join(RawFile, RawFile.id == model.raw_file_id).join(Run, Run.id == RawFile.run_pk)
        .where(RunResult.id.in_(ids)).order_by(Run.run_id)).all()


def grouser_scores(grouser: dict) -> Figure:
    """RMS residual of each grouser effective-radius model; the chosen one highlighted."""
    fig = Figure(figsize=(6, 3.2))
    ax = fig.subplots()
    models = list(grouser["scores_mps"])
    rms_mmps = [1000 * grouser["scores_mps"][m] for m in models]
    ax.barh(models, rms_mmps, color=["#0072B2" if m == grouser["chosen"] else "0.7"
                                     for m in models])
    ax.set(xlabel="RMS residual of the model field (mm/s)",
           title=f"grouser model: {grouser['chosen']}, by {grouser['margin_percent']:.1f} % "
                 f"(gear gamma {grouser['gamma']})")
    ax.set_xlim(0.95 * min(rms_mmps), 1.02 * max(rms_mmps))
    ax.invert_yaxis()  # models top to bottom in their order
    fig.tight_layout()
    return fig


def _image(anchor: str, caption: str, fig) -> Image:
    import matplotlib.pyplot as plt

    png, full = to_png(fig)
    plt.close(fig)
    return Image(anchor, caption, png, thumbnail(full))


def gather_flows(session: Session, data: CampaignData) -> FlowData | None:
    """The stored soil flows and flow failures of the campaign's newest results; None: none."""
    names = [f.name for f in fields(FlowRecord)]
    flows = [(run_id, FlowRecord(**{n: getattr(row, n) for n in names}))
             for run_id, row in _newest(session, data, SoilFlow)]
    failures = [(run_id, f.channel, f.problem)
                for run_id, f in _newest(session, data, SoilFlowFailure)]
    return FlowData(flows, failures) if flows or failures else None


def _figures(index: int, run_id: str, row: FlowRecord) -> list[Image]:
    # here: a campaign without soil flow loads neither softflow nor numba
    from softflow import flow_plots
    from softflow.flow_archive import unpack_flow

    result, frame = unpack_flow(row.result, row.field_npz)
    anchor = f"flow-{index}"
    images = [
        _image(f"{anchor}-speed", f"{run_id}: soil speed (bin frame) over frame "
                                  f"{row.frame_first}", flow_plots.magnitude_map(result, frame)),
        _image(f"{anchor}-profiles", f"{run_id}: v_r and v_theta against the distance from the "
                                     "rim, with their fits", flow_plots.profiles_with_fits(result)),
        _image(f"{anchor}-rates", f"{run_id}: k(beta) and alpha3(beta), 95 % CI",
               flow_plots.rates_by_beta(result))]
    if result.grouser:
        images.append(_image(f"{anchor}-grousers", f"{run_id}: grouser-model scores",
                             grouser_scores(result.grouser)))
    return images


def _summary(flows: list) -> Table:
    cells = [[run_id, f"{f.frame_first}–{f.frame_last}", f"{f.t_first_s:.2f}–{f.t_last_s:.2f}",
              str(f.pairs), f.engine, f"{1000 * f.sled_velocity_x_mps:.2f}",
              f"{100 * f.outlier_fraction:.2f}",
              "–" if f.grouser_model is None
              else f"{f.grouser_model} ({f.grouser_margin_percent:.1f} %)",
              "–" if None in (f.alpha1_per_m, f.alpha2)
              else f"{f.alpha1_per_m:.3g}, {f.alpha2:.3g}"]
             for run_id, f in flows]
    return Table(["run", "frames", "time (s)", "pairs", "engine", "sled velocity x (mm/s)",
                  "outliers (%)", "grouser model (margin)", "alpha1 (1/m), alpha2"], cells,
                 numeric=frozenset({3, 5, 6}))


def flow_section(data: CampaignData, palette: Palette) -> Section | None:
    """Soil flow of every run of the campaign with side-camera frames; None without any."""
    found: FlowData | None = data.extras.get(NAME)
    if found is None:
        return None
    flows, failures = found.flows, found.failures
    blocks: list = [Note("Soil velocity under the wheel from the side-camera frames of each "
                         "run's stable window (SOFT): speed over the frame, radial and "
                         "tangential profiles with their exponential fits, the decay rates "
                         "k(beta) and alpha3(beta) with 95 % confidence intervals, and the "
                         "grouser effective-radius models scored against the field.")]
    blocks += [Note(f"{run_id}: soil flow not measured: {channel}: {problem}", warning=True)
               for run_id, channel, problem in failures]
    if flows:
        blocks.append(_summary(flows))
    for i, (run_id, row) in enumerate(flows):
        blocks.append(Heading(f"{run_id}, frames {row.frame_first}–{row.frame_last}"))
        blocks += _figures(i, run_id, row)
    return Section("soil-flow", "Soil flow under the wheel", blocks)


register(Extension(NAME, flow_section, gather_flows))
