"""Metadata where labs keep it: a ``<run>.run.json`` sidecar for every layout (delimited text,
MCAP, CSV run folder included), file attributes named ``<record>.<key>`` or
``swt.<record>.<key>`` in HDF5 and TDMS, record structs with or without ``swt`` in MATLAB;
an error names the form the user's file is in.

The files are written by their own libraries (h5py, npTDMS, scipy.io, mcap, pandas) with the
records of a sample-campaign MCAP; the truth is that MCAP's metadata as ingest reads it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import ingest
from bench import format_files as fw

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / "L070_MP0_SC_s+010.mcap"
CMU_MAP = "cmu_3d_terramechanics"


@pytest.fixture(scope="module")
def spec_run() -> fw.SpecRun:
    return fw.read_spec_mcap(SAMPLE)


@pytest.fixture(scope="module")
def reference():
    return ingest.read_run(SAMPLE).metadata


def _flat(records: dict, prefix: str) -> dict:
    return {f"{prefix}{r}.{k}": v for r, rec in records.items() for k, v in rec.items()}


@pytest.mark.parametrize("prefix", ["", "swt."])
def test_hdf5_root_attributes(tmp_path, spec_run, reference, prefix):
    import h5py

    path = tmp_path / "run.h5"
    with h5py.File(path, "w") as f:
        for topic, fields in spec_run.topics.items():
            for k, v in fields.items():
                f.create_dataset(f"{topic}/{k}", data=v)
        f.attrs.update(_flat(spec_run.records, prefix))
    assert ingest.read_run(path).metadata == reference


@pytest.mark.parametrize("prefix", ["", "swt."])
def test_tdms_file_properties(tmp_path, spec_run, reference, prefix):
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    path = tmp_path / "run.tdms"
    objects = [RootObject(properties=_flat(spec_run.records, prefix))]
    for topic, fields in spec_run.topics.items():
        objects += [GroupObject(topic), *(ChannelObject(topic, k, v) for k, v in fields.items())]
    with TdmsWriter(path) as writer:
        writer.write_segment(objects)
    assert ingest.read_run(path).metadata == reference


@pytest.mark.parametrize("inside_swt", [False, True])
def test_matlab_record_structs(tmp_path, spec_run, reference, inside_swt):
    """``run.run_id`` or ``swt.run.run_id``; the calibration record (its keys are no MATLAB
    names) in the sidecar."""
    from scipy.io import savemat

    path = tmp_path / "run.mat"
    records = {k: v for k, v in spec_run.records.items() if k != "calibration"}
    variables = {fw.variable_name(t): {k: v.reshape(1, -1) for k, v in fields.items()}
                 for t, fields in spec_run.topics.items()}
    variables.update({"swt": records} if inside_swt else records)
    savemat(path, variables, format="5")
    (tmp_path / "run.run.json").write_text(json.dumps(
        {"calibration": spec_run.records["calibration"]}))
    assert ingest.read_run(path).metadata == reference


def test_sidecar_for_an_mcap(tmp_path, ingest_tools, ingest_spec):
    wheel = ingest_spec.records.pop("wheel")
    path = ingest_tools.write_mcap(tmp_path / "r7.mcap", ingest_spec)
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(path)
    assert caught.value.problem == ("metadata record missing; give its keys (wheel.<key>) in "
                                    "the MCAP's swt.wheel metadata record, or the sidecar "
                                    "r7.run.json")
    (tmp_path / "r7.run.json").write_text(json.dumps({"wheel": wheel}))
    assert ingest.read_run(path).metadata.wheel.radius_m == float(wheel["radius_m"])


def test_sidecar_beside_a_csv_run_folder(tmp_path, ingest_tools, ingest_spec):
    folder = ingest_tools.write_csv_run(tmp_path / "r8", ingest_spec.topics, ingest_spec.records)
    run_json = json.loads((folder / "run.json").read_text())
    del run_json["wheel"]["width_m"]
    (folder / "run.json").write_text(json.dumps(run_json))
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(folder)
    assert caught.value.channel == "swt.wheel.width_m"
    assert caught.value.problem == ('missing; add wheel.width_m to run.json ("wheel": {...}), '
                                    "or the sidecar r8.run.json")
    (tmp_path / "r8.run.json").write_text('{"wheel": {"width_m": 0.2}}')
    assert ingest.read_run(folder).metadata.wheel.width_m == 0.2


def test_sidecar_for_a_delimited_text_log(tmp_path, ingest_cmu_root):
    """The CMU map's defaults (23 N, radius 0.058 m) give way to the sidecar; values from the
    file name still win over both; find_runs does not take the sidecar for a run."""
    source = ingest_cmu_root / "raw" / "gr810_vx_10" / "12-5-20" / "10_3_0_1.txt"
    log = Path(shutil.copy(source, tmp_path / source.name))
    default = ingest.read_run(log, CMU_MAP).metadata
    assert (default.run.condition.load_set_n, default.wheel.radius_m) == (23.0, 0.058)
    (tmp_path / "10_3_0_1.run.json").write_text(json.dumps(
        {"run": {"load_N": 25.5, "velocity_mps": 0.5}, "wheel": {"radius_m": 0.06}}))
    meta = ingest.read_run(log, CMU_MAP).metadata
    assert (meta.run.condition.load_set_n, meta.wheel.radius_m) == (25.5, 0.06)
    # the file name's, not 0.5
    assert meta.run.condition.velocity_set_mps == default.run.condition.velocity_set_mps
    assert ingest.find_runs(tmp_path, CMU_MAP) == [log]


@pytest.mark.parametrize("writer, name, form", [
    (fw.write_hdf5, "run.h5", "root attributes wheel.<key> or swt.wheel.<key> (or attributes "
                              "of the group /swt/wheel), or the sidecar run.run.json"),
    (fw.write_tdms, "run.tdms", "file properties wheel.<key> or swt.wheel.<key>, or the sidecar "
                    "run.run.json"),
    (fw.write_mat5, "run.mat", "a struct wheel or swt.wheel (one field per key), or the sidecar "
                    "run.run.json"),
    (fw.write_ros1, "run.bag", "the sidecar run.run.json"),
])
def test_a_missing_key_names_the_form_of_the_file(tmp_path, spec_run, writer, name, form):
    records = {**spec_run.records, "wheel": {k: v for k, v in spec_run.records["wheel"].items()
                                             if k != "radius_m"}}
    path = writer(fw.SpecRun(spec_run.topics, records), tmp_path / name)
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(path, "spec_ros" if writer is fw.write_ros1 else None)
    assert caught.value.channel == "swt.wheel.radius_m"
    assert caught.value.problem == f"missing; add wheel.radius_m to {form}"
