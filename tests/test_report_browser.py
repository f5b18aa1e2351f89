"""The report in a real browser: headless Chromium (Debian's package, installed by
.ci/chromium.sh) opens the page from disk with the network off, every image decodes, every
inline SVG time series is laid out, nothing reaches the console, a full-page screenshot is
not blank, and a run's lightbox shows its drawing full size.

How: a copy of the page gets a probe script as the first thing in <head>; it records console
errors/warnings, error events (a broken image fires one) and unhandled rejections, and on
load draws every image into a canvas (a full decode; a broken image throws or has no size)
and checks its pixels are not uniform, then writes the results and the page height into the
DOM, which ``--dump-dom`` prints. Every console line Chromium logs to stderr also counts
(the page itself has no script, so it should log nothing). A second run takes the screenshot
at the page's full height. A deliberately broken page checks that the probe catches faults.
"""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from html import unescape
from pathlib import Path

import cv2
import numpy as np
import pytest

from campaign_report import write_report
from test_report_campaign import build_small_campaign

CHROMIUM = next((p for p in (shutil.which("chromium"), "/usr/bin/chromium")
                 if p and Path(p).is_file()), None)
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium not installed (.ci/chromium.sh installs Debian's package)")

WIDTH = 1280
MAX_HEIGHT = 16000  # beyond this Chromium's screenshot gets tiled/clipped

PROBE = """<script>
(() => {
  const faults = [];
  for (const level of ["error", "warn"]) {
    const original = console[level];
    console[level] = (...args) => { faults.push(level + ": " + args.join(" "));
                                    original.apply(console, args); };
  }
  window.addEventListener("error", e => faults.push("error event: " +
      (e.message || (e.target && (e.target.tagName + " " + String(e.target.src).slice(0, 40))))),
    true);
  window.addEventListener("unhandledrejection", e => faults.push("rejection: " + e.reason));
  const decode = img => {  // drawing forces a full decode; the pixels must not be uniform
    if (!img.complete || img.naturalWidth === 0) return "not decoded";
    try {
      const canvas = document.createElement("canvas");
      canvas.width = canvas.height = 32;
      const context = canvas.getContext("2d");
      context.drawImage(img, 0, 0, 32, 32);
      const pixels = context.getImageData(0, 0, 32, 32).data;
      let lo = 255, hi = 0;
      for (let i = 0; i < pixels.length; i += 4) {
        lo = Math.min(lo, pixels[i + 1]); hi = Math.max(hi, pixels[i + 1]);
      }
      return hi - lo > 10 ? "ok" : "uniform";
    } catch (e) { return "failed: " + e.name; }
  };
  window.addEventListener("load", () => {  // synchronous: --dump-dom prints after it ran
    const images = [...document.images];
    const out = document.createElement("pre");
    out.id = "probe";
    const drawings = [...document.querySelectorAll(".gallery figure > a > svg")].map(
      svg => { const box = svg.getBoundingClientRect();
               return [Math.round(box.width), Math.round(box.height)]; });
    out.textContent = JSON.stringify({images: images.length, decoded: images.map(decode),
      drawings, faults, height: document.documentElement.scrollHeight});
    document.body.appendChild(out);
  });
})();
</script>"""


def _chromium(url: str, profile: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
         "--no-first-run", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--hide-scrollbars", f"--user-data-dir={profile}",
         "--enable-logging=stderr", "--v=0", *extra, url],
        capture_output=True, text=True, timeout=120)


