"""Every measured figure in docs/validation/ says where it comes from (issue 39 item 5): each
record carries lines ``From release X (note): `python -m MODULE ARGS``` naming a released
version (CHANGELOG.md) and a command that exists; a page a bench writes (``python -m bench
NAME --markdown``) is ``NAME.md`` and carries the line the bench puts under its title. No
bench that writes a page is cheap enough to rerun here (the coverage and calibration runs
take minutes to hours; the WPM pages are rates on the machine they ran on), so the pages are
marked by release instead of compared with a fresh run."""

from __future__ import annotations

import importlib.util
import re
import tomllib
from pathlib import Path

import pytest

from bench.__main__ import page

ROOT = Path(__file__).resolve().parents[1]
RECORDS = sorted((ROOT / "docs" / "validation").glob("*.md"))
PROVENANCE = re.compile(r"^From release (?P<release>\d+\.\d+\.\d+)(?: \((?P<note>[^)]*)\))?: "
                        r"`python -m (?P<module>[\w.]+)(?P<args>[^`]*)`$", re.MULTILINE)
RELEASED = set(re.findall(r"^## (\d+\.\d+\.\d+) — ", (ROOT / "CHANGELOG.md").read_text(),
                          re.MULTILINE))
#: the benches with a page: ``markdown(numbers)`` beside ``main``
PAGE_BENCHES = sorted(p.stem[len("bench_"):] for p in (ROOT / "bench").glob("bench_*.py")
                      if "\ndef markdown(" in p.read_text())


def _problems(path: Path) -> list[str]:
    lines = list(PROVENANCE.finditer(path.read_text()))
    if not lines:
        return ["no line 'From release X: `python -m ...`'"]
    problems = []
    for line in lines:
        args = line["args"].split()
        if line["release"] not in RELEASED:
            problems.append(f"release {line['release']} is not in CHANGELOG.md")
        if line["module"] != "bench":
            if importlib.util.find_spec(line["module"]) is None:
                problems.append(f"no module {line['module']}")
        elif not args or not (ROOT / "bench" / f"bench_{args[0]}.py").is_file():
            problems.append(f"no bench {args[:1]}")
        elif "--markdown" in args and (args[0] not in PAGE_BENCHES
                                       or path.name != f"{args[0]}.md"):
            problems.append(f"python -m bench {args[0]} --markdown does not write {path.name}")
    return problems


@pytest.mark.parametrize("path", RECORDS, ids=[p.name for p in RECORDS])
def test_every_record_names_its_release_and_command(path):
    assert _problems(path) == []


def test_every_bench_page_is_a_record_marked_by_its_command():
    assert PAGE_BENCHES  # coverage, gap_calibration, wpm, wpm_c
    for name in PAGE_BENCHES:
        text = (ROOT / "docs" / "validation" / f"{name}.md").read_text()
        commands = {m["module"] + m["args"] for m in PROVENANCE.finditer(text)}
        assert f"bench {name} --markdown" in commands, name


def test_a_bench_page_carries_the_line_this_test_reads():
    release = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    text = page("coverage", "# Coverage\n\nbody\n")
    line = f"From release {release}: `python -m bench coverage --markdown`"
    assert text == f"# Coverage\n\n{line}\n\nbody\n"
    assert PROVENANCE.search(text)["release"] == release


def test_a_record_without_its_release_or_with_a_wrong_command_is_named(tmp_path):
    bad = {"none.md": "# x\n\nsome figures\n",
           "unreleased.md": "# x\n\nFrom release 9.9.9: `python -m bench coverage`\n",
           "wpm.md": "# x\n\nFrom release 0.15.0: `python -m bench coverage --markdown`\n",
           "gone.md": "# x\n\nFrom release 0.15.0: `python -m testbeds.nowhere DIR`\n"}
    found = {}
    for name, text in bad.items():
        (tmp_path / name).write_text(text)
        found[name] = _problems(tmp_path / name)
    assert found == {
        "none.md": ["no line 'From release X: `python -m ...`'"],
        "unreleased.md": ["release 9.9.9 is not in CHANGELOG.md"],
        "wpm.md": ["python -m bench coverage --markdown does not write wpm.md"],
        "gone.md": ["no module testbeds.nowhere"]}


def test_a_bench_on_the_pinned_instruction_set_runs_in_a_child_on_it():
    """A bench whose module asks for the pinned instruction set runs as ``python -m bench NAME
    [options]`` with bench/pinned_isa.py's environment, once: not again from inside the
    child, and not for a bench that does not ask."""
    import platform
    import types

    from bench.__main__ import pinned_child
    from bench.pinned_isa import MARKER, PINNED_ISA

    asks, plain = types.SimpleNamespace(ON_PINNED_ISA=True), types.SimpleNamespace()
    command, env = pinned_child("gap_calibration", asks, ["--markdown"], {"HOME": "/h"})
    assert command[1:] == ["-m", "bench", "gap_calibration", "--markdown"]
    x86 = platform.machine() in ("x86_64", "AMD64")
    assert env == {"HOME": "/h", MARKER: "1", **(PINNED_ISA if x86 else {})}
    assert pinned_child("gap_calibration", asks, [], env) is None
    assert pinned_child("wpm", plain, [], {"HOME": "/h"}) is None
    for name in ("gap_calibration", "gap_real", "gap_blind"):
        module = importlib.import_module(f"bench.bench_{name}")
        assert module.ON_PINNED_ISA is True
