"""softflow.field_analysis on renders: decay rates per beta, grouser model choice, CLI and JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softflow.field_analysis import analyse_frames
from softflow.frames import load_frames
from swtlab_cli.main import main
from virtual_testbed.flow_render import (FlowScene, default_radial_decay_per_m,
                                         default_tangential_decay_per_m, render_flow,
                                         write_flow_render)


@pytest.fixture(scope="module")
def smooth_wheel():
    """Ten frames of the default smooth-wheel scene, seed 5: for the accuracy check and the
    checks of the outputs' form."""
    scene = FlowScene(seed=5)
    return scene, render_flow(scene, 10)


@pytest.fixture(scope="module")
def smooth_wheel_folder(smooth_wheel, tmp_path_factory):
    """That render written once as a run folder (frames, run.json, truth apart), read by the
    CLI and the frame loader; neither writes into it."""
    folder = tmp_path_factory.mktemp("smooth_wheel") / "run"
    write_flow_render(smooth_wheel[1], folder)
    return folder


def _contact(result):
    beta = result.beta_rad
    return (beta < -np.deg2rad(20)) & (beta > -np.deg2rad(160))


@pytest.mark.slow  # optical flow on ten rendered frames
@pytest.mark.slow_render
def test_decay_rates_within_5_percent(smooth_wheel):
    """Every defined contact bin's ``k`` and ``alpha3`` within 5 % of the truth (the issue's
    target, per bin, whatever the number of bins) on one render: 10 bins of each.

    A regression check; the record is the bench's (``bench_softflow.decay_and_grousers``:
    seeds 5-9, this scene, ten frames, every contact bin; docs/validation/softflow.md: ``k``
    within 3 %, ``alpha3`` within 4.5 %). The suite checked seeds 5 and 9 (40 bins); seed 5
    alone (measured largest errors 1.3 % and 1.6 %; seed 9's 0.7 % and 2.5 %) catches a
    regression that puts a fraction q of bins beyond 5 % with probability 1 - (1 - q)^20
    if bins failed independently: 0.88 at q = 0.1, 0.96 at q = 0.15 (two renders: 0.985,
    0.998)."""
    scene, r = smooth_wheel
    res = analyse_frames(r.frames, r.t_s, scene.px_per_m)
    contact = _contact(res)
    theta = res.beta_rad + np.pi / 2
    k = np.array([f.rate_per_m if f else np.nan for f in res.radial])
    a3 = np.array([f.rate_per_m if f else np.nan for f in res.tangential])
    # defined: rim velocity of the component >= 30 % of the travel velocity (issue 21)
    k_bins = contact & (np.abs(np.sin(theta)) >= 0.3)  # v_r vanishes under the axle
    a3_bins = contact & (np.abs(np.cos(theta) - 1 / (1 - scene.slip)) >= 0.3)
    k_err = k[k_bins] / default_radial_decay_per_m(res.beta_rad[k_bins]) - 1
    a3_err = a3[a3_bins] / default_tangential_decay_per_m(res.beta_rad[a3_bins]) - 1
    assert np.all(np.abs(k_err) < 0.05), k_err
    assert np.all(np.abs(a3_err) < 0.05), a3_err
    undefined = np.flatnonzero(contact & ~a3_bins)
    assert len(undefined) and all("not defined" in res.tangential_reason[i] for i in undefined)
    assert res.sled_velocity_mps[0] == pytest.approx(scene.velocity_mps, rel=0.01)
    assert res.mean.outlier_fraction < 0.01
    for f in np.array(res.tangential)[a3_bins]:
        assert f.ci95_per_m[0] < f.rate_per_m < f.ci95_per_m[1] and f.r2 > 0.8
    assert res.grouser is None


def test_alpha1_alpha2_from_given_strain(smooth_wheel):
    """One frame pair: the fit of the given strain is exact algebra on whatever k is measured
    (the pair gives k in 28 bins, as 3 pairs do)."""
    scene, r = smooth_wheel
    res = analyse_frames(r.frames[:2], r.t_s[:2], scene.px_per_m)
    k = np.array([f.rate_per_m if f else np.nan for f in res.radial])
    alpha1, alpha2 = 2.0, 0.05
    eps = alpha1 / k - alpha2  # the strain for which k = alpha1 / (eps + alpha2) exactly
    res = analyse_frames(r.frames[:2], r.t_s[:2], scene.px_per_m, eps_vol_by_beta=eps)
    assert res.alpha12["alpha1_per_m"] == pytest.approx(alpha1, rel=1e-6)
    assert res.alpha12["alpha2"] == pytest.approx(alpha2, rel=1e-6)
    data = res.to_dict()  # a given strain is taken as resolved
    assert data["alpha1_alpha2_reason"] is None
    assert all(row["eps_vol_p_reason"] is None and row["eps_vol_p_bound"] is None
               for row in data["per_beta"])


@pytest.mark.slow  # optical flow on four supersampled frames per grouser model
@pytest.mark.slow_render
@pytest.mark.parametrize("model, seed", [("piecewise", 100), ("gear", 103)])
def test_grouser_model_chosen(model, seed):
    """Four frames (three pairs): the scores of the four models are those of six frames
    within 2 % (measured: piecewise 0.00075 against the next 0.00090 m/s, gear 0.00079
    against 0.00081; six frames 0.00074/0.00089 and 0.00079/0.00081)."""
    scene = FlowScene(grouser_count=12, grouser_height_px=10, grouser_model=model,
                      grouser_gamma=3.0, seed=seed, supersample=3)
    r = render_flow(scene, 4)
    res = analyse_frames(r.frames, r.t_s, scene.px_per_m, wheel_radius_px=100,
                         grouser_count=12, grouser_height_px=10)
    assert res.grouser["chosen"] == model, res.grouser
    assert set(res.grouser["scores_mps"]) == {"piecewise", "cosine", "cosine_series", "gear"}


def test_cli_json(smooth_wheel_folder, tmp_path, capsys):
    out = tmp_path / "flow.json"
    assert main(["flow", str(smooth_wheel_folder), "--frames", "0:3", "--json", str(out),
                 "--plots", str(tmp_path / "plots")]) == 0
    data = json.loads(out.read_text())
    assert data["frame_range"] == [0, 3] and data["pairs"] == 2
    row = data["per_beta"][0]
    assert {"beta_deg", "k", "alpha3"} <= set(row)
    assert {"rate_per_m", "ci95_per_m", "r2", "amplitude_mps"} <= set(row["alpha3"])
    assert len(list((tmp_path / "plots").glob("*.png"))) == 3
    assert "alpha3_per_m" in capsys.readouterr().out


def test_cli_bad_input(tmp_path, capsys):
    assert main(["flow", str(tmp_path / "nothing")]) == 3
    assert "no such file" in capsys.readouterr().err


def test_frames_from_folder_range(smooth_wheel, smooth_wheel_folder):
    scene, r = smooth_wheel
    fs = load_frames(smooth_wheel_folder, (2, 5))
    assert fs.frame_range == (2, 5) and len(fs.frames) == 3
    assert fs.t_s == pytest.approx(r.t_s[2:5])
    assert fs.px_per_m == scene.px_per_m and fs.wheel_radius_px == pytest.approx(100)
