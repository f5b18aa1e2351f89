"""``swtlab track-slip`` end to end on rendered photos (truth from the renderer)."""

from __future__ import annotations

import json

import pytest

from swtlab_cli import exit_codes
from swtlab_cli.main import main
from virtual_testbed.track_render import write_track_render


@pytest.fixture(scope="module")
def track_png(tmp_path_factory):
    folder = tmp_path_factory.mktemp("track")
    png, truth_path = write_track_render(folder / "track.png", 0.55, px_per_m=850.0, seed=2,
                                         size_px=(800, 600), track_angle_deg=130.0,
                                         sun_azimuth_deg=150.0)
    return png, json.loads(truth_path.read_text())


def test_json_output(track_png, capsys):
    png, truth = track_png
    code = main(["track-slip", str(png), "--radius-m", "0.125", "--grousers", "12",
                 "--px-per-m", "850", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == exit_codes.OK
    assert abs(out["slip"] - truth["slip"]) < 0.005
    assert out["marks_used"] >= 10 and out["slip_std"] > 0


def test_human_output_with_two_point_scale(track_png, capsys):
    png, truth = track_png
    (x1, y1), (x2, y2) = truth["scale_points_px"]
    code = main(["track-slip", str(png), "--radius-m", "0.125", "--grousers", "12",
                 "--scale-points", f"{x1},{y1},{x2},{y2}",
                 "--scale-distance-m", str(truth["scale_distance_m"])])
    out = capsys.readouterr().out
    assert code == exit_codes.OK
    assert out.startswith("slip") and "marks used" in out and "%" in out


def test_refusal_is_one_line_and_exit_code_3(tmp_path, capsys):
    png, _ = write_track_render(tmp_path / "sand.png", 0.3, seed=1, size_px=(640, 480),
                                marks=False)
    code = main(["track-slip", str(png), "--radius-m", "0.125", "--grousers", "12",
                 "--px-per-m", "900"])
    err = capsys.readouterr().err
    assert code == exit_codes.BAD_INPUT
    assert "no periodic grouser marks found" in err and err.count("\n") == 1


def test_unreadable_file(tmp_path, capsys):
    code = main(["track-slip", str(tmp_path / "none.png"), "--radius-m", "0.125",
                 "--grousers", "12", "--px-per-m", "900"])
    assert code == exit_codes.BAD_INPUT
    assert capsys.readouterr().err.count("\n") == 1


def test_scale_points_need_a_distance(track_png):
    png, _ = track_png
    with pytest.raises(SystemExit) as info:
        main(["track-slip", str(png), "--radius-m", "0.125", "--grousers", "12",
              "--scale-points", "1,2,3,4"])
    assert info.value.code == exit_codes.USAGE
