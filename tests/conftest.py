"""Shared test fixtures. Ingest fixtures are prefixed ``ingest_`` and build small spec-form runs
(MCAP written with ``mcap.writer.Writer``, json encoding, jsonschema schemas; CSV run folders)
whose true SI values are known."""

from __future__ import annotations

import base64
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from swtlab_base.cores import threads_per_worker


def pytest_configure(config) -> None:
    """Each pytest-xdist worker (``make test``: one per core) runs numba and BLAS (OpenCV's
    and scipy's too) on its share of the cores, as a ``swtlab process --jobs`` worker does:
    two workers of two BLAS threads each on two cores wait for each other's threads
    (softflow.threads; 62 track photos measured on a busy 2-core machine: 81 s, 41 s on one
    thread). OpenCV's own threads are left as they are: tests/test_process_parallel.py forks
    workers after this process used OpenCV's thread pool. The results do not depend on the
    thread count (tests/test_softflow_threads.py sets its own; those 62 results were
    equal)."""
    workers = os.environ.get("PYTEST_XDIST_WORKER_COUNT")
    if workers and os.environ.get("PYTEST_XDIST_WORKER"):
        import scipy.linalg  # noqa: F401  (its BLAS, loaded now, is limited too)

        from softflow.threads import limit

        limit(threads_per_worker(int(workers)), opencv=False)

#: true signals of the synthetic spec run (SI units, after calibration and zeroing)
INGEST_TRUTH = {
    "duration_s": 6.0,
    "omega_radps": 2.0,          # wheel angular velocity
    "radius_m": 0.1,
    "sled_velocity_mps": 0.15,   # driving slip = (0.2 - 0.15)/0.2 = 0.25
    "slip": 0.25,
    "arm_length_m": 0.8,
    "angle_zero_rad": 0.1,
    "suspension_angle_rad": 0.08,
    "encoder_step_rad": 2 * np.pi / 4096,
    "sled_step_m": 1e-5,
    "fz_n": 150.0,
}

INGEST_RATES_HZ = {"/hub/wrench": 1000.0, "/tether/force": 500.0, "/wheel/encoder": 200.0,
                   "/sled/encoder": 100.0, "/tether/encoder": 100.0, "/suspension/angle": 50.0}


def _times_ns(rate_hz: float, duration_s: float, rng: np.random.Generator) -> np.ndarray:
    """Uneven sample times: nominal rate with 10 % jitter, strictly increasing."""
    n = int(duration_s * rate_hz)
    dt = 1.0 / rate_hz
    t = np.arange(n) * dt + rng.uniform(-0.1, 0.1, n) * dt
    t[0] = 0.0
    return np.round(t * 1e9).astype(np.int64)


def ingest_truth_topics(seed: int = 0) -> dict[str, dict[str, np.ndarray]]:
    """Spec topics with ``t_ns`` and SI field values (the truth ingest must give back)."""
    rng = np.random.default_rng(seed)
    d = INGEST_TRUTH
    out = {}
    for topic, rate in INGEST_RATES_HZ.items():
        t_ns = _times_ns(rate, d["duration_s"], rng)
        t = t_ns * 1e-9
        if topic == "/hub/wrench":
            fields = {"fx": 10 + np.sin(t), "fy": 0.5 * np.cos(t), "fz": d["fz_n"] + 0 * t,
                      "tx": 0.1 * t, "ty": 4 + 0.2 * np.sin(3 * t), "tz": -0.05 + 0 * t}
        elif topic == "/tether/force":
            fields = {"dp": 20 + 2 * np.sin(2 * t)}
        elif topic == "/wheel/encoder":
            step = d["encoder_step_rad"]
            fields = {"angle": np.floor(d["omega_radps"] * t / step) * step}
        elif topic in ("/sled/encoder", "/tether/encoder"):
            step = d["sled_step_m"]
            fields = {"position": np.floor(d["sled_velocity_mps"] * t / step) * step}
        else:
            fields = {"angle": d["suspension_angle_rad"] + 0 * t}
        out[topic] = {"t_ns": t_ns, **fields}
    return out


def ingest_records(**changes: dict[str, str | None]) -> dict[str, dict[str, str]]:
    """Spec metadata records (strings, as in MCAP); ``changes={'run': {'mode': 'towed'}}``,
    a value of None removes the key."""
    d = INGEST_TRUTH
    records = {
        "run": {"run_id": "r001", "campaign": "c1", "wheel": "w1", "soil": "ES-3",
                "multipass": "0", "mode": "speed_control", "load_N": "150",
                "slip_setpoint": "0.25", "velocity_mps": "0.15", "gravity_mps2": "9.80665",
                "started_at": "2026-11-20T10:00:00+00:00"},
        "wheel": {"radius_m": str(d["radius_m"]), "width_m": "0.12", "grouser_count": "12",
                  "grouser_height_m": "0.01"},
        "suspension": {"arm_length_m": str(d["arm_length_m"]),
                       "angle_zero_rad": str(d["angle_zero_rad"])},
    }
    for name, values in changes.items():
        record = records.setdefault(name, {})
        for key, value in values.items():
            if value is None:
                record.pop(key, None)
            else:
                record[key] = value
    return records


