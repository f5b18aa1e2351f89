"""``swtlab process`` names the SQLite file it wrote, resolved, and says when the URL gave a
path relative to the working directory (``sqlite:///tmp/x/lab.sqlite`` is ./tmp/x/...)."""

from __future__ import annotations

from pathlib import Path

from swtlab_cli.main import main

SAMPLE_RUN = Path(__file__).resolve().parents[1] / "sample_data" / "campaign" / \
    "L070_MP0_SC_s+010.mcap"


def _last_line(capsys) -> str:
    return capsys.readouterr().out.strip().splitlines()[-1]


def test_process_names_the_file_a_sqlite_url_resolves_to(tmp_path, capsys, monkeypatch):
    campaign = tmp_path / "c"
    campaign.mkdir()
    (campaign / SAMPLE_RUN.name).write_bytes(SAMPLE_RUN.read_bytes())
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["process", str(campaign), "--db", "sqlite:///tmp/x/lab.sqlite", "--quiet",
                 "--jobs", "1"]) == 0
    written = work / "tmp" / "x" / "lab.sqlite"
    assert written.is_file()
    assert _last_line(capsys) == (
        f"database: sqlite:///tmp/x/lab.sqlite = {written} (sqlite:/// and a relative path: "
        "from the working directory; an absolute path takes four slashes: "
        "sqlite:////tmp/x/lab.sqlite)  (list the results: swtlab results --db "
        "sqlite:///tmp/x/lab.sqlite)")
    absolute = tmp_path / "abs" / "lab.sqlite"
    assert main(["process", str(campaign), "--db", f"sqlite:///{absolute}", "--quiet",
                 "--jobs", "1"]) == 0
    assert absolute.is_file()
    assert _last_line(capsys).startswith(f"database: sqlite:///{absolute} = {absolute}  (list")
