"""``swtlab results`` (its text table, not its CSV/JSON) gives each mean to the decimal its
u95 supports and every uncertainty to two significant digits (GUM 7.2.6)."""

from __future__ import annotations

import math

import pandas as pd

from swtlab_cli.cmd_results import SUMMARY_U, shown


def test_means_to_the_decimal_of_their_u95():
    frame = pd.DataFrame({"run_id": ["a", "b"], "load_set_n": [70.0, 180.0],
                          "torque_nm_mean": [0.0001211, 10.05762],
                          "torque_nm_u95": [0.0068, 0.027],
                          "dp_n_mean": [13.374332, math.nan], "dp_n_se": [0.01125, math.nan],
                          "dp_n_u95": [0.3712, math.nan]})
    text = shown(frame, SUMMARY_U)
    assert text.to_dict("list") == {
        "run_id": ["a", "b"], "load_set_n": ["70", "180"],
        "torque_nm_mean": ["0.0001", "10.058"], "torque_nm_u95": ["0.0068", "0.027"],
        "dp_n_mean": ["13.37", ""], "dp_n_se": ["0.011", ""], "dp_n_u95": ["0.37", ""]}
