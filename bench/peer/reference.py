"""Converged geometrically exact reference solutions for C2, C3 and C4.

    python bench/peer/reference.py [case ...]     (default: all cases)

For each case a few Exudyn ANCF runs (exudyn_cases.run, generalized-alpha, fixed step) on a
ladder of element counts and steps. The finest run is written to bench/reference/<case>.csv
(17 significant digits); the differences between the finest run and the runs one refinement
coarser (in elements, in step) are written to bench/reference/convergence.json, relative to the
largest absolute value of each output, with the CPU time of every run.

Each run is done in a fresh process (multiprocessing, one at a time) so that memory is returned
and a crash of one run does not lose the others.
"""
import json
import multiprocessing as mp
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import exudyn_cases as ec  # noqa: E402

OUT_DIR = os.path.normpath(os.path.join(HERE, '..', 'reference'))

# (n_elements, step[, Newton absolute tolerance]): the runs of each case; 'elements' and 'step'
# name the runs one refinement coarser in elements and in step than the reference (REFERENCE).
# The C3 rule for the absolute tolerance is below round-off for 160 elements at h = 1e-5 s
# (Newton fails there, also with 1e-7), so that run gets 1e-6.
LADDERS = {
    'c2': dict(runs=[(64, 2.5e-6), (128, 5e-6), (128, 2.5e-6)],
               elements=(64, 2.5e-6), step=(128, 5e-6)),
    'c3_elastic': dict(runs=[(80, 5e-6), (160, 1e-5, 1e-6), (160, 5e-6)],
                       elements=(80, 5e-6), step=(160, 1e-5)),
    'c3_rigid': dict(runs=[(40, 5e-6), (80, 2e-5), (80, 1e-5), (80, 5e-6)],
                     elements=(40, 5e-6), step=(80, 1e-5)),
    'c4_omega10': dict(runs=[(40, 2.5e-4), (80, 1e-3), (80, 5e-4), (80, 2.5e-4)],
                       elements=(40, 2.5e-4), step=(80, 5e-4)),
    'c4_omega4': dict(runs=[(40, 2.5e-4), (80, 1e-3), (80, 5e-4), (80, 2.5e-4)],
                      elements=(40, 2.5e-4), step=(80, 5e-4)),
}
# the reference run of each case (finest in both)
REFERENCE = {
    'c2': (128, 2.5e-6),
    'c3_elastic': (160, 5e-6),
    'c3_rigid': (80, 5e-6),
    'c4_omega10': (80, 2.5e-4),
    'c4_omega4': (80, 2.5e-4),
}


def _worker(args):
    case, ne, h, atol = args
    r = ec.run(case, ne, h, adaptive_step=False, absolute_tolerance=atol)
    if r.outputs is None:
        return dict(case=case, ne=ne, h=h, ok=False, cpu=r.cpu, info=r.info)
    return dict(case=case, ne=ne, h=h, ok=True, cpu=r.cpu, steps=r.steps, info=r.info,
                t=r.t.tolist(), outputs={k: v.tolist() for k, v in r.outputs.items()})


def run_case(case, runs):
    results = {}
    ctx = mp.get_context('spawn')
    for run in runs:
        ne, h = run[:2]
        atol = run[2] if len(run) > 2 else None
        with ctx.Pool(1) as pool:
            w0 = time.time()
            res = pool.apply(_worker, ((case, ne, h, atol),))
        print('%s ne=%d h=%g ok=%s cpu=%.1f s wall=%.1f s' % (case, ne, h, res['ok'], res['cpu'],
                                                              time.time() - w0), flush=True)
        results[(ne, h)] = res
    return results


def rel_diff(a, b):
    """max |a - b| / max |b| per output."""
    return {k: float(np.max(np.abs(np.asarray(a[k]) - np.asarray(b[k]))) / np.max(np.abs(b[k])))
            for k in b}


def write_csv(case, res):
    names = ec.CASES[case]['outputs']
    path = os.path.join(OUT_DIR, case + '.csv')
    t = np.round(np.asarray(res['t']), 9)   # grid times as the doubles nearest to i*dt
    cols = [t] + [np.asarray(res['outputs'][n]) for n in names]
    with open(path, 'w') as f:
        f.write('t,' + ','.join(names) + '\n')
        for i in range(len(t)):
            f.write(','.join('%.17g' % c[i] for c in cols) + '\n')
    return path


def main(cases):
    os.makedirs(OUT_DIR, exist_ok=True)
    conv_path = os.path.join(OUT_DIR, 'convergence.json')
    conv = json.load(open(conv_path)) if os.path.exists(conv_path) else {}
    for case in cases:
        lad = LADDERS[case]
        results = run_case(case, lad['runs'])
        ref = results[REFERENCE[case]]
        if not ref['ok']:
            print('reference run failed:', case, ref['info'])
            continue
        path = write_csv(case, ref)
        entry = dict(reference=dict(n_elements=ref['ne'], step=ref['h'], cpu=ref['cpu'],
                                    steps=ref['steps']),
                     max_abs={k: float(np.max(np.abs(v))) for k, v in ref['outputs'].items()},
                     runs=[])
        for (ne, h), r in results.items():
            row = dict(n_elements=ne, step=h, ok=r['ok'], cpu=r['cpu'])
            if r['ok'] and (ne, h) != REFERENCE[case]:
                row['rel_diff_to_reference'] = rel_diff(r['outputs'], ref['outputs'])
            entry['runs'].append(row)
        for kind in ('elements', 'step'):
            r = results[lad[kind]]
            if r['ok']:
                entry['refinement_' + kind] = dict(coarser=list(lad[kind]),
                                                   rel_diff=rel_diff(r['outputs'], ref['outputs']))
        if case == 'c4_omega10':
            y = np.asarray(ref['outputs']['tip_deflection'])
            i = int(np.argmax(np.abs(y)))
            entry['peak_tip_deflection'] = dict(value=float(y[i]), t=float(ref['t'][i]))
        conv[case] = entry
        json.dump(conv, open(conv_path, 'w'), indent=1)
        print('wrote', path, json.dumps({k: entry.get(k) for k in
                                         ('refinement_elements', 'refinement_step')}), flush=True)


TARGET = {'chord_angle': 1e-5, 'slider_position': 1e-5}
TARGET_C4 = 5e-5


def convergence_table(conv):
    """Markdown table of the reference convergence figures from convergence.json."""
    lines = ['| case | output | reference run (elements, step) | CPU of the reference run (s) | '
             'vs half the elements | vs double the step | target |',
             '|---|---|---|---|---|---|---|']
    for case in LADDERS:
        if case not in conv:
            continue
        e = conv[case]
        ref = e['reference']
        for out in ec.CASES[case]['outputs']:
            tgt = TARGET_C4 if case.startswith('c4') else TARGET.get(out)
            re_, rs = e.get('refinement_elements'), e.get('refinement_step')
            lines.append('| %s | %s | %d, %g s | %.0f | %.1e (%d el.) | %.1e (h = %g s) | %s |' % (
                case, out, ref['n_elements'], ref['step'], ref['cpu'],
                re_['rel_diff'][out], re_['coarser'][0], rs['rel_diff'][out], rs['coarser'][1],
                '<= %.0e' % tgt if tgt else 'report'))
    return '\n'.join(lines)


if __name__ == '__main__':
    if sys.argv[1:] == ['--table']:
        print(convergence_table(json.load(open(os.path.join(OUT_DIR, 'convergence.json')))))
    else:
        main(sys.argv[1:] or list(LADDERS))
