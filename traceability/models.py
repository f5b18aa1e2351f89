"""ORM tables of the traceability database (SQLAlchemy 2 typed declarative mapping).

Every derived row points at the ``processing_record`` that made it (swtlab
version, stage, parameters, time), so any number traces back to raw files.
"""

from __future__ import annotations

from datetime import datetime

from sqlalchemy import (JSON, DateTime, Float, ForeignKey, Integer, LargeBinary, String,
                        UniqueConstraint)
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column, relationship

from swtlab_base import domain

#: characters of a name users write (campaign, run_id, wheel, soil, topic, channel field);
#: longer names are refused by ``traceability.text`` with a clear error, on every backend
NAME_CHARS = 1000
#: characters of a file path
PATH_CHARS = 4096
#: characters of a stored error message (longer ones are cut, with a mark)
MESSAGE_CHARS = 2000


class Base(DeclarativeBase):
    pass


class ProcessingRecord(Base):
    """Who made a row: swtlab version and the sha256 of the lock file it was installed from
    (None where there was none, e.g. a wheel install), pipeline stage, its parameters, when."""

    __tablename__ = "processing_record"
    id: Mapped[int] = mapped_column(primary_key=True)
    swtlab_version: Mapped[str] = mapped_column(String(40))
    lock_sha256: Mapped[str | None] = mapped_column(String(64), nullable=True)
    stage: Mapped[str] = mapped_column(String(40))
    parameters: Mapped[dict] = mapped_column(JSON, default=dict)
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True))


class Campaign(Base):
    __tablename__ = "campaign"
    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(NAME_CHARS), unique=True)


class Wheel(Base):
    """A wheel as the metadata describes it; one row per distinct geometry under a name."""

    __tablename__ = "wheel"
    __table_args__ = (UniqueConstraint("name", "radius_m", "width_m", "grouser_count",
                                       "grouser_height_m", "stiffness_n_per_mm"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(NAME_CHARS))
    radius_m: Mapped[float] = mapped_column(Float)
    width_m: Mapped[float] = mapped_column(Float)
    grouser_count: Mapped[int] = mapped_column(Integer)
    grouser_height_m: Mapped[float] = mapped_column(Float)
    stiffness_n_per_mm: Mapped[float | None] = mapped_column(Float, nullable=True)
    mass_kg: Mapped[float | None] = mapped_column(Float, nullable=True)


class Soil(Base):
    __tablename__ = "soil"
    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(NAME_CHARS), unique=True)


class TestCondition(Base):
    """The set point of a run (:class:`swtlab_base.domain.TestCondition`, the one definition;
    :meth:`to_domain` and :func:`condition_columns` map between the two) of one campaign, wheel
    and soil. The columns keep the spec's names ``load_n`` and ``velocity_mps``."""

    __tablename__ = "test_condition"
    __test__ = False  # not a pytest class
    id: Mapped[int] = mapped_column(primary_key=True)
    campaign_id: Mapped[int] = mapped_column(ForeignKey("campaign.id"))
    wheel_id: Mapped[int] = mapped_column(ForeignKey("wheel.id"))
    soil_id: Mapped[int] = mapped_column(ForeignKey("soil.id"))
    mode: Mapped[str] = mapped_column(String(20))
    multipass: Mapped[int] = mapped_column(Integer)
    load_n: Mapped[float] = mapped_column(Float)
    slip_setpoint: Mapped[float | None] = mapped_column(Float, nullable=True)
    velocity_mps: Mapped[float] = mapped_column(Float)
    gravity_mps2: Mapped[float] = mapped_column(Float)
    steer_deg: Mapped[float | None] = mapped_column(Float, nullable=True)

    wheel: Mapped[Wheel] = relationship()
    soil: Mapped[Soil] = relationship()

    def to_domain(self) -> domain.TestCondition:
        """This row's set point as the domain type."""
        return domain.TestCondition(mode=self.mode, load_set_n=self.load_n,
                                    multipass=self.multipass, velocity_set_mps=self.velocity_mps,
                                    slip_setpoint=self.slip_setpoint,
                                    gravity_mps2=self.gravity_mps2, steer_deg=self.steer_deg)


def condition_columns(condition: domain.TestCondition) -> dict[str, object]:
    """The :class:`TestCondition` row's set-point columns of ``condition``."""
    return {"mode": condition.mode, "multipass": condition.multipass,
            "load_n": condition.load_set_n, "slip_setpoint": condition.slip_setpoint,
            "velocity_mps": condition.velocity_set_mps, "gravity_mps2": condition.gravity_mps2,
            "steer_deg": condition.steer_deg}


