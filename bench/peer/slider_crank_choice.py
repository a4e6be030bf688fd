"""slider_crank as shipped since 2026-12-07, at its accuracy study's choice (crank 2, rod 4
elements, fixed step 1.76e-3 s), against what it shipped before, the paper's mesh at the first
study's step (crank 3, rod 8, 3.71e-4 s): both packaged from scenes/slider_crank.toml, run by
fmpy.simulate_fmu on the FMU extracted once, in alternating rounds; the process CPU time of each call, the ratio per round
(median, least-largest), and each run's error against bench/reference/c3_elastic.csv on the
unit's grid (relative to the reference's largest value: as_shipped.py's score).

    .venv-bench/bin/python bench/peer/slider_crank_choice.py   # after `make release`
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from as_shipped import output, score  # noqa: E402
from sweep import load_reference  # noqa: E402

# (pattern, replacement) from the shipped scene to the paper's mesh: each must match once
PAPER = [
    (r'max_step = 1\.76e-3', 'max_step = 3.71e-4'),
    (r'(name = "crank"\nlength = 0\.152\nelements = )2', r'\g<1>3'),
    (r'(name = "rod"\nlength = 0\.304\nelements = )4', r'\g<1>8'),
]
OUTPUTS = (('slider.position', 'slider_position'), ('rod.mid.deflection', 'rod_mid_deflection'))


def package(scene_text, where, name):
    toml, fmu = os.path.join(where, name + '.toml'), os.path.join(where, name + '.fmu')
    with open(toml, 'w') as f:
        f.write(scene_text)
    subprocess.run([os.path.join(ROOT, 'target/release/fmu-harness'), 'package', toml, '-o', fmu,
                    '--binary', 'linux64=' + os.path.join(ROOT, 'target/release/libfmu_beam.so')],
                   check=True, stdout=subprocess.DEVNULL)
    return fmu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--rounds', type=int, default=5)
    args = ap.parse_args()
    import fmpy
    shipped = open(os.path.join(ROOT, 'scenes/slider_crank.toml')).read()
    paper = shipped
    for pattern, repl in PAPER:
        paper, n = re.subn(pattern, repl, paper)
        if n != 1:
            sys.exit('scenes/slider_crank.toml changed: %r matched %d times' % (pattern, n))
    ref = load_reference('c3_elastic')
    with tempfile.TemporaryDirectory() as where:
        dirs = {name: fmpy.extract(package(text, where, name), os.path.join(where, name))
                for name, text in (('shipped', shipped), ('paper', paper))}
        cpu = {name: [] for name in dirs}
        for k in range(args.rounds):
            for name in (dirs if k % 2 == 0 else reversed(list(dirs))):
                t0 = time.process_time()
                res = fmpy.simulate_fmu(dirs[name], output=[o for o, _ in OUTPUTS])
                cpu[name].append(time.process_time() - t0)
                if k == 0:
                    print(name, 'error:', ', '.join('%s %.2e' % (col, score(res, output(o), ref, col))
                                                    for o, col in OUTPUTS))
    ratios = [s / p for s, p in zip(cpu['shipped'], cpu['paper'])]
    for name, v in cpu.items():
        print('%s CPU s: median %.4f (%.4f-%.4f)' % (name, np.median(v), min(v), max(v)))
    print('shipped / paper: median %.3f (%.3f-%.3f), %d rounds, load average %.1f'
          % (np.median(ratios), min(ratios), max(ratios), args.rounds, os.getloadavg()[0]))


if __name__ == '__main__':
    main()
