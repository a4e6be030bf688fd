"""`fmu-harness animate` looked at as a person would (issue 15).

The page is opened in headless Chromium (Debian's package, `make browser`; driven by
Playwright): it loads without script errors and without asking for anything beyond its own
file, the drawn beam moves between two times, Play (a real mouse click) advances the time, a
mouse drag turns the 3D view, and screenshots are kept in build/test-artifacts/animate/.
The GIF's frames differ, and the tip drawn in each frame is where the run's CSV says it is: the
end of the drawn beam (the middle of its 3-pixel-wide end, found from the pixels alone) against
`beam.tip.x/y` through the GIF's world-to-pixel map, within 2 pixels (the tip is rounded to a
pixel, then the stroke is laid across it); with the deformation magnified, the slider-crank's
rod passes through its magnified mid-span point and not through the true one.
"""

import csv
import json
import shutil
import subprocess
import time

import numpy as np
import pytest
from PIL import Image
from playwright.sync_api import sync_playwright

from fmu_util import ROOT

ARTIFACTS = ROOT / "build" / "test-artifacts" / "animate"
# the drawn tip against the CSV's: rounding the tip to a pixel (up to 0.71 px) and laying the
# 3-pixel stroke across it (its middle is then up to a pixel off the line)
TIP_PIXELS = 2.0
# a polyline vertex is drawn: the pixel it rounds to is of the beam's colour
ON_LINE_PIXELS = 1.0
# farther than this from every pixel of the beam: not drawn
OFF_LINE_PIXELS = 2.5


def read_run(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names = rows[0]
    data = np.array(rows[1:], dtype=float)
    return {n: data[:, k] for k, n in enumerate(names)}


def animate(harness, run, name, *extra):
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    out = {k: ARTIFACTS / f"{name}.{k}" for k in ("html", "gif", "json", "csv")}
    started = time.perf_counter()
    r = subprocess.run(
        [str(harness), "animate", str(run), "-o", str(out["html"]), "--gif", str(out["gif"]),
         "--metadata", str(out["json"]), "--csv", str(out["csv"]), *extra],
        capture_output=True, text=True, timeout=300,
    )
    assert r.returncode == 0, r.stderr
    print(f"{name}: {time.perf_counter() - started:.2f} s\n{r.stdout}")
    out["meta"] = json.loads(out["json"].read_text())
    out["run"] = read_run(out["csv"])
    return out


@pytest.fixture(scope="module")
def c3(harness, fmu_dir):
    # 1 ms frames, as the tests below count them (the scene's own communication step is 10 ms)
    return animate(harness, fmu_dir / "slider_crank.fmu", "slider_crank", "--speed", "0.25",
                   "--step", "1e-3")


@pytest.fixture(scope="module")
def c4(harness, fmu_dir):
    return animate(harness, fmu_dir / "spin_up_omega10.fmu", "spin_up_omega10")


@pytest.fixture(scope="module")
def rollup(harness):
    return animate(harness, ROOT / "scenes" / "rollup_3d.toml", "rollup_3d", "--step", "0.02")


class Page:
    """One page of headless Chromium, with everything it reported kept: uncaught exceptions,
    console errors, failed requests, and every URL it asked for."""

    def __init__(self, browser):
        self.page = browser.new_page(viewport={"width": 1000, "height": 900})
        self.failures, self.requests = [], []
        self.page.on("pageerror", lambda e: self.failures.append(f"exception: {e}"))
        self.page.on("console", lambda m: m.type == "error" and self.failures.append(f"console: {m.text}"))
        self.page.on("requestfailed", lambda r: self.failures.append(f"request failed: {r.url}"))
        self.page.on("request", lambda r: self.requests.append(r.url))

    def open(self, path, fragment=""):
        self.page.goto(path.resolve().as_uri() + fragment, wait_until="load")

    def eval(self, expression):
        return self.page.evaluate(expression)

    def centre(self, selector):
        box = self.page.locator(selector).bounding_box()
        return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


@pytest.fixture(scope="module")
def chromium():
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.fail("chromium is not installed: run `make browser` (Debian's chromium package)")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=["--no-sandbox"])
        yield browser
        browser.close()


@pytest.fixture
def browser(chromium):
    page = Page(chromium)
    yield page
    page.page.close()