def probe(page: Path, work: Path) -> tuple[dict, list[str]]:
    """(what the probe found, console lines Chromium logged) for ``page`` opened from disk."""
    copy = work / f"probed-{page.name}"
    copy.write_text(page.read_text(encoding="utf-8").replace("<head>", "<head>" + PROBE, 1),
                    encoding="utf-8")
    done = _chromium(copy.as_uri(), work / "profile-probe", "--dump-dom")
    found = re.search(r'<pre id="probe">(.*?)</pre>', done.stdout, re.S)
    assert found, f"the probe did not report (chromium rc {done.returncode}): {done.stderr[-800:]}"
    console = [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    return json.loads(unescape(found.group(1))), console


def screenshot(page: Path, work: Path, height: int) -> np.ndarray:
    """A WIDTH x ``height`` screenshot of the page (the page itself, unprobed)."""
    return screenshot_of(page.as_uri(), work, height)


def screenshot_of(url: str, work: Path, height: int) -> np.ndarray:
    """A WIDTH x ``height`` screenshot of ``url`` (a fragment opens its ``:target``)."""
    png = work / "screenshot.png"
    png.unlink(missing_ok=True)
    done = _chromium(url, work / "profile-shot", f"--screenshot={png}",
                     f"--window-size={WIDTH},{height}")
    assert png.is_file(), f"no screenshot (chromium rc {done.returncode}): {done.stderr[-800:]}"
    image = cv2.imread(str(png), cv2.IMREAD_COLOR)
    assert image is not None
    return image


def test_the_probe_catches_a_broken_image_and_a_console_error(tmp_path):
    stripes = np.zeros((16, 16, 3), np.uint8)
    stripes[:, ::2] = 255
    good = base64.b64encode(cv2.imencode(".png", stripes)[1].tobytes()).decode()
    page = tmp_path / "broken.html"
    page.write_text('<!DOCTYPE html><html><head></head><body><img src="data:image/png;base64,'
                    f'AAAA"><img src="data:image/png;base64,{good}">'
                    '<script>console.error("boom")</script></body></html>')
    found, console = probe(page, tmp_path)
    assert found["decoded"] == ["not decoded", "ok"]
    assert "error: boom" in found["faults"] and any("error event" in f for f in found["faults"])
    assert any('"boom"' in line for line in console)


def test_report_opens_in_chromium_without_errors_and_renders(tmp_path):
    runs = [f"L070_MP0_SC_s{s}.mcap" for s in ("-010", "+000", "+005", "+010", "+020", "+035",
                                               "+060")] + ["L180_MP0_SC_s+090.mcap"]
    url = build_small_campaign(tmp_path, runs=runs, export=False)
    page = write_report(url, tmp_path / "report.html")
    found, console = probe(page, tmp_path)
    assert found["images"] == page.read_text().count("<img ") >= 1  # the curve figures
    assert found["decoded"] == ["ok"] * found["images"]
    # every run's time series, inline SVG, laid out as a thumbnail of the 800 x 640 figure
    assert len(found["drawings"]) == len(runs)
    assert all(w > 200 and abs(h / w - 0.8) < 0.02 for w, h in found["drawings"])
    assert found["faults"] == [] and console == []
    height = min(found["height"], MAX_HEIGHT)
    assert height > 1500
    image = screenshot(page, tmp_path, height)
    assert image.shape[:2] == (height, WIDTH)
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    assert grey.std() > 20 and (grey < 200).mean() > 0.03  # text, tables and plots drawn
    # the thumbnails' band shows plots: the page's blue accents and traces are in it
    blue = (image[:, :, 0] > 150) & (image[:, :, 2] < 100)
    assert blue.sum() > 2000
    # a run's lightbox (opened by its fragment) shows the thumbnail's drawing again, full
    # size (<use>): the white figure over the dark backdrop, its trace in the load colour
    shot = screenshot_of(page.as_uri() + "#full-run-0", tmp_path, 900)
    centre = shot[200:700, 240:1040]
    backdrop = shot[:, :100]
    assert (cv2.cvtColor(backdrop, cv2.COLOR_BGR2GRAY) < 80).mean() > 0.9
    assert (cv2.cvtColor(centre, cv2.COLOR_BGR2GRAY) > 240).mean() > 0.5
    trace = (centre[:, :, 0] > 150) & (centre[:, :, 2] < 60) & (centre[:, :, 1] < 150)
    assert trace.sum() > 500  # the 70 N colour, #0072B2
