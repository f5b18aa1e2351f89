"""The sample campaign's results, WPM CSV and gap JSON are those stored under
``tests/reference/sample_campaign/`` (issue 39, item 7): a restructuring changes no number.

A commit that means to change a number regenerates the reference in the same commit, from
the repository root::

    python -m tests.reference.regenerate            # results.csv, wpm.csv, gap.json
    python -m tests.reference.regenerate gap.json   # only the gap report

(what is normalised away, the tolerance of the comparison and the one instruction set both
run on: ``tests/reference/regenerate.py``).
"""

from __future__ import annotations

import json

import pytest

from tests.reference.regenerate import NAMES, REFERENCE, differences


@pytest.fixture(scope="module")
def now(sample_reference_run) -> dict[str, str]:
    return json.loads((sample_reference_run / "outputs.json").read_text())


@pytest.mark.slow  # the sample campaign (60 runs) processed, exported and diagnosed
@pytest.mark.parametrize("name", NAMES)
def test_the_sample_campaign_gives_the_stored_reference(now, name):
    reference = (REFERENCE / name).read_text()
    found = differences(name, reference, now[name])
    assert not found, (f"{len(found)} difference(s) from {REFERENCE / name} (if meant: "
                       f"python -m tests.reference.regenerate {name}):\n" + "\n".join(found[:20]))


def test_the_comparison_sees_a_number_moved_by_1e_8():
    reference = (REFERENCE / "wpm.csv").read_text()
    rows = reference.splitlines(keepends=True)
    header = next(i for i, row in enumerate(rows) if row.startswith("soil,"))
    a0 = rows[header].split(",").index("a0")
    cells = rows[header + 1].split(",")
    cells[a0] = repr(float(cells[a0]) * (1 + 1e-8))
    rows[header + 1] = ",".join(cells)
    found = differences("wpm.csv", reference, "".join(rows))
    assert len(found) == 1 and found[0].startswith(f"wpm.csv line {header + 2}, a0: ")