class Run(Base):
    """One drive through the bin, identified by (campaign, run_id) from its metadata (by its
    content where the file names no run_id). ``current_version``: the raw-file version its
    results and condition come from (the newest stored, or an older one the file was
    reverted to)."""

    __tablename__ = "run"
    __table_args__ = (UniqueConstraint("campaign_id", "run_id"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    campaign_id: Mapped[int] = mapped_column(ForeignKey("campaign.id"))
    run_id: Mapped[str] = mapped_column(String(NAME_CHARS))
    condition_id: Mapped[int] = mapped_column(ForeignKey("test_condition.id"))
    started_at: Mapped[datetime | None] = mapped_column(DateTime(timezone=True), nullable=True)
    current_version: Mapped[int] = mapped_column(Integer)

    campaign: Mapped[Campaign] = relationship()
    condition: Mapped[TestCondition] = relationship()
    raw_files: Mapped[list[RawFile]] = relationship(back_populates="run",
                                                    order_by="RawFile.version")


class RawFile(Base):
    """One version of a run's raw file (or CSV run folder); a changed file is a new version.
    ``missing_since``: when ``swtlab process`` of its folder found the file gone (None: there,
    or never looked for)."""

    __tablename__ = "raw_file"
    __table_args__ = (UniqueConstraint("run_pk", "version"), UniqueConstraint("run_pk", "sha256"))
    id: Mapped[int] = mapped_column(primary_key=True)
    run_pk: Mapped[int] = mapped_column(ForeignKey("run.id"))
    version: Mapped[int] = mapped_column(Integer)
    path: Mapped[str] = mapped_column(String(PATH_CHARS))
    size_bytes: Mapped[int] = mapped_column(Integer)
    sha256: Mapped[str] = mapped_column(String(64))
    file_format: Mapped[str] = mapped_column(String(NAME_CHARS))
    channel_summary: Mapped[list[dict]] = mapped_column(JSON)
    problems: Mapped[list] = mapped_column(JSON)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))
    missing_since: Mapped[datetime | None] = mapped_column(DateTime(timezone=True),
                                                          nullable=True)

    run: Mapped[Run] = relationship(back_populates="raw_files")
    processing: Mapped[ProcessingRecord] = relationship()
    calibrations: Mapped[list[Calibration]] = relationship(back_populates="raw_file")


class Calibration(Base):
    """A gain/offset or a tare (zero offset) applied to one channel of one raw file."""

    __tablename__ = "calibration"
    id: Mapped[int] = mapped_column(primary_key=True)
    raw_file_id: Mapped[int] = mapped_column(ForeignKey("raw_file.id"))
    kind: Mapped[str] = mapped_column(String(20))  # "gain_offset" or "zero"
    topic: Mapped[str] = mapped_column(String(NAME_CHARS))
    field: Mapped[str] = mapped_column(String(NAME_CHARS))
    gain: Mapped[float] = mapped_column(Float)
    offset: Mapped[float] = mapped_column(Float)

    raw_file: Mapped[RawFile] = relationship(back_populates="calibrations")


class IngestFailure(Base):
    """A file that could not be processed, with its one-line reason (a batch report lists it):
    the ``stage`` that failed (``ingest``, ``results``, ``store``), the exception's class
    ``error_type`` and the run's ``run_id`` where ingest got that far."""

    __tablename__ = "ingest_failure"
    id: Mapped[int] = mapped_column(primary_key=True)
    path: Mapped[str] = mapped_column(String(PATH_CHARS))
    sha256: Mapped[str] = mapped_column(String(64))
    error: Mapped[str] = mapped_column(String(MESSAGE_CHARS))
    stage: Mapped[str] = mapped_column(String(20), default="ingest")
    error_type: Mapped[str | None] = mapped_column(String(100), nullable=True)
    run_id: Mapped[str | None] = mapped_column(String(NAME_CHARS), nullable=True)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    processing: Mapped[ProcessingRecord] = relationship()

    @property
    def failure_type(self) -> str:
        """``error_type``; a row stored before migration 0010 added the column has none and
        was an ingest failure: ``IngestError``."""
        return self.error_type or "IngestError"