def frames(gif_path):
    """Every frame of the GIF as an RGB array (Pillow composes the partial frames)."""
    im = Image.open(gif_path)
    out = []
    for k in range(im.n_frames):
        im.seek(k)
        out.append(np.asarray(im.convert("RGB")).astype(int))
    return out


def pixel(meta, p):
    rows, off = np.array(meta["pixel_rows"]), np.array(meta["pixel_offset"])
    return rows @ np.asarray(p, dtype=float) + off


def at(run, name, t):
    return float(np.interp(t, run["time"], run[name]))


def colour_mask(img, rgb):
    return np.all(img == np.array(rgb), axis=2)


def test_gif_frames_differ_and_have_the_run_s_length(c4):
    meta, gif = c4["meta"], frames(c4["gif"])
    assert meta["fps"] == 25 and len(gif) == len(meta["times"]) == 501  # 20 s at 25 frames/s
    assert Image.open(c4["gif"]).info["duration"] == 40  # ms per frame
    changed = [not np.array_equal(a, b) for a, b in zip(gif, gif[1:])]
    assert sum(changed) >= 0.95 * len(changed), f"{sum(changed)} of {len(changed)} frames change"
    print(f"C4 GIF: {c4['gif'].stat().st_size / 1024:.0f} kB, {len(gif)} frames")


def drawn_end(xs, ys, direction):
    """The middle of the far end of a drawn stroke: the pixels within a pixel of the farthest
    one along `direction` (a unit vector in pixels), averaged."""
    s = xs * direction[0] + ys * direction[1]
    end = s >= s.max() - 1.0
    return np.array([xs[end].mean(), ys[end].mean()])


def test_gif_shows_the_c4_tip_where_the_csv_says(c4):
    meta, run = c4["meta"], c4["run"]
    assert meta["magnification"] == 1  # the spin-up deflects 13.5 % of the length: true scale
    gif = frames(c4["gif"])
    beam = meta["beam_colors"][0]
    rows = np.array(meta["pixel_rows"])
    misses = []
    for k, img in enumerate(gif):
        t = meta["times"][k]
        tip = pixel(meta, [at(run, "beam.tip.x", t), at(run, "beam.tip.y", t), 0.0])
        phi = at(run, "beam.tip.phi", t)  # the tip's slope: the direction the stroke ends in
        u = rows @ [np.cos(phi), np.sin(phi), 0.0]
        ys, xs = np.nonzero(colour_mask(img, beam))
        assert len(xs) > 50, f"frame {k}: no beam drawn"
        end = drawn_end(xs, ys, u / np.linalg.norm(u))
        misses.append(np.hypot(*(end - tip)))
        assert misses[-1] <= TIP_PIXELS, f"frame {k} (t = {t}): drawn tip {end}, CSV {tip}"
    print(f"C4: drawn tip within {max(misses):.2f} px of the CSV's tip (median {np.median(misses):.2f}) "
          f"over {len(gif)} frames")


def rod_mid_node(run):
    """The rod's middle node (its shape outputs count from 1): an even number of elements."""
    nodes = sum(1 for name in run if name.startswith("rod.shape.x["))
    assert nodes % 2 == 1, nodes
    return (nodes + 1) // 2


def test_gif_magnifies_the_rod_s_deflection_only(c3):
    meta, run = c3["meta"], c3["run"]
    m = meta["magnification"]
    assert m == 20  # the rod deflects 0.4 % of its length: about 10 % shown
    gif = frames(c3["gif"])
    rod = meta["beam_colors"][1]
    k_mid = rod_mid_node(run)
    checked = 0
    for k in range(0, len(gif), 8):
        t = meta["times"][k]
        root = np.array([at(run, "rod.shape.x[1]", t), at(run, "rod.shape.y[1]", t)])
        mid = np.array([at(run, f"rod.shape.x[{k_mid}]", t), at(run, f"rod.shape.y[{k_mid}]", t)])
        axis = np.array([at(run, "rod.axis.x", t), at(run, "rod.axis.y", t)])
        d = mid - root
        across = d - (d @ axis) * axis
        shown = pixel(meta, [*(mid + (m - 1) * across), 0.0])
        true = pixel(meta, [*mid, 0.0])
        if np.hypot(*(shown - true)) < 8:
            continue  # too little deflection at this time to tell the two apart
        ys, xs = np.nonzero(colour_mask(gif[k], rod))
        near = lambda p: np.min(np.hypot(xs - p[0], ys - p[1]))  # noqa: E731
        assert near(shown) <= ON_LINE_PIXELS, f"frame {k}: magnified mid-span {shown} not drawn"
        assert near(true) > OFF_LINE_PIXELS, f"frame {k}: the true mid-span {true} is drawn"
        checked += 1
    assert checked >= 5, checked


