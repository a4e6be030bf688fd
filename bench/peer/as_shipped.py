"""The shipped scenes as a user runs them (issue 34 item 3), against the peer.

    python bench/peer/as_shipped.py [--repeats N] [--fmus DIR]

For each C2-C4 scene: its packaged FMU (build/fmus/<scene>.fmu) run by fmpy.simulate_fmu with
its own DefaultExperiment and solver settings, as a user runs it; its outputs scored against
the exact reference (bench/reference/<case>.csv) on the FMU's own output grid (error = max over
the grid of |y - y_ref| / max |y_ref|, y_ref interpolated linearly where the grids differ); then
Exudyn's cheapest run in build/bench/peer_points.csv (`sweep.py`) whose error ON THE SAME GRID
(the FMU's) is at most ours, re-run here (`cheapest_peer`). Ours and Exudyn's runs alternate
(ours, Exudyn's, ours, ...) so that both see the same load on a shared machine.

Our time is the process CPU time of the whole call a user makes, in two forms, and of the run:
  * `fmu`: simulate_fmu(path): unzips the FMU, reads modelDescription.xml, loads the engine,
    instantiates (reads the scene, builds the system) and runs: what one call costs;
  * `extracted`: simulate_fmu(directory) on an FMU extracted once (fmpy.extract), as a script
    that runs a unit more than once does;
  * `run`: fmi2Instantiate to fmi2FreeInstance on the extracted, loaded unit, stepped over its
    DefaultExperiment's grid with every output read (`instantiate_to_terminate`): what issue
    46's independent run timed.
Exudyn's time is the CPU time of its SolveSystem alone (model building excluded, as in the
sweep). The ratio is ours / Exudyn's, median of the per-pair ratios, with min and max.

Writes build/bench/as_shipped.csv and build/bench/AS_SHIPPED.md, appends the table to
build/bench/PEER.md (the peer bench's report) and prints it.
"""
import argparse
import csv
import os
import shutil
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import exudyn_cases as ec  # noqa: E402
from sweep import load_reference, parse_setting  # noqa: E402

ROOT = os.path.normpath(os.path.join(HERE, '..', '..'))
OUT_DIR = os.path.join(ROOT, 'build', 'bench')

# (scene, peer case, [(reference column, how to read it from an fmpy result)]): the outputs the
# peer's sweep scores (C2's chord angle from the tip's position).
CHORD = ('chord', 'beam')


def output(name):
    return ('output', name)


SCENES = [
    ('flexible_pendulum', 'c2',
     [('chord_angle', CHORD), ('tip_deflection', output('beam.tip.deflection'))]),
    ('flexible_pendulum_substructured', 'c2',
     [('chord_angle', CHORD), ('tip_deflection', output('beam.tip.deflection'))]),
    ('slider_crank', 'c3_elastic',
     [('slider_position', output('slider.position')),
      ('rod_mid_deflection', output('rod.mid.deflection'))]),
    ('slider_crank_rigid_crank', 'c3_rigid',
     [('slider_position', output('slider.position')),
      ('rod_mid_deflection', output('rod.mid.deflection'))]),
    ('spin_up_omega10', 'c4_omega10', [('tip_deflection', output('beam.tip.deflection'))]),
    ('spin_up_omega4', 'c4_omega4', [('tip_deflection', output('beam.tip.deflection'))]),
]


def quantity(result, how):
    """The scored quantity from fmpy's structured array."""
    kind, name = how
    if kind == 'output':
        return np.asarray(result[name], dtype=float)
    # the chord angle of a beam pinned at the origin, from its tip, unwrapped (it swings
    # through -pi, where atan2 jumps), as the peer bench scores it
    return np.unwrap(np.arctan2(result[name + '.tip.y'], result[name + '.tip.x']))


def score(result, how, ref, column):
    t = np.asarray(result['time'], dtype=float)
    y = quantity(result, how)
    y_ref = np.interp(t, ref['t'], ref[column])
    return float(np.max(np.abs(y - y_ref)) / np.max(np.abs(ref[column])))


def peer_points(path):
    with open(path, newline='') as f:
        return [r for r in csv.DictReader(f) if r['tool'] == 'exudyn']


def peer_error_on(run, column, t, ref):
    """A peer run's error on the grid `t` (ours): its output at those times (its own grid holds
    them; interpolated linearly where it does not) against the reference there."""
    y = np.interp(t, run.t, run.outputs[column])
    y_ref = np.interp(t, ref['t'], ref[column])
    return float(np.max(np.abs(y - y_ref)) / np.max(np.abs(ref[column])))