class StableWindow(Base):
    """The stable phase found in one raw-file version: where, how, and the checks it passed."""

    __tablename__ = "stable_window"
    id: Mapped[int] = mapped_column(primary_key=True)
    raw_file_id: Mapped[int] = mapped_column(ForeignKey("raw_file.id"))
    found: Mapped[bool] = mapped_column()
    start_s: Mapped[float | None] = mapped_column(Float, nullable=True)
    end_s: Mapped[float | None] = mapped_column(Float, nullable=True)
    method: Mapped[str] = mapped_column(String(200))
    parameters: Mapped[dict] = mapped_column(JSON)
    diagnostics: Mapped[dict] = mapped_column(JSON)
    reason: Mapped[str | None] = mapped_column(String(1000), nullable=True)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    processing: Mapped[ProcessingRecord] = relationship()


class RunResult(Base):
    """Results of one raw-file version under one set of processing parameters.

    ``params_sha256`` hashes the processing parameters and swtlab version: the same
    file processed the same way is stored once; other parameters add a row.
    """

    __tablename__ = "run_result"
    __table_args__ = (UniqueConstraint("raw_file_id", "params_sha256"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    raw_file_id: Mapped[int] = mapped_column(ForeignKey("raw_file.id"))
    stable_window_id: Mapped[int] = mapped_column(ForeignKey("stable_window.id"))
    params_sha256: Mapped[str] = mapped_column(String(64))
    status: Mapped[str] = mapped_column(String(20))
    flags: Mapped[list] = mapped_column(JSON)
    oscillation: Mapped[dict] = mapped_column(JSON)
    corrections: Mapped[dict] = mapped_column(JSON)
    dp_trace: Mapped[dict | None] = mapped_column(JSON, nullable=True)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    raw_file: Mapped[RawFile] = relationship()
    window: Mapped[StableWindow] = relationship()
    processing: Mapped[ProcessingRecord] = relationship()
    quantities: Mapped[list[RunQuantity]] = relationship(back_populates="result",
                                                         order_by="RunQuantity.id")
    traces: Mapped[list[RunTrace]] = relationship(back_populates="result",
                                                  order_by="RunTrace.id")


class RunQuantity(Base):
    """One quantity of a run result: mean, standard deviation, autocorrelation-corrected SE."""

    __tablename__ = "run_quantity"
    __table_args__ = (UniqueConstraint("run_result_id", "quantity"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    run_result_id: Mapped[int] = mapped_column(ForeignKey("run_result.id"))
    quantity: Mapped[str] = mapped_column(String(60))
    unit: Mapped[str] = mapped_column(String(20))
    mean: Mapped[float | None] = mapped_column(Float, nullable=True)
    std: Mapped[float | None] = mapped_column(Float, nullable=True)
    se: Mapped[float | None] = mapped_column(Float, nullable=True)
    n: Mapped[int] = mapped_column(Integer)
    n_eff: Mapped[float | None] = mapped_column(Float, nullable=True)

    result: Mapped[RunResult] = relationship(back_populates="quantities")


class RunTrace(Base):
    """One quantity of a run result against time, decimated for plots (``run_results.traces``;
    ``channel``: the quantity, e.g. ``dp_n``): ``samples`` raw samples, ``block`` samples per
    min/max pair (1: kept whole), ``points`` stored; ``arrays`` is a compressed npz of ``t_s``
    (float64, s) and ``values`` (float32, in ``unit``)."""

    __tablename__ = "run_trace"
    __table_args__ = (UniqueConstraint("run_result_id", "channel"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    run_result_id: Mapped[int] = mapped_column(ForeignKey("run_result.id"))
    channel: Mapped[str] = mapped_column(String(60))
    unit: Mapped[str] = mapped_column(String(20))
    samples: Mapped[int] = mapped_column(Integer)
    block: Mapped[int] = mapped_column(Integer)
    points: Mapped[int] = mapped_column(Integer)
    arrays: Mapped[bytes] = mapped_column(LargeBinary)

    result: Mapped[RunResult] = relationship(back_populates="traces")


class CurveFit(Base):
    """A fitted performance curve of one (wheel, soil, multipass, load) group and quantity.

    ``fit_sha256`` hashes the fitted inputs, the fit options and the swtlab version: the
    same fit is stored once and reused by every export that holds it.
    """

    __tablename__ = "curve_fit"
    id: Mapped[int] = mapped_column(primary_key=True)
    fit_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    wheel: Mapped[str] = mapped_column(String(NAME_CHARS))
    soil: Mapped[str] = mapped_column(String(NAME_CHARS))
    multipass: Mapped[int] = mapped_column(Integer)
    load_n: Mapped[float] = mapped_column(Float)
    quantity: Mapped[str] = mapped_column(String(40))
    unit: Mapped[str] = mapped_column(String(20))
    degree: Mapped[int] = mapped_column(Integer)
    coefficients: Mapped[list] = mapped_column(JSON)
    slip_min: Mapped[float] = mapped_column(Float)
    slip_max: Mapped[float] = mapped_column(Float)
    n_points: Mapped[int] = mapped_column(Integer)
    rmse: Mapped[float] = mapped_column(Float)
    diagnostics: Mapped[dict] = mapped_column(JSON)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    processing: Mapped[ProcessingRecord] = relationship()
    inputs: Mapped[list[RunResult]] = relationship(secondary="curve_fit_input")


class CurveFitInput(Base):
    """Which run results a curve was fitted from."""

    __tablename__ = "curve_fit_input"
    curve_fit_id: Mapped[int] = mapped_column(ForeignKey("curve_fit.id"), primary_key=True)
    run_result_id: Mapped[int] = mapped_column(ForeignKey("run_result.id"), primary_key=True)


class WpmExport(Base):
    """One WPM CSV written: where, its sha256, the sha256 of its fitted inputs, its curves."""

    __tablename__ = "wpm_export"
    id: Mapped[int] = mapped_column(primary_key=True)
    path: Mapped[str] = mapped_column(String(PATH_CHARS))
    file_sha256: Mapped[str] = mapped_column(String(64))
    inputs_sha256: Mapped[str] = mapped_column(String(64))
    format_version: Mapped[str] = mapped_column(String(40))
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    processing: Mapped[ProcessingRecord] = relationship()
    fits: Mapped[list[CurveFit]] = relationship(secondary="wpm_export_fit")


class WpmExportFit(Base):
    __tablename__ = "wpm_export_fit"
    wpm_export_id: Mapped[int] = mapped_column(ForeignKey("wpm_export.id"), primary_key=True)
    curve_fit_id: Mapped[int] = mapped_column(ForeignKey("curve_fit.id"), primary_key=True)


class GapReport(Base):
    """A sim-to-real gap diagnosis of this database's results against a simulation
    (the JSON of docs/gap-report.md, with the verdict apart for queries)."""

    __tablename__ = "gap_report"
    id: Mapped[int] = mapped_column(primary_key=True)
    sim_source: Mapped[str] = mapped_column(String(PATH_CHARS))
    verdict: Mapped[list | str] = mapped_column(JSON)
    report: Mapped[dict] = mapped_column(JSON)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    processing: Mapped[ProcessingRecord] = relationship()


class SoilFlow(Base):
    """Soil velocity field under the wheel from one raw-file version's side-camera frames in its
    stable window (``softflow``, docs/softflow.md), once per processing parameters.

    Frames ``frame_first..frame_last`` (inclusive, in time order) at ``t_first_s..t_last_s``;
    velocities in the bin frame; the wheel as seen in the first frame (pixels). ``result`` is
    ``FlowResult.to_dict()`` (schema ``swtlab.softflow/1``); ``field_npz`` the compact arrays the
    report draws from (``softflow.flow_archive``).
    """

    __tablename__ = "soil_flow"
    __table_args__ = (UniqueConstraint("raw_file_id", "params_sha256"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    raw_file_id: Mapped[int] = mapped_column(ForeignKey("raw_file.id"))
    stable_window_id: Mapped[int] = mapped_column(ForeignKey("stable_window.id"))
    params_sha256: Mapped[str] = mapped_column(String(64))
    frame_first: Mapped[int] = mapped_column(Integer)
    frame_last: Mapped[int] = mapped_column(Integer)
    t_first_s: Mapped[float] = mapped_column(Float)
    t_last_s: Mapped[float] = mapped_column(Float)
    pairs: Mapped[int] = mapped_column(Integer)
    engine: Mapped[str] = mapped_column(String(40))
    px_per_m: Mapped[float] = mapped_column(Float)
    sled_velocity_x_mps: Mapped[float] = mapped_column(Float)  # image x (right)
    sled_velocity_y_mps: Mapped[float] = mapped_column(Float)  # image y (down)
    outlier_fraction: Mapped[float] = mapped_column(Float)
    wheel_center_x_px: Mapped[float] = mapped_column(Float)
    wheel_center_y_px: Mapped[float] = mapped_column(Float)
    wheel_radius_px: Mapped[float] = mapped_column(Float)
    grouser_model: Mapped[str | None] = mapped_column(String(40), nullable=True)
    grouser_margin_percent: Mapped[float | None] = mapped_column(Float, nullable=True)
    grouser_gamma: Mapped[float | None] = mapped_column(Float, nullable=True)
    alpha1_per_m: Mapped[float | None] = mapped_column(Float, nullable=True)
    alpha2: Mapped[float | None] = mapped_column(Float, nullable=True)
    #: why alpha1 and alpha2 are blank (e.g. eps_vol^P not resolvable to 0.01); None: given
    alpha12_problem: Mapped[str | None] = mapped_column(String(MESSAGE_CHARS), nullable=True)
    result: Mapped[dict] = mapped_column(JSON)
    field_npz: Mapped[bytes] = mapped_column(LargeBinary)
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    raw_file: Mapped[RawFile] = relationship()
    window: Mapped[StableWindow] = relationship()
    processing: Mapped[ProcessingRecord] = relationship()
    fits: Mapped[list[SoilFlowFit]] = relationship(back_populates="flow",
                                                   order_by="SoilFlowFit.id")


class SoilFlowFit(Base):
    """One decay fit ``A exp(-rate (r - R))`` of a soil flow at one angle ``beta``: component
    ``k`` (radial) or ``alpha3`` (tangential), with its 95 % confidence interval."""

    __tablename__ = "soil_flow_fit"
    __table_args__ = (UniqueConstraint("soil_flow_id", "beta_deg", "component"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    soil_flow_id: Mapped[int] = mapped_column(ForeignKey("soil_flow.id"))
    beta_deg: Mapped[float] = mapped_column(Float)
    component: Mapped[str] = mapped_column(String(10))
    amplitude_mps: Mapped[float] = mapped_column(Float)
    rate_per_m: Mapped[float] = mapped_column(Float)
    ci95_low_per_m: Mapped[float | None] = mapped_column(Float, nullable=True)
    ci95_high_per_m: Mapped[float | None] = mapped_column(Float, nullable=True)
    r2: Mapped[float | None] = mapped_column(Float, nullable=True)
    points: Mapped[int] = mapped_column(Integer)

    flow: Mapped[SoilFlow] = relationship(back_populates="fits")


class SoilFlowFailure(Base):
    """Side-camera frames of a raw-file version that could not be analysed, and why."""

    __tablename__ = "soil_flow_failure"
    __table_args__ = (UniqueConstraint("raw_file_id", "params_sha256"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    raw_file_id: Mapped[int] = mapped_column(ForeignKey("raw_file.id"))
    params_sha256: Mapped[str] = mapped_column(String(64))
    channel: Mapped[str] = mapped_column(String(NAME_CHARS))
    problem: Mapped[str] = mapped_column(String(MESSAGE_CHARS))
    processing_id: Mapped[int] = mapped_column(ForeignKey("processing_record.id"))

    raw_file: Mapped[RawFile] = relationship()
    processing: Mapped[ProcessingRecord] = relationship()


class RunUncertainty(Base):
    """The uncertainty budget of one quantity of a run result
    (``run_results.uncertainty_budget``): the correction added to the window mean, each
    term's standard uncertainty (NULL: not in the budget), combined ``u``, effective degrees
    of freedom (NULL: infinite), coverage factor ``k``, ``u95 = k u`` and what was not measured."""

    __tablename__ = "run_uncertainty"
    __table_args__ = (UniqueConstraint("run_result_id", "quantity"),)
    id: Mapped[int] = mapped_column(primary_key=True)
    run_result_id: Mapped[int] = mapped_column(ForeignKey("run_result.id"))
    quantity: Mapped[str] = mapped_column(String(60))
    unit: Mapped[str] = mapped_column(String(20))
    correction: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_statistical: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_zero_drift: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_calibration: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_quantisation: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_phase_sampling: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_clock: Mapped[float | None] = mapped_column(Float, nullable=True)
    u_timing: Mapped[float | None] = mapped_column(Float, nullable=True)
    u: Mapped[float | None] = mapped_column(Float, nullable=True)
    dof: Mapped[float | None] = mapped_column(Float, nullable=True)
    k: Mapped[float | None] = mapped_column(Float, nullable=True)
    u95: Mapped[float | None] = mapped_column(Float, nullable=True)
    not_measured: Mapped[list] = mapped_column(JSON)
