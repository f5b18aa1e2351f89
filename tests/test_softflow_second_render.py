"""softflow on the second side-camera renderer (written apart, issue 21): wheel, sled velocity,
failures that are failures.

Seeds used while tuning the wheel detector, the grouser search and the sled-velocity
estimate: second renderer 1, 2, 3 and 300-319 (the bench's first draw); first renderer 4, 6,
7. The accuracy figures below come from seeds 21-25.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from softflow.decay_fit import DecayFit
from softflow.field_analysis import analyse_frames
from softflow.flow_checks import (FlowMeasurementError, check_contact_fits, check_sled_velocity,
                                  fit_reason)
from softflow.wheel_detect import track_wheel
from swtlab_cli.main import main
from virtual_testbed.second_flow_render import SecondScene, render_second, write_second

TUNING_SEEDS = (1, 2, 3, *range(300, 320))


@pytest.mark.parametrize("seed, background, axle_y, surface_drop",
                         [(21, "sky", 96.0, 0.55), (22, "wall", 90.0, 0.4),
                          (23, "frame", 100.0, 0.7), (24, "sky", 88.0, 0.3)])
def test_wheel_found_whatever_lies_above_the_soil(seed, background, axle_y, surface_drop):
    """Issue 21: the centre was found 26 px above the axle when a smooth region above the
    soil merged with the disc. Required: centre within 2 px, radius within 1 px, no hints."""
    assert seed not in TUNING_SEEDS
    scene = SecondScene(background=background, axle_px=(160.0 + seed % 5, axle_y),
                        soil_top_px=axle_y + surface_drop * 72.0, seed=seed)
    frames, _, truth = render_second(scene, 1)
    pose = track_wheel(frames)[0]
    assert np.hypot(*np.subtract(pose.center_px, truth["wheel_center_px"])) < 2.0
    assert pose.radius_px == pytest.approx(truth["wheel_radius_px"], abs=1.0)


@pytest.fixture(scope="module")
def sky_run():
    scene = SecondScene(background="sky", slip=0.4, seed=25)
    return scene, render_second(scene, 4)


@pytest.mark.slow  # the sky run's four frames rendered (module fixture) and their flow measured
@pytest.mark.slow_render
def test_sled_velocity_within_1_percent_and_reasons_per_angle(sky_run):
    scene, (frames, t_s, truth) = sky_run
    res = analyse_frames(frames, t_s, scene.px_per_m)
    assert res.sled_velocity_mps[0] == pytest.approx(truth["sled_velocity_mps"][0], rel=0.01)
    assert abs(res.sled_velocity_mps[1]) < 0.01 * scene.speed_mps
    data = res.to_dict()
    for row in data["per_beta"]:  # a rate or the reason why not, never both, never neither
        for name in ("k", "alpha3"):
            assert (row[name] is None) != (row[name + "_reason"] is None)
    under = [row for row in data["per_beta"] if abs(row["beta_deg"] + 90) < 10]
    assert all("not defined" in row["k_reason"] for row in under)  # v_r = 0 under the axle


@pytest.mark.slow_render  # the sky run's first three frames written and measured by swtlab flow
def test_cli_fails_on_an_implausible_sled_velocity(sky_run, tmp_path, capsys):
    """The frames say the soil moves towards the image right while the metadata say the wheel
    travels to the left: the far soil would move with the sled. Exit 3, no JSON."""
    scene, (frames, t_s, truth) = sky_run
    write_second(scene, (frames[:3], t_s[:3], truth), tmp_path / "run")
    record = json.loads((tmp_path / "run" / "run.json").read_text())
    record["camera"]["travel_direction"] = "-x"
    (tmp_path / "run" / "run.json").write_text(json.dumps(record))
    out = tmp_path / "flow.json"
    assert main(["flow", str(tmp_path / "run"), "--json", str(out)]) == 3
    err = capsys.readouterr().err
    assert "soil flow not measured" in err and "sled velocity" in err
    assert not out.exists()


def test_cli_fails_without_a_wheel(tmp_path, capsys):
    rng = np.random.default_rng(0)
    import cv2

    folder = tmp_path / "frames"
    folder.mkdir()
    base = cv2.GaussianBlur(rng.uniform(0, 255, (200, 260)).astype(np.float32), (0, 0), 1.2)
    for k in range(2):
        cv2.imwrite(str(folder / f"{k * 50_000_000}.png"),
                    np.clip(np.roll(base, 2 * k, axis=1) * 3 - 255, 0, 255).astype(np.uint8))
    assert main(["flow", str(folder), "--px-per-m", "1000"]) == 3
    assert "wheel" in capsys.readouterr().err


def test_sled_velocity_checks():
    check_sled_velocity(np.array([0.05, 0.001]), 0.001, 1)
    with pytest.raises(FlowMeasurementError, match="vertical"):
        check_sled_velocity(np.array([0.051, -0.138]), 0.001, 1)  # issue 21, slip 0.5
    with pytest.raises(FlowMeasurementError, match="against the travel"):
        check_sled_velocity(np.array([-0.05, 0.0]), 0.001, 1)
    with pytest.raises(FlowMeasurementError, match="spreads"):
        check_sled_velocity(np.array([0.05, 0.0]), 0.02, 1)


def test_fit_reasons_and_contact_region():
    good = DecayFit(-0.05, 40.0, (38.0, 42.0), 0.99, 30)
    assert fit_reason(good, 30, 0.8) is None
    assert "not defined" in fit_reason(good, 30, 0.2)
    assert "not resolved" in fit_reason(DecayFit(-0.05, 40.0, (5.0, 75.0), 0.9, 30), 30, 0.8)
    assert "not exponential" in fit_reason(DecayFit(-0.05, 40.0, (38.0, 42.0), 0.3, 30), 30, 0.8)
    assert "no fit" in fit_reason(None, 3, 0.8)
    beta = np.deg2rad(np.arange(-175.0, 180.0, 10.0))
    fits = [None] * len(beta)
    with pytest.raises(FlowMeasurementError, match="contact region"):
        check_contact_fits(beta, fits, fits)
    above = list(fits)
    above[-1] = good  # beta = 175 deg: above the axle, not in the contact region
    with pytest.raises(FlowMeasurementError):
        check_contact_fits(beta, above, fits)
    inside = list(fits)
    inside[9] = good  # beta = -85 deg
    check_contact_fits(beta, fits, inside)


@pytest.mark.parametrize("slip", [0.1, 0.6])
def test_polar_fits_on_the_exact_field_recover_the_rates(slip):
    """The sled velocity, polar bins and decay fits alone, on the renderer's exact velocity field
    (no images), started from the far-field estimate: the sled velocity within 0.01 % and every
    contact bin where the component is defined within 1 % of the renderer's law. Before, r bins
    cut by the image bottom or the soil surface held one side of the wedge only (k 5-10 % off
    at beta -115 to -85 deg), and the far-field estimate, 0.05 % off because the far soil still
    moves, left k up to 7 % and alpha3 up to 70 % off."""
    from softflow.field_analysis import world_profiles
    from softflow.polar import beta_bins, far_field_velocity, polar_coordinates
    from virtual_testbed.second_flow_render import (camera_velocity_px, radial_rate_per_m,
                                                    tangential_rate_per_m)

    scene = SecondScene(slip=slip)
    y, x = np.mgrid[0:scene.height_px, 0:scene.width_px].astype(float)
    v = np.stack(camera_velocity_px(scene, x, y), -1) * scene.fps / scene.px_per_m
    r_px, beta, theta = polar_coordinates(x.shape, scene.axle_px, 1)
    v[(y < scene.surface_px + 2) | (r_px < scene.rim_px + 8)] = np.nan  # sky and rim band
    under = (y > scene.axle_px[1] + scene.rim_px + 8) & np.isfinite(v[..., 0])
    far, _ = far_field_velocity(v, r_px, under)
    assert abs(-far[0] / scene.speed_mps - 1) > 2e-4  # the start is off
    far_px = under & (r_px >= np.quantile(r_px[under], 0.85))
    centres = beta_bins(10.0)
    sled, _, _, radial, tangential = world_profiles(
        v, -far, r_px, beta, theta, far_px, centres, scene.rim_px, scene.rim_px + 12,
        scene.px_per_m, 1)
    assert sled == pytest.approx([scene.speed_mps, 0.0], abs=1e-4 * scene.speed_mps)
    contact = np.flatnonzero((centres > np.deg2rad(-160)) & (centres < np.deg2rad(-20)))
    th = centres + np.pi / 2
    checked = 0
    for fits, law, rim in ((radial, radial_rate_per_m, np.abs(np.sin(th))),
                           (tangential, tangential_rate_per_m,
                            np.abs(np.cos(th) - 1 / (1 - slip)))):
        for j in contact[rim[contact] >= 0.3]:
            assert fits[j].rate_per_m == pytest.approx(float(law(scene, th[j])), rel=0.01), j
            checked += 1
    assert checked >= 16


def test_second_renderer_grouser_kinematics():
    """Hand calculation of the second renderer's own grouser kinematics: between the bars the
    soil turns with the wheel (camera-frame speed w r, along -e_theta), at and beyond the tip
    circle R_t = R + h the laws run from R_t with the tips' speed w R_t, so the field is
    continuous there; the bars are drawn turning with the wheel."""
    from virtual_testbed.second_flow_render import _grouser_cover, camera_velocity_px

    scene = SecondScene(slip=0.3, grouser_count=12, grouser_height_px=8.0)
    w_per_frame = scene.omega_radps / scene.fps  # rad per frame
    ax, ay = scene.axle_px
    for r in (74.0, 78.0, 80.0):  # between the bars, and at the tips: rigid rotation
        for th in (-0.7, 0.0, 0.9):  # theta from the downward vertical towards travel (+x)
            x, y = ax + r * np.sin(th), ay + r * np.cos(th)
            ux, uy = camera_velocity_px(scene, np.array([x]), np.array([y]))
            # -w r e_theta, e_theta = (cos th, -sin th) in (x, down)
            assert ux[0] == pytest.approx(-w_per_frame * r * np.cos(th), abs=1e-9)
            assert uy[0] == pytest.approx(w_per_frame * r * np.sin(th), abs=1e-9)
    th, r = 0.4, 80.0 + 20.0  # 20 px (20 mm) beyond the tips: the laws from R_t
    ux, uy = camera_velocity_px(scene, np.array([ax + r * np.sin(th)]),
                                np.array([ay + r * np.cos(th)]))
    v = scene.speed_mps
    k = 50.0 * (1 + 0.2 * np.sin(th + 0.4))
    a3 = 65.0 * (1 + 0.15 * np.cos(2 * th))
    v_r = v * np.sin(th) * np.exp(-k * 0.020)
    v_t = (v * np.cos(th) - scene.omega_radps * 0.080) * np.exp(-a3 * 0.020)
    scale = scene.px_per_m / scene.fps
    assert ux[0] == pytest.approx((v_r * np.sin(th) + v_t * np.cos(th) - v) * scale, rel=1e-9)
    assert uy[0] == pytest.approx((v_r * np.cos(th) - v_t * np.sin(th)) * scale, rel=1e-9)
    # bar 0 at theta = -angle: covered on its centre line between rim and tips, not beyond
    angle = 0.25
    at = [ax + rr * np.sin(-angle) for rr in (76.0, 84.0)], [ay + rr * np.cos(-angle)
                                                             for rr in (76.0, 84.0)]
    cover = _grouser_cover(scene, np.array(at[0]), np.array(at[1]), angle)
    assert cover[0] == pytest.approx(1.0) and cover[1] == pytest.approx(0.0)


def test_polar_fits_on_the_exact_grousered_field_recover_the_rates():
    """With grousers the profiles are exp(-rate (r - R_t)): fitted from the tips outwards, every
    defined contact bin of the exact field is within 1 % of the renderer's law (defined: rim
    velocity at the tips at least 30 % of the travel velocity, from the truth)."""
    from softflow.field_analysis import world_profiles
    from softflow.polar import beta_bins, far_field_velocity, polar_coordinates
    from virtual_testbed.second_flow_render import camera_velocity_px, scene_truth

    scene = SecondScene(slip=0.4, grouser_count=12, grouser_height_px=8.0)
    truth = scene_truth(scene)
    y, x = np.mgrid[0:scene.height_px, 0:scene.width_px].astype(float)
    v = np.stack(camera_velocity_px(scene, x, y), -1) * scene.fps / scene.px_per_m
    r_px, beta, theta = polar_coordinates(x.shape, scene.axle_px, 1)
    v[(y < scene.surface_px + 2) | (r_px < scene.tip_px + 8)] = np.nan
    under = (y > scene.axle_px[1] + scene.tip_px + 8) & np.isfinite(v[..., 0])
    far, _ = far_field_velocity(v, r_px, under)
    far_px = under & (r_px >= np.quantile(r_px[under], 0.85))
    centres = beta_bins(10.0)
    _, _, _, radial, tangential = world_profiles(
        v, -far, r_px, beta, theta, far_px, centres, scene.rim_px, scene.tip_px + 12,
        scene.px_per_m, 1)
    contact = (centres > np.deg2rad(-160)) & (centres < np.deg2rad(-20))
    checked = 0
    for fits, rate, rim in ((radial, "radial_decay_per_m", "radial_rim_velocity_mps"),
                            (tangential, "tangential_decay_per_m", "tangential_rim_velocity_mps")):
        for j in np.flatnonzero(contact & (np.abs(truth[rim]) >= 0.3 * scene.speed_mps)):
            assert fits[j].rate_per_m == pytest.approx(truth[rate][j], rel=0.01), (rate, j)
            checked += 1
    assert checked >= 16