def test_page_loads_without_errors_and_the_beam_moves(c3, browser):
    browser.open(c3["html"], "#t=0.4")
    assert browser.eval("window.anim && window.anim.ready") is True
    assert browser.failures == [] and browser.eval("window.__errors") == []
    assert browser.requests == [c3["html"].resolve().as_uri()]  # self-contained: nothing fetched
    assert browser.eval("window.anim.view().mag") == 20
    first = browser.eval("window.anim.drawnBeams()")
    browser.page.screenshot(path=ARTIFACTS / "slider_crank_page_t0.4.png")
    browser.eval("window.anim.setTime(1.2)")
    second = browser.eval("window.anim.drawnBeams()")
    browser.page.screenshot(path=ARTIFACTS / "slider_crank_page_t1.2.png")
    assert [b["name"] for b in first] == ["crank", "rod"]
    mid = rod_mid_node(c3["run"]) - 1  # the drawn points count from 0
    moved = np.hypot(*(np.array(first[1]["px"][mid]) - np.array(second[1]["px"][mid])))
    assert moved > 20, f"the rod's mid-span moved {moved} px between 0.4 and 1.2 s"
    a = np.asarray(Image.open(ARTIFACTS / "slider_crank_page_t0.4.png").convert("RGB")).astype(int)
    b = np.asarray(Image.open(ARTIFACTS / "slider_crank_page_t1.2.png").convert("RGB")).astype(int)
    assert np.count_nonzero(np.any(a != b, axis=2)) > 500
    # the rod is on the screen in its colour, where the page says it drew its mid-span
    rod = c3["meta"]["beam_colors"][1]
    box = browser.page.locator("#view").bounding_box()
    scale = box["width"] / browser.eval("document.getElementById('view').width")
    mx, my = (np.array(first[1]["px"][mid]) * scale + [box["x"], box["y"]]).round().astype(int)
    assert np.count_nonzero(colour_mask(a, rod)) > 200
    assert colour_mask(a[my - 2:my + 3, mx - 2:mx + 3], rod).any(), (mx, my)
    assert browser.failures == []


def test_play_button_advances_time(c3, browser):
    browser.open(c3["html"], "#t=0.1")
    start = browser.eval("window.anim.view().frame")
    browser.page.mouse.click(*browser.centre("#play"))
    time.sleep(0.6)
    view = browser.eval("window.anim.view()")
    assert view["playing"] and view["frame"] > start + 20, view  # 0.25x: about 150 ms of run
    browser.page.mouse.click(*browser.centre("#play"))
    paused = browser.eval("window.anim.view().frame")
    time.sleep(0.3)
    assert browser.eval("window.anim.view().frame") == paused
    assert browser.failures == []


def test_a_drag_turns_the_3d_view(rollup, browser):
    browser.open(rollup["html"], "#t=2")
    assert browser.eval("window.anim.dims") == 3
    before = browser.eval("window.anim.drawnBeams()")[0]["px"]
    browser.page.screenshot(path=ARTIFACTS / "rollup_3d_page_before_drag.png")
    x, y = browser.centre("#view")
    mouse = browser.page.mouse
    mouse.move(x, y)
    mouse.down()
    mouse.move(x + 120, y + 40, steps=10)
    mouse.up()
    view = browser.eval("window.anim.view()")
    after = browser.eval("window.anim.drawnBeams()")[0]["px"]
    browser.page.screenshot(path=ARTIFACTS / "rollup_3d_page_after_drag.png")
    assert view["az"] == -60 - 0.5 * 120 and view["el"] == 25 + 0.5 * 40, view
    assert view["frame"] == browser.eval("window.anim.times.indexOf(2)")
    moved = max(np.hypot(*(np.array(p) - np.array(q))) for p, q in zip(before, after))
    assert moved > 20, f"the drawn beam moved {moved} px when the view turned"
    assert browser.failures == []
