"""Demo animations (issue 15): the slider-crank (C3, played at a quarter of real time, the rod's
deflection magnified) and the spin-up (C4, Ω = 10, 20 s at 25 frames/s, true scale), each as a
self-contained HTML player and an animated GIF drawn by `fmu-harness animate` from its packaged
FMU, plus one still frame of each GIF as PNG.

Writes build/demo/<scene>.{html,gif,csv} and <scene>_frame.png. Run by `make demo`.

`--repeat N` then times the writing alone N more times (the animation drawn again from the
recorded CSV) and prints min / median / max of the seconds to write the GIF, the page and the
whole command, with the file sizes: the figures of the README's "Animations and shape outputs".
"""

import argparse
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fmu_util import ROOT  # noqa: E402

# (scene, extra options of `animate`, simulated time of the still frame)
ANIMATIONS = [
    ("slider_crank", ["--speed", "0.25"], 0.6),
    ("spin_up_omega10", [], 6.0),
]
WROTE = re.compile(r"^wrote (\S+) \((\d+) frames, ([0-9.]+) kB, ([0-9.]+) s\)$")


def animate(harness, run, out, options, extra=()):
    """Runs `fmu-harness animate`; returns (wall seconds, {suffix: seconds to write it})."""
    cmd = [str(harness), "animate", str(run), "-o", str(out.with_suffix(".html")),
           "--gif", str(out.with_suffix(".gif")), *options, *extra]
    started = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - started
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}\n{r.stderr}")
    written = {}
    for line in r.stdout.splitlines():
        m = WROTE.match(line)
        if m:
            written[Path(m.group(1)).suffix] = float(m.group(4))
    return wall, written, r.stdout


def still(gif, t, fps, speed, png):
    """The GIF's frame at simulated time t, as PNG."""
    im = Image.open(gif)
    im.seek(min(round(t / speed * fps), im.n_frames - 1))
    im.convert("RGB").save(png)


def spread(v):
    return f"{min(v):.2f} / {statistics.median(v):.2f} / {max(v):.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harness", type=Path, default=ROOT / "target" / "release" / "fmu-harness")
    ap.add_argument("--fmus", type=Path, default=ROOT / "build" / "fmus")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "demo")
    ap.add_argument("--repeat", type=int, default=0, help="time the writing N more times")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for scene, options, t_still in ANIMATIONS:
        out = args.out / scene
        fmu = args.fmus / f"{scene}.fmu"
        wall, _, text = animate(args.harness, fmu, out, options, ["--csv", str(out.with_suffix(".csv"))])
        print(text, end="")
        print(f"{scene}: {wall:.2f} s in all (running the FMU included)")
        speed = float(options[options.index("--speed") + 1]) if "--speed" in options else 1.0
        still(out.with_suffix(".gif"), t_still, 25.0, speed, args.out / f"{scene}_frame.png")
        print(f"wrote {args.out / f'{scene}_frame.png'} (t = {t_still} s)")
        if args.repeat:
            runs = [animate(args.harness, out.with_suffix(".csv"), out, options, ["--scene", str(fmu)])
                    for _ in range(args.repeat)]
            sizes = {s: out.with_suffix(s).stat().st_size for s in (".gif", ".html")}
            print(f"{scene}, drawn from the CSV {args.repeat} times: seconds min / median / max")
            print(f"  GIF   {spread([w['.gif'] for _, w, _ in runs])}  ({sizes['.gif'] / 1024:.0f} kB)")
            print(f"  page  {spread([w['.html'] for _, w, _ in runs])}  ({sizes['.html'] / 1024:.0f} kB)")
            print(f"  whole command (reading the CSV included)  {spread([w for w, _, _ in runs])}")


if __name__ == "__main__":
    main()
