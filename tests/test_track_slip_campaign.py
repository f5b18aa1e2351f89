"""Track photos in a campaign: image slip beside encoder slip in the database (issue: the two
agree within 1 %, as the RUAG SWT campaign found)."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from swtlab_cli.main import main
from virtual_testbed.campaign import generate_campaign
from virtual_testbed.conditions import RunCondition
from virtual_testbed.sensors import Rates

RATES = Rates(40.0, 40.0, 20.0, 20.0, 10.0, 10.0)


@pytest.mark.slow  # a five-run campaign with track photos generated, processed and reported
def test_image_slip_beside_encoder_slip(tmp_path, capsys):
    slips = (0.05, 0.2, 0.4, 0.7)
    conditions = [RunCondition.of(f"P{i}", "speed_control", 180.0, 0, s, track_photos=2)
                  for i, s in enumerate(slips)]
    conditions.append(RunCondition.of("NOPHOTO", "speed_control", 180.0, 0, 0.3))
    forms = {c.run_id: ("csv" if c.run_id == "P1" else "mcap") for c in conditions}
    generate_campaign(tmp_path, conditions, seed=21, rates=RATES, form=forms)
    db = f"sqlite:///{tmp_path / 'db.sqlite'}"
    assert main(["process", str(tmp_path / "campaign"), "--db", db, "--quiet"]) == 0
    capsys.readouterr()
    assert main(["results", "--db", db, "--json"]) == 0
    table = pd.DataFrame(json.loads(capsys.readouterr().out)).set_index("run_id")
    assert pd.isna(table.loc["NOPHOTO", "image_slip_mean"])
    for condition in conditions[:-1]:
        truth = json.loads((tmp_path / "truth" / f"{condition.run_id}.json").read_text())
        row = table.loc[condition.run_id]
        assert row["image_slip_mean"] == pytest.approx(truth["track_photos"]["slip"], abs=0.005)
        assert abs(row["image_slip_mean"] - row["slip_mean"]) < 0.01  # below 1 % of slip
        assert 0 < row["image_slip_se"] < 0.005
    # the report shows the two side by side with their difference
    page = tmp_path / "report.html"
    assert main(["report", "--db", db, "-o", str(page), "--quiet"]) == 0
    html = page.read_text()
    assert "Image slip against encoder slip" in html
    assert all(f">P{i}<" in html for i in range(len(slips)))
    assert "within the 1 %" in html and "NOT within" not in html