def ingest_block_sizes(n: int, rng: np.random.Generator) -> list[int]:
    """Uneven block sizes 1..40 covering n samples (blocks of one sample included)."""
    sizes = []
    while sum(sizes) < n:
        sizes.append(int(rng.choice([1, 1, 3, 17, 40])))
    sizes[-1] -= sum(sizes) - n
    return [s for s in sizes if s > 0]


@dataclass
class IngestMcapSpec:
    """Everything a test may change before writing an MCAP run."""

    topics: dict[str, dict[str, np.ndarray]]
    records: dict[str, dict[str, str]]
    extra_blocks: list[tuple[str, bytes]] = field(default_factory=list)
    frames: dict[str, list[int]] = field(default_factory=dict)  # topic -> t_ns of frames


def ingest_write_mcap(path: Path, spec: IngestMcapSpec, seed: int = 0, **writer_options) -> Path:
    """Write a spec-form MCAP: JSON blocks of uneven size, jsonschema schemas, swt.* metadata.

    ``writer_options`` go to ``mcap.writer.Writer`` (compression, chunking, ...)."""
    from mcap.writer import Writer

    rng = np.random.default_rng(seed)
    messages = []  # (log_time, channel_key, bytes)
    with open(path, "wb") as stream:
        writer = Writer(stream, **{"chunk_size": 32 * 1024, **writer_options})
        writer.start(profile="", library="swtlab-tests")
        channels = {}
        for topic, fields in spec.topics.items():
            schema = {"type": "object", "properties": {k: {"type": "array"} for k in fields}}
            sid = writer.register_schema(name=f"swt{topic.replace('/', '.')}",
                                         encoding="jsonschema", data=json.dumps(schema).encode())
            channels[topic] = writer.register_channel(topic=topic, message_encoding="json",
                                                      schema_id=sid)
            n = len(fields["t_ns"])
            start = 0
            for size in ingest_block_sizes(n, rng):
                block = {k: v[start:start + size].tolist() for k, v in fields.items()}
                messages.append((int(fields["t_ns"][start]), topic, json.dumps(block).encode()))
                start += size
        for topic, data in spec.extra_blocks:
            if topic not in channels:
                sid = writer.register_schema(name="x", encoding="jsonschema", data=b"{}")
                channels[topic] = writer.register_channel(topic=topic, message_encoding="json",
                                                          schema_id=sid)
            messages.append((0, topic, data))
        if spec.frames:
            sid = writer.register_schema(name="foxglove.CompressedImage", encoding="jsonschema",
                                         data=b"{}")
            for topic, stamps in spec.frames.items():
                channels[topic] = writer.register_channel(topic=topic, message_encoding="json",
                                                          schema_id=sid)
                for i, t_ns in enumerate(stamps):
                    msg = {"timestamp": {"sec": int(t_ns // 10**9), "nsec": int(t_ns % 10**9)},
                           "frame_id": "side", "format": "png",
                           "data": base64.b64encode(b"frame-%d" % i).decode()}
                    messages.append((int(t_ns), topic, json.dumps(msg).encode()))
        for log_time, topic, data in sorted(messages, key=lambda m: m[0]):
            writer.add_message(channel_id=channels[topic], log_time=log_time, data=data,
                               publish_time=log_time)
        for name, values in spec.records.items():
            writer.add_metadata(name=f"swt.{name}", data={k: str(v) for k, v in values.items()})
        writer.finish()
    return path


def ingest_write_csv_run(folder: Path, topics: dict[str, dict[str, np.ndarray]],
                         records: dict[str, dict[str, str]]) -> Path:
    """Write the CSV form: run.json (numbers as JSON numbers) + <topic>.csv with t_s first."""
    import pandas as pd

    folder.mkdir(parents=True, exist_ok=True)

    def number(value: str):
        try:
            return float(value) if any(c in value for c in ".eE") else int(value)
        except ValueError:
            return value

    meta = {name: {k: number(v) for k, v in values.items()} for name, values in records.items()}
    (folder / "run.json").write_text(json.dumps(meta, indent=1))
    for topic, fields in topics.items():
        table = {"t_s": fields["t_ns"] * 1e-9}
        table.update({k: v for k, v in fields.items() if k != "t_ns"})
        pd.DataFrame(table).to_csv(folder / (topic.strip("/").replace("/", "_") + ".csv"),
                                   index=False, float_format="%.17g")
    return folder


@pytest.fixture
def ingest_spec() -> IngestMcapSpec:
    """A fresh, good spec run description (truth topics + records) to modify in a test."""
    return IngestMcapSpec(topics=ingest_truth_topics(), records=ingest_records())


@pytest.fixture
def ingest_good_mcap(tmp_path: Path, ingest_spec: IngestMcapSpec) -> Path:
    """A good spec-form MCAP run in tmp_path."""
    return ingest_write_mcap(tmp_path / "good.mcap", ingest_spec)


@pytest.fixture(scope="session")
def ingest_cmu_root() -> Path:
    """The real CMU 3d-terramechanics data (skips when the shared folder is absent)."""
    root = Path(__file__).resolve().parents[2] / "shared" / "data" / "cmu-3d-terramechanics"
    if not root.is_dir():
        root = Path("/work/shared/data/cmu-3d-terramechanics")
    if not root.is_dir():
        pytest.skip("CMU data not available")
    return root


@pytest.fixture
def ingest_tools():
    """The ingest fixture helpers (writers, truth, records) in one namespace."""
    from types import SimpleNamespace

    return SimpleNamespace(truth=INGEST_TRUTH, rates=INGEST_RATES_HZ,
                           truth_topics=ingest_truth_topics, records=ingest_records,
                           Spec=IngestMcapSpec, write_mcap=ingest_write_mcap,
                           write_csv_run=ingest_write_csv_run)


# --- databases: every database test runs on SQLite, and on PostgreSQL where .ci/run started one


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    """A fresh, empty database URL: a SQLite file, or a new PostgreSQL database (dropped after)."""
    if request.param == "sqlite":
        yield f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
        return
    import os
    import uuid

    from sqlalchemy import create_engine, text
    from sqlalchemy.engine import make_url

    admin_url = os.environ.get("SWTLAB_TEST_POSTGRES_URL")
    if not admin_url:
        pytest.skip("no PostgreSQL server (set SWTLAB_TEST_POSTGRES_URL; .ci/run starts one)")
    name = f"swtlab_test_{uuid.uuid4().hex[:12]}"
    admin = create_engine(admin_url, isolation_level="AUTOCOMMIT")
    with admin.connect() as connection:
        connection.execute(text(f'CREATE DATABASE "{name}"'))
    yield make_url(admin_url).set(database=name).render_as_string(hide_password=False)
    with admin.connect() as connection:
        connection.execute(text(f'DROP DATABASE "{name}" WITH (FORCE)'))
    admin.dispose()


def _once_per_run(tmp_path_factory, name: str, make) -> Path:
    """``name`` in the test run's shared folder, made by ``make(path)`` once per run: the
    pytest-xdist workers of one run share it, the first to need it makes it while the others
    wait on a lock (the folder above a worker's base temporary folder is that run's own).
    What is shared is only read."""
    import fcntl

    base = tmp_path_factory.getbasetemp()
    shared = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    done = shared / name
    with open(shared / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            partial = shared / f"{name}.partial"
            make(partial)
            partial.rename(done)
    return done


@pytest.fixture(scope="session")
def sample_reference_run(tmp_path_factory) -> Path:
    """The committed sample campaign processed once per test run (:func:`_once_per_run`) on
    the reference's pinned instruction set (``tests/reference/regenerate.py``): a folder
    with ``swtlab.sqlite`` (as processed) and ``outputs.json`` (the normalised results, WPM
    CSV and gap JSON the reference is compared with)."""
    from tests.reference.regenerate import pinned_outputs

    def make(path: Path) -> None:
        path.mkdir()
        made = pinned_outputs(keep_db=path / "swtlab.sqlite")
        (path / "outputs.json").write_text(json.dumps(made))

    return _once_per_run(tmp_path_factory, "sample_campaign", make)


@pytest.fixture(scope="session")
def processed_sample_db(sample_reference_run, tmp_path_factory) -> str:
    """The committed sample campaign as processed (URL of a SQLite database); each worker
    gets its own copy of it."""
    from tests.reference.regenerate import sqlite_copy

    mine = tmp_path_factory.mktemp("sample_db") / "swtlab.sqlite"
    sqlite_copy(sample_reference_run / "swtlab.sqlite", mine)
    return f"sqlite:///{mine}"


@pytest.fixture(scope="session")
def varied_campaign(tmp_path_factory) -> Path:
    """The virtual testbed's varied campaign (``varied_conditions``: 56 runs, seed 11, every
    third run CSV, the others MCAP; truths in ``truth/``), generated once per test run
    (:func:`_once_per_run`) for the modules that read it: tests/test_stable_phase_virtual.py,
    tests/test_run_results_virtual.py. Read only."""
    from virtual_testbed import generate_campaign
    from virtual_testbed.sample_campaign import SAMPLE_RATES
    from virtual_testbed.varied_campaign import varied_conditions, varied_forms

    def make(path: Path) -> None:
        conditions = varied_conditions()
        generate_campaign(path, conditions, seed=11, rates=SAMPLE_RATES,
                          form=varied_forms(conditions))

    return _once_per_run(tmp_path_factory, "varied_campaign_11", make)
