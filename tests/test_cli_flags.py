"""Python errors speak Python, the command line speaks flags: an error raised through the API
names keyword arguments (``multipass=0``); each command prints them as its own flags."""

from __future__ import annotations

import argparse

import pytest

from swtlab_cli import cmd_process, cmd_wpm
from swtlab_cli.flags import as_flags


def _args(module, command: str):
    parser = argparse.ArgumentParser(prog="swtlab")
    module.register(parser.add_subparsers())
    return parser.parse_args(command.split())


@pytest.mark.parametrize("text, flags", [
    ("2 curve sets match in x.csv; pick one: soil='ES-3', wheel='w 1', multipass=0; "
     "soil='ES-3', wheel='w 1', multipass=1",
     "2 curve sets match in x.csv; pick one: --soil ES-3 --wheel 'w 1' --multipass 0; "
     "--soil ES-3 --wheel 'w 1' --multipass 1"),
    ("no curves for soil='clay' in x.csv", "no curves for --soil clay in x.csv"),
    ("load_n=70 N and mode='towed' are no keywords of the command",
     "--load 70 N and mode='towed' are no keywords of the command"),
])
def test_wpm_keywords_become_its_flags(text, flags):
    assert as_flags(text, _args(cmd_wpm, "wpm query f.csv --load 1 --dp 2")) == flags


def test_switches_and_hyphens(tmp_path):
    args = _args(cmd_process, f"process {tmp_path} --db x.sqlite")
    assert as_flags("a.mcap claims run_id 'r1'; pass allow_run_id_reuse=True to store it",
                    args) == "a.mcap claims run_id 'r1'; pass --allow-run-id-reuse to store it"
    assert as_flags("allow_run_id_reuse=False", args) == "allow_run_id_reuse=False"
    assert as_flags("e.g. channel_map='cmu_3d_terramechanics'", args) == \
        "e.g. --channel-map cmu_3d_terramechanics"
    assert as_flags("path/x=1 and a.b=2 stay", args) == "path/x=1 and a.b=2 stay"


def test_the_api_names_keywords(tmp_path):
    """Errors raised through the API carry no command-line flag."""
    import ingest
    from softflow.frames import FrameSourceError, load_frames

    text = tmp_path / "log.dat"
    text.write_text("1,2,3\n")
    with pytest.raises(ingest.IngestError) as caught:
        ingest.read_run(text)
    assert "channel_map='cmu_3d_terramechanics'" in caught.value.problem
    assert "--" not in caught.value.problem
    folder = tmp_path / "frames"
    folder.mkdir()
    import cv2
    import numpy as np

    for name in ("a.png", "b.png"):
        cv2.imwrite(str(folder / name), np.zeros((8, 8), np.uint8))
    with pytest.raises(FrameSourceError, match=r"give the frame rate \(fps=FPS\)$"):
        load_frames(folder)
