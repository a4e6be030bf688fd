"""The peer table of `make bench-peer` timed again, interleaved (issue 34 item 4).

    .venv-bench/bin/python bench/peer/interleaved.py [--repeats 5] [--budget 600] [--cells c2,c4_omega4]

`make bench-peer` runs Exudyn's sweep and ours in two phases, minutes apart, so a change of the
machine's load between them falls on one tool only. This script takes, for every case, output
and target that both tools reach, the two runs that set the ratio in build/bench/PEER.md (our
cheapest run and Exudyn's, chosen from build/bench/ours_points.csv and peer_points.csv by the
rule of `fmu-bench peer`: the cheapest median CPU among the runs that meet the target for
good), and times them again in turns: ours, Exudyn's, ours, Exudyn's, ... `--repeats` rounds.
Each round's ratio ours / Exudyn's is taken; the table gives the median over the rounds and the
least and largest.

Ours: `target/release/fmu-bench peer-run` in a subprocess, one sample per call (the thread's
CPU time from building the unit to its last step, as `fmu-bench peer` times it; a run shorter
than 0.1 s is timed in a batch and divided). Exudyn's: `exudyn_cases.run` in this process
(process CPU time of SolveSystem alone, as bench/peer/sweep.py times it), a run shorter than
0.1 s also in a batch. Each distinct pair of runs is timed once and serves every target it sets.

Cost: pairs whose round would take more than --long seconds (from the sweep's medians) get 3
rounds instead of --repeats; pairs whose round would take more than --skip seconds are left out
(and listed); the estimate is printed before it starts. With the defaults the whole takes about
8-10 minutes on a 2-core machine.

Writes build/bench/INTERLEAVED.md and build/bench/interleaved.csv.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import exudyn_cases as ec  # noqa: E402
import sweep  # noqa: E402

ROOT = os.path.normpath(os.path.join(HERE, '..', '..'))
BENCH = os.path.join(ROOT, 'build', 'bench')
FMU_BENCH = os.path.join(ROOT, 'target', 'release', 'fmu-bench')
TARGETS = (1e-2, 1e-3, 1e-4, 1e-5)
MIN_SAMPLE = 0.1     # s: shorter runs are timed in batches
SUBPROCESS_OVERHEAD = 0.05   # s per call of ours beyond its runs (start, scene, first run)


def read_points(path):
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r['error'] = float(r['error'])
        r['cpu_median'] = float(r['cpu_median'])
        r['steps'] = int(float(r['steps'])) if r['steps'] not in ('', None) else 0
    return rows


def family(setting):
    """As `family` in bench/src/work_precision/peer.rs: (family, size), smaller is tighter."""
    for mode in ('fixed step', 'tolerance'):
        if setting.startswith(mode):
            rest = setting[len(mode):]
            size, _, tail = rest.partition(',')
            size = size.strip()
            while size.endswith(' s'):
                size = size[:-2]
            try:
                value = float(size)
            except ValueError:
                return None
            return (mode if not tail else mode + ',' + tail, value)
    fields = setting.split(';')
    h = [f[2:] for f in fields if f.startswith('h=')]
    if not h:
        return None
    try:
        h = float(h[0])
    except ValueError:
        return None
    return (';'.join(f for f in fields if not f.startswith('h=')), h)


def meets(points, p, target):
    """As `meets` in peer.rs: p meets the target, and so does every tighter setting of its
    family run with the same formulation. (A NaN error is not above the target there either.)"""
    if p['error'] > target:
        return False
    fam = family(p['setting'])
    if fam is None:
        return True
    for q in points:
        if (q['tool'], q['case'], q['output'], q['formulation']) != \
                (p['tool'], p['case'], p['output'], p['formulation']):
            continue
        fq = family(q['setting'])
        if fq is None or fq[0] != fam[0] or fq[1] >= fam[1]:
            continue
        if not q['error'] <= target:
            return False
    return True


def cheapest(points, tool, case, output, target):
    best = None
    for p in points:
        if p['tool'] == tool and p['case'] == case and p['output'] == output \
                and meets(points, p, target):
            if best is None or p['cpu_median'] < best['cpu_median']:
                best = p
    return best


def peer_md_choices(path):
    """(case output, target) -> (ours 'formulation at setting', theirs setting) from PEER.md's
    table of the runs behind each ratio, to check that the choice here is the same."""
    out = {}
    if not os.path.exists(path):
        return out
    with open(path) as f:
        lines = f.read().split('## The runs behind each ratio', 1)[-1].splitlines()
    for line in lines:
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if len(cells) != 4 or cells[1] in ('target', '---'):
            continue

        def head(c):
            return c.split(': error', 1)[0] if c != 'not reached' else None
        out[(cells[0], cells[1])] = (head(cells[2]), head(cells[3]))
    return out


def exudyn_args(case, setting):
    a = sweep.parse_setting(setting)
    return a['ne'], a['step'], a['spectral_radius']


def batch(t):
    """Runs per timed sample for a run of t seconds: enough to last MIN_SAMPLE."""
    return max(1, math.ceil(MIN_SAMPLE / max(t, 1e-4))) if t < MIN_SAMPLE else 1


def run_ours(case, formulation, setting):
    cmd = [FMU_BENCH, 'peer-run', '--scenes', 'scenes', '--references', 'bench/reference',
           '--case', case, '--formulation', formulation, '--setting', setting, '--samples', '1']
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError('%s: %s' % (' '.join(cmd), res.stderr.strip()))
    return json.loads(res.stdout.strip().splitlines()[-1])


def run_theirs(case, setting, batch):
    ne, h, rho = exudyn_args(case, setting)
    total, last = 0.0, None
    for _ in range(batch):
        last = ec.run(case, ne, h, spectral_radius=rho)
        total += last.cpu
    return total / batch, last


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--repeats', type=int, default=5, help='rounds per pair (default 5)')
    ap.add_argument('--long', type=float, default=8.0,
                    help='a pair whose round takes longer (s, from the sweep) gets 3 rounds')
    ap.add_argument('--skip', type=float, default=40.0,
                    help='a pair whose round takes longer (s, from the sweep) is left out')
    ap.add_argument('--cells', default='', help='only these cases, comma-separated')
    ap.add_argument('--points', default=BENCH, help='where ours_points.csv and peer_points.csv are')
    ap.add_argument('--output', default=BENCH)
    a = ap.parse_args()
    if not os.path.exists(FMU_BENCH):
        sys.exit('%s not built (make release)' % FMU_BENCH)
    ours = read_points(os.path.join(a.points, 'ours_points.csv'))
    theirs = read_points(os.path.join(a.points, 'peer_points.csv'))
    md = peer_md_choices(os.path.join(a.points, 'PEER.md'))
    wanted = [c for c in a.cells.split(',') if c]

    # the cells and the distinct pairs of runs behind them
    pairs, cells = {}, []
    keys = []
    for p in ours:
        k = (p['case'], p['output'])
        if k not in keys:
            keys.append(k)
    for case, output in keys:
        if wanted and case not in wanted:
            continue
        for t in TARGETS:
            o = cheapest(ours, 'fmu-beam', case, output, t)
            x = cheapest(theirs, 'exudyn', case, output, t)
            if o is None or x is None:
                continue
            label = ('%s %s' % (case, output), '%.0e' % t)
            chosen = ('%s at %s' % (o['formulation'], o['setting']),
                      '%s at %s' % (x['formulation'], x['setting']))
            if label in md and md[label] != chosen:
                print('note: %s %s: PEER.md chose %s, here %s' % (label + (md[label], chosen)),
                      flush=True)
            key = (case, o['formulation'], o['setting'], x['setting'])
            if key not in pairs:
                pairs[key] = dict(ours_sweep=o['cpu_median'], theirs_sweep=x['cpu_median'],
                                  ours_error={}, theirs_error={})
            cells.append(dict(case=case, output=output, target=t, key=key,
                              ours_error=o['error'], theirs_error=x['error'],
                              sweep_ratio=o['cpu_median'] / x['cpu_median']))

    # the cost of each pair's rounds, from the sweep's medians
    plan, skipped, estimate = [], [], 0.0
    for key, pr in pairs.items():
        o, x = pr['ours_sweep'], pr['theirs_sweep']
        ours_round = o * (1 + (batch(o) if o < MIN_SAMPLE else 0)) + SUBPROCESS_OVERHEAD
        round_s = ours_round + x * batch(x)
        if round_s > a.skip:
            skipped.append((key, round_s))
            continue
        n = a.repeats if round_s <= a.long else min(3, a.repeats)
        plan.append((key, n))
        estimate += n * round_s
    print('%d cells, %d pairs of runs, %d left out; estimated %.0f s' % (
        len(cells), len(pairs), len(skipped), estimate), flush=True)
    for key, s in skipped:
        print('  left out (a round would take %.0f s): %s' % (s, key), flush=True)

    load0, wall0, date = os.getloadavg(), time.time(), time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    results = {}
    for key, n in plan:
        case, formulation, setting, xsetting = key
        xb = batch(pairs[key]['theirs_sweep'])
        ours_s, theirs_s, ratios, info_o, info_x = [], [], [], None, None
        for _ in range(n):
            r = run_ours(case, formulation, setting)
            c, res = run_theirs(case, xsetting, xb)
            ours_s.append(r['cpu'])
            theirs_s.append(c)
            ratios.append(r['cpu'] / c)
            info_o, info_x = r, res
        ne, h, rho = exudyn_args(case, xsetting)
        _, mbs, _ = ec.build(case, ne)
        info_x = dict(info_x.info, steps=info_x.steps, ae_size=mbs.systemData.AEsize())
        results[key] = dict(ours=ours_s, theirs=theirs_s, ratios=ratios, info_ours=info_o,
                            info_theirs=info_x)
        print('%-10s %-28s %-38s | %-32s ours %.4f s exudyn %.4f s ratio %.2f (%.2f-%.2f)' % (
            case, formulation, setting, xsetting, statistics.median(ours_s),
            statistics.median(theirs_s), statistics.median(ratios), min(ratios), max(ratios)),
            flush=True)
    load1, wall = os.getloadavg(), time.time() - wall0

    os.makedirs(a.output, exist_ok=True)
    cols = ['case', 'output', 'target', 'ratio_median', 'ratio_min', 'ratio_max', 'rounds',
            'sweep_ratio', 'ours_formulation', 'ours_setting', 'ours_cpu_median', 'ours_error',
            'ours_steps', 'ours_rejected', 'ours_newton', 'ours_jacobians', 'ours_n', 'ours_m',
            'ours_sparse', 'exudyn_setting', 'exudyn_cpu_median', 'exudyn_error', 'exudyn_steps',
            'exudyn_newton', 'exudyn_jacobians', 'exudyn_ode2', 'exudyn_ae']
    rows = []
    for c in cells:
        r = results.get(c['key'])
        case, formulation, setting, xsetting = c['key']
        row = dict(case=c['case'], output=c['output'], target='%.0e' % c['target'],
                   sweep_ratio='%.2f' % c['sweep_ratio'], ours_formulation=formulation,
                   ours_setting=setting, ours_error='%.2e' % c['ours_error'],
                   exudyn_setting=xsetting, exudyn_error='%.2e' % c['theirs_error'])
        if r is not None:
            o, x = r['info_ours'], r['info_theirs']
            row.update(ratio_median='%.2f' % statistics.median(r['ratios']),
                       ratio_min='%.2f' % min(r['ratios']), ratio_max='%.2f' % max(r['ratios']),
                       rounds=len(r['ratios']),
                       ours_cpu_median='%.4f' % statistics.median(r['ours']),
                       ours_steps=o['steps'], ours_rejected=o['rejected'],
                       ours_newton=o['newton_iterations'], ours_jacobians=o['jacobians'],
                       ours_n=o['n'], ours_m=o['m'], ours_sparse=o['sparse'],
                       exudyn_cpu_median='%.4f' % statistics.median(r['theirs']),
                       exudyn_steps=x['steps'], exudyn_newton=x.get('newton_iterations', ''),
                       exudyn_jacobians=x.get('jacobians', ''), exudyn_ode2=x['ode2_size'],
                       exudyn_ae=x['ae_size'])
        else:
            row.update(ratio_median='left out')
        rows.append(row)
    with open(os.path.join(a.output, 'interleaved.csv'), 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for row in rows:
            w.writerow(row)

    md_lines = [
        '# The peer table, timed interleaved',
        '',
        '%s; %d pairs of runs, ours and Exudyn\'s in turns; %.0f s wall; load average %.2f at '
        'the start, %.2f at the end (1 min).' % (date, len(results), wall, load0[0], load1[0]),
        '',
        'Median of the rounds\' ratios ours / Exudyn\'s (least-largest, rounds); in brackets the '
        'ratio of `make bench-peer` (two phases).',
        '',
        '| case, output | ' + ' | '.join('%.0e' % t for t in TARGETS) + ' |',
        '|---|' + '---|' * len(TARGETS),
    ]
    for case, output in keys:
        if wanted and case not in wanted:
            continue
        line = '| %s %s |' % (case, output)
        for t in TARGETS:
            row = next((r for r in rows if (r['case'], r['output'], r['target']) ==
                        (case, output, '%.0e' % t)), None)
            if row is None:
                line += ' - |'
            elif row['ratio_median'] == 'left out':
                line += ' left out (%s) |' % row['sweep_ratio']
            else:
                line += ' %s (%s-%s, %s) [%s] |' % (row['ratio_median'], row['ratio_min'],
                                                   row['ratio_max'], row['rounds'],
                                                   row['sweep_ratio'])
        md_lines.append(line)
    md_lines += ['', '## The runs', '',
                 '| case, output | target | ours | CPU s | steps (refused) | Newton | matrices '
                 '| n + m | Exudyn | CPU s | steps | Newton | Jacobians | n + m |',
                 '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|']
    for row in rows:
        if row['ratio_median'] == 'left out':
            continue
        md_lines.append('| %s %s | %s | %s at %s | %s | %s (%s) | %s | %s | %s + %s%s | %s | %s '
                        '| %s | %s | %s | %s + %s |' % (
                            row['case'], row['output'], row['target'], row['ours_formulation'],
                            row['ours_setting'], row['ours_cpu_median'], row['ours_steps'],
                            row['ours_rejected'], row['ours_newton'], row['ours_jacobians'],
                            row['ours_n'], row['ours_m'], ' sparse' if row['ours_sparse'] else '',
                            row['exudyn_setting'], row['exudyn_cpu_median'], row['exudyn_steps'],
                            row['exudyn_newton'], row['exudyn_jacobians'], row['exudyn_ode2'],
                            row['exudyn_ae']))
    with open(os.path.join(a.output, 'INTERLEAVED.md'), 'w') as f:
        f.write('\n'.join(md_lines) + '\n')
    print('\n'.join(md_lines))
    print('wrote %s and interleaved.csv' % os.path.join(a.output, 'INTERLEAVED.md'))


if __name__ == '__main__':
    main()