def cheapest_peer(points, case, column, error, t=None, ref=None):
    """Exudyn's cheapest run whose error is at most `error` on OUR output grid `t`; where none
    is, its most accurate run, marked `best`: more accurate runs would cost it at least as much
    if its cost grows with accuracy, so the ratio against it is then an upper bound.

    The sweep scores the peer on the reference's grid (1e-3 s on C2 and C3), finer than a
    shipped unit's 1e-2 s: a maximum over ten times the points is larger, so a run that misses
    our error there may meet it on our grid (the issue-46 run found Exudyn's crank 2, rod 4 at
    1e-3 s as accurate as slider_crank on a 2e-2 s grid, where this bench had held it to 1e-3 s
    points). A run whose sweep error meets ours meets it on any coarser grid of its points; each
    cheaper run is re-run here and scored on our grid (`t`, `ref`), cheapest first."""
    runs = [p for p in points if p['case'] == case and p['output'] == column
            and np.isfinite(float(p['error']))]
    if not runs:
        return None
    runs.sort(key=lambda p: float(p['cpu_median']))
    ok = [p for p in runs if float(p['error']) <= error]
    bound = float(ok[0]['cpu_median']) if ok else float('inf')
    if t is not None:
        for p in runs:
            if float(p['cpu_median']) >= bound:
                break
            run = ec.run(case, **parse_setting(p['setting']))
            if run.outputs is None:
                continue
            on_ours = peer_error_on(run, column, t, ref)
            if on_ours <= error:
                return dict(p, error=on_ours, best=False, rescored=True)
    if ok:
        return dict(ok[0], best=False)
    return dict(min(runs, key=lambda p: float(p['error'])), best=True)


def row_of(scene, case, column, comm, error, peer, ours_fmu, ours_dir, ours_run, theirs):
    row = dict(scene=scene, case=case, output=column, comm_step=comm, error=error,
               ours_fmu=statistics.median(ours_fmu), ours_extracted=statistics.median(ours_dir),
               ours_run=statistics.median(ours_run),
               peer_setting=(peer['setting'] + (' (its most accurate: ratio an upper bound)'
                                                 if peer['best'] else '')
                             + (' (scored on our grid)' if peer.get('rescored') else '')
                             if peer else 'no run in the sweep'),
               peer_error=float(peer['error']) if peer else float('nan'),
               peer_cpu=statistics.median(theirs) if theirs else float('nan'))
    for key, ours in (('fmu', ours_fmu), ('extracted', ours_dir), ('run', ours_run)):
        ratios = [o / t for o, t in zip(ours, theirs)] if theirs else [float('nan')]
        row['ratio_' + key] = statistics.median(ratios)
        row['ratio_%s_min' % key] = min(ratios)
        row['ratio_%s_max' % key] = max(ratios)
    print('%-32s %-18s error %.2e  ours %.4f s (extracted %.4f s)  Exudyn %s %.2e %.4f s  '
          'ratio %.2f (extracted %.2f, instantiate to terminate %.2f)' % (
              scene, column, error, row['ours_fmu'], row['ours_extracted'], row['peer_setting'],
              row['peer_error'], row['peer_cpu'], row['ratio_fmu'], row['ratio_extracted'],
              row['ratio_run']),
          flush=True)
    return row


def instantiate_to_terminate(unzipdir, fmpy):
    """CPU seconds from fmi2Instantiate to fmi2FreeInstance of a unit already extracted and
    loaded, stepped over its DefaultExperiment's grid and read at every point: what issue 46's
    independent run timed, the part of a call that compares with the peer's SolveSystem (model
    building excluded on its side, our scene's build included on ours)."""
    from fmpy.fmi2 import FMU2Slave
    md = fmpy.read_model_description(unzipdir)
    de = md.defaultExperiment
    vrs = [v.valueReference for v in md.modelVariables
           if v.causality == 'output' and v.type == 'Real']
    unit = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                     modelIdentifier=md.coSimulation.modelIdentifier, instanceName='timed')
    n = int(round((float(de.stopTime) - float(de.startTime or 0)) / float(de.stepSize)))
    h = float(de.stepSize)
    t0 = time.process_time()
    unit.instantiate()
    unit.setupExperiment(startTime=0.0)
    unit.enterInitializationMode()
    unit.exitInitializationMode()
    unit.getReal(vrs)
    for k in range(n):
        unit.doStep(k * h, h)
        unit.getReal(vrs)
    unit.terminate()
    unit.freeInstance()
    seconds = time.process_time() - t0
    unit.freeLibrary()
    return seconds


