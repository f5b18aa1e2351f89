"""Output files are written whole or not at all (issue 17, item 6; ``swtlab_base.atomic``): a writer
killed mid-write or failing before the rename leaves the old file, and the database records an
export's sha256 only once the file is in place."""

from __future__ import annotations

import hashlib
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from sqlalchemy import func, select

import swtlab_base.atomic
from swtlab_base.atomic import atomic_file, write_atomically
from swtlab_cli import exit_codes
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import WpmExport

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_data" / "campaign"
OLD = b"time_s,dp_n\n0,1\n"

#: a child that writes 1 MiB blocks slowly through atomic_file, saying when 8 MiB are written
SLOW_WRITER = """
import sys, time
from swtlab_base.atomic import atomic_file
with atomic_file(sys.argv[1], "wb") as stream:
    for i in range(100_000):
        stream.write(b"n" * (1 << 20))
        stream.flush()
        if i == 7:
            print("written 8 MiB", flush=True)
        time.sleep(0.01)
"""


def _no_rename(*args):
    raise OSError(28, "No space left on device")


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_sigkill_mid_write_leaves_the_old_file(tmp_path):
    target = tmp_path / "wpm.csv"
    target.write_bytes(OLD)
    child = subprocess.Popen([sys.executable, "-c", SLOW_WRITER, str(target)], cwd=ROOT,
                             stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline() == "written 8 MiB\n"
    child.send_signal(signal.SIGKILL)
    child.wait(timeout=30)
    assert child.returncode == -signal.SIGKILL
    assert target.read_bytes() == OLD
    (partial,) = _leftovers(tmp_path)  # the kill came mid-write: the part is beside, unnamed
    assert (tmp_path / partial).stat().st_size >= 8 << 20


@pytest.mark.parametrize("writer", ["bytes", "text stream"])
def test_failure_between_write_and_rename_keeps_the_old_file(tmp_path, monkeypatch, writer):
    target = tmp_path / "out.csv"
    target.write_bytes(OLD)

    monkeypatch.setattr(swtlab_base.atomic.os, "replace", _no_rename)
    with pytest.raises(OSError, match="No space"):
        if writer == "bytes":
            write_atomically(target, b"new content\n" * 1000)
        else:
            with atomic_file(target, newline="") as stream:
                stream.write("new content\n" * 1000)
    assert target.read_bytes() == OLD and _leftovers(tmp_path) == []


def test_new_file_replaces_old_with_ordinary_permissions(tmp_path):
    target = tmp_path / "deep" / "page.html"
    write_atomically(target, "<p>é</p>")
    write_atomically(target, "<p>new</p>")
    assert target.read_text(encoding="utf-8") == "<p>new</p>" and _leftovers(target.parent) == []
    assert target.stat().st_mode & 0o777 == 0o666 & ~_umask()


def _umask() -> int:
    import os

    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_export_hash_is_recorded_only_after_the_rename(tmp_path, monkeypatch, capsys):
    campaign = tmp_path / "campaign"
    campaign.mkdir()
    for path in sorted(SAMPLE.glob("L300_MP0_SC_*.mcap")):
        shutil.copy(path, campaign / path.name)
    db = f"sqlite:///{tmp_path / 'swtlab.sqlite'}"
    assert main(["process", str(campaign), "--db", db, "--quiet"]) == 0
    wpm = tmp_path / "wpm.csv"
    assert main(["export", "--db", db, "-o", str(wpm), "--degree", "3"]) == 0
    first = wpm.read_bytes()

    with open_database(db, read_only=True)() as session:
        recorded = session.scalars(select(WpmExport.file_sha256)).all()
    assert recorded == [hashlib.sha256(first).hexdigest()]
    monkeypatch.setattr(swtlab_base.atomic.os, "replace", _no_rename)
    capsys.readouterr()
    assert main(["export", "--db", db, "-o", str(wpm), "--degree", "4"]) == exit_codes.BAD_INPUT
    assert "cannot write" in capsys.readouterr().err
    assert wpm.read_bytes() == first and _leftovers(tmp_path) == []
    with open_database(db, read_only=True)() as session:
        assert session.scalar(select(func.count()).select_from(WpmExport)) == 1
