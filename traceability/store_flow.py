"""Persist soil flows measured from side-camera frames (docs/softflow.md), and the runs whose
frames could not be analysed; once per (raw-file version, processing parameters), like run
results, whose stable window they were measured in."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from swtlab_base.plain_json import jsonable
from traceability.models import RawFile, SoilFlow, SoilFlowFailure, SoilFlowFit, StableWindow
from traceability.store import new_processing_record
from traceability.store_results import params_sha256

COMPONENTS = ("k", "alpha3")


def _fits(per_beta: list[dict]) -> list[SoilFlowFit]:
    return [SoilFlowFit(beta_deg=row["beta_deg"], component=c,
                        amplitude_mps=fit["amplitude_mps"], rate_per_m=fit["rate_per_m"],
                        ci95_low_per_m=fit["ci95_per_m"][0], ci95_high_per_m=fit["ci95_per_m"][1],
                        r2=fit["r2"], points=fit["points"])
            for row in per_beta for c in COMPONENTS if (fit := row[c]) is not None]


def store_flow(session: Session, raw_file: RawFile, window: StableWindow, result: Any,
               field_npz: bytes, parameters: dict[str, Any]) -> SoilFlow:
    """Store ``result`` (a ``softflow.FlowResult``) measured in ``window``, with its compact
    arrays ``field_npz`` (``softflow.flow_archive.pack_flow``)."""
    data = jsonable(result.to_dict())
    pose = result.poses[0]
    grouser = data["grouser_model"] or {}
    alpha12 = data["alpha1_alpha2"] or {}
    row = SoilFlow(
        raw_file=raw_file, window=window, params_sha256=params_sha256(parameters),
        frame_first=result.frame_range[0], frame_last=result.frame_range[1] - 1,
        t_first_s=float(result.t_s[0]), t_last_s=float(result.t_s[-1]), pairs=data["pairs"],
        engine=result.engine, px_per_m=result.px_per_m,
        sled_velocity_x_mps=data["sled_velocity_mps"][0],
        sled_velocity_y_mps=data["sled_velocity_mps"][1],
        outlier_fraction=data["outlier_fraction"], wheel_center_x_px=float(pose.center_px[0]),
        wheel_center_y_px=float(pose.center_px[1]), wheel_radius_px=float(pose.radius_px),
        grouser_model=grouser.get("chosen"), grouser_margin_percent=grouser.get("margin_percent"),
        grouser_gamma=grouser.get("gamma"), alpha1_per_m=alpha12.get("alpha1_per_m"),
        alpha2=alpha12.get("alpha2"), alpha12_problem=data["alpha1_alpha2_reason"], result=data,
        field_npz=field_npz,
        processing=new_processing_record(session, "flow", parameters),
        fits=_fits(data["per_beta"]))
    session.add(row)
    session.flush()
    return row


def store_flow_failure(session: Session, raw_file: RawFile, channel: str, problem: str,
                       parameters: dict[str, Any]) -> SoilFlowFailure:
    """Record why the frames of ``raw_file`` could not be analysed."""
    row = SoilFlowFailure(raw_file=raw_file, params_sha256=params_sha256(parameters),
                          channel=channel, problem=problem,
                          processing=new_processing_record(session, "flow", parameters))
    session.add(row)
    session.flush()
    return row


def stored_flow_failure(session: Session, path: Path, sha256: str,
                        params_hash: str) -> SoilFlowFailure | None:
    """The failure recorded for this exact file content at this path and these parameters."""
    return session.scalars(
        select(SoilFlowFailure).join(RawFile, RawFile.id == SoilFlowFailure.raw_file_id)
        .where(RawFile.path == str(path.resolve()), RawFile.sha256 == sha256,
               SoilFlowFailure.params_sha256 == params_hash)).first()