def cpu(fn):
    t0 = time.process_time()
    value = fn()
    return time.process_time() - t0, value


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--repeats', type=int, default=5)
    ap.add_argument('--fmus', default=os.path.join(ROOT, 'build', 'fmus'))
    ap.add_argument('--peer-points', default=os.path.join(OUT_DIR, 'peer_points.csv'))
    ap.add_argument('--scenes', nargs='*', help='only these scenes')
    args = ap.parse_args()

    import fmpy  # noqa: E402 (the bench venv has it; imported late so --help needs nothing)

    points = peer_points(args.peer_points)
    rows = []
    wall0 = time.time()
    for scene, case, scored in SCENES:
        if args.scenes and scene not in args.scenes:
            continue
        fmu = os.path.join(args.fmus, scene + '.fmu')
        ref = load_reference(case)
        comm = float(fmpy.read_model_description(fmu).defaultExperiment.stepSize)
        unzipdir = fmpy.extract(fmu)
        try:
            _, result = cpu(lambda: fmpy.simulate_fmu(fmu))
            for column, how in scored:
                error = score(result, how, ref, column)
                t_ours = np.asarray(result['time'], dtype=float)
                peer = cheapest_peer(points, case, column, error, t_ours, ref)
                peer_args = parse_setting(peer['setting']) if peer else None
                ours_fmu, ours_dir, ours_run, theirs = [], [], [], []
                for _ in range(args.repeats):
                    ours_fmu.append(cpu(lambda: fmpy.simulate_fmu(fmu))[0])
                    ours_dir.append(cpu(lambda: fmpy.simulate_fmu(unzipdir))[0])
                    ours_run.append(instantiate_to_terminate(unzipdir, fmpy))
                    if peer_args:
                        theirs.append(ec.run(case, **peer_args).cpu)
                rows.append(row_of(scene, case, column, comm, error, peer, ours_fmu, ours_dir,
                                   ours_run, theirs))
        finally:
            shutil.rmtree(unzipdir, ignore_errors=True)
    os.makedirs(OUT_DIR, exist_ok=True)
    cols = list(rows[0]) if rows else []
    with open(os.path.join(OUT_DIR, 'as_shipped.csv'), 'w', newline='') as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow(['%.6g' % r[c] if isinstance(r[c], float) else r[c] for c in cols])
    load = os.getloadavg()
    lines = [
        '## As shipped (issue 34 item 3)',
        '',
        'Each scene\'s FMU run by `fmpy.simulate_fmu` with its own DefaultExperiment and solver',
        'settings, scored against `bench/reference/` on its output grid, against Exudyn\'s',
        'cheapest run of the sweep with an error at most ours (where none is that accurate, its',
        'most accurate run); %d interleaved runs each, ratio ='
        % args.repeats,
        'ours / Exudyn\'s CPU time, median (min-max) of the pairs. `one call`: simulate_fmu on the',
        '.fmu (unzip, load, instantiate, run); `extracted`: on the FMU extracted once; `run`:',
        'fmi2Instantiate to fmi2FreeInstance on the DefaultExperiment\'s grid, every output read',
        '(what issue 46 timed; Exudyn\'s time is its SolveSystem, model building excluded).',
        'Load average at the end: %.1f %.1f %.1f; %.0f s wall.' % (load + (time.time() - wall0,)),
        '',
        '| scene | output | comm. step (s) | error | ours, one call (s) | extracted (s) | run (s) | '
        'Exudyn\'s cheapest as accurate | its error | its CPU (s) | ratio, one call | '
        'ratio, extracted | ratio, run |',
        '|---|---|---|---|---|---|---|---|---|---|---|---|---|',
    ]
    for r in rows:
        lines.append('| %s | %s | %g | %.2e | %.4f | %.4f | %.4f | %s | %.2e | %.4f | '
                     '%.2f (%.2f-%.2f) | %.2f (%.2f-%.2f) | %.2f (%.2f-%.2f) |' % (
                         r['scene'], r['output'], r['comm_step'], r['error'], r['ours_fmu'],
                         r['ours_extracted'], r['ours_run'], r['peer_setting'], r['peer_error'],
                         r['peer_cpu'], r['ratio_fmu'], r['ratio_fmu_min'], r['ratio_fmu_max'],
                         r['ratio_extracted'], r['ratio_extracted_min'],
                         r['ratio_extracted_max'], r['ratio_run'], r['ratio_run_min'],
                         r['ratio_run_max']))
    text = '\n'.join(lines) + '\n'
    with open(os.path.join(OUT_DIR, 'AS_SHIPPED.md'), 'w') as f:
        f.write(text)
    peer_report = os.path.join(OUT_DIR, 'PEER.md')
    if os.path.exists(peer_report) and not args.scenes:
        # the peer bench's report gains the rows (`make bench-peer` writes it just before)
        with open(peer_report) as f:
            report = f.read().split('\n## As shipped (issue 34 item 3)')[0].rstrip('\n')
        with open(peer_report, 'w') as f:
            f.write(report + '\n\n' + text)
    print()
    print(text)


if __name__ == '__main__':
    main()
