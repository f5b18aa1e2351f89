"""A towed row's torque entered as the 0 a paper prints by convention is warned about; a blank
cell (the documented way) and a driven row are not."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from sim_gap.points_csv import TowedTorqueWarning, read_points_csv

HEADER = "source,wheel_radius_m,wheel_width_m,load_set_n,slip,dp_n,dp_n_se,torque_nm,torque_nm_se\n"
SHIPPED = Path(__file__).resolve().parents[1] / "sim_gap" / "data" / "ding2011_points.csv"


def _write(tmp_path, *rows: str) -> Path:
    path = tmp_path / "points.csv"
    path.write_text(HEADER + "".join(r + "\n" for r in rows))
    return path


@pytest.mark.parametrize("slip, torque", [("0.0", "0.0"), ("-0.05", "0"), ("0", "-0.0")])
def test_a_towed_torque_of_zero_is_warned_about(tmp_path, slip, torque):
    path = _write(tmp_path, "a,0.15,0.16,80,0.2,11,0.5,3.0,0.1",
                  f"a,0.15,0.16,80,{slip},-6.5,0.5,{torque},0.1")
    with pytest.warns(TowedTorqueWarning) as caught:
        table = read_points_csv(path)
    # only the reader's warnings: a warning of another module's object collected meanwhile
    # (seen once under xdist) is recorded too
    towed = [w for w in caught if issubclass(w.category, TowedTorqueWarning)]
    assert len(towed) == 1, [(w.category.__name__, str(w.message)) for w in caught]
    assert str(towed[0].message).startswith(f"{path}:3: column 'torque_nm': exactly 0 on a "
                                            f"towed row (slip {float(slip):g} <= 0)")
    assert "leave the cell (and its _se or _sd) blank" in str(towed[0].message)
    assert table["torque_nm"].tolist() == [3.0, 0.0]  # still read as written


def test_blank_towed_torque_and_driven_rows_are_silent(tmp_path):
    path = _write(tmp_path, "a,0.15,0.16,80,0.0,-6.5,0.5,,", "a,0.15,0.16,80,0.1,11,0.5,0.0,0.1")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = read_points_csv(path)
        read_points_csv(SHIPPED)  # its towed rows leave the torque blank
    assert np.isnan(table["torque_nm"].iloc[0]) and table["torque_nm"].iloc[1] == 0.0
