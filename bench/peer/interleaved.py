"""The peer table of `make bench-peer` timed again, interleaved (issue 34 item 4).

    .venv-bench/bin/python bench/peer/interleaved.py [--repeats 5] [--cells c2,c4_omega4]
        [--margin 1.25] [--candidates 3]

`make bench-peer` runs Exudyn's sweep and ours in two phases, minutes apart, so a change of the
machine's load between them falls on one tool only. This script takes, for every case, output
and target that both tools reach, the runs that set the ratio in build/bench/PEER.md (our
cheapest run and Exudyn's, chosen from build/bench/ours_points.csv and peer_points.csv by the
rule of `fmu-bench peer`: the cheapest median CPU among the runs that meet the target for
good) and those close behind them, and times them again in turns: ours, Exudyn's, ours,
Exudyn's, ... `--repeats` rounds. Each round's ratio ours / Exudyn's is taken; the table gives
the median over the rounds and the least and largest.

The sweeps' choice is itself a median of 3 runs taken minutes apart, and two settings within a
few percent of each other trade places with the load. So each tool's candidates for a cell are
every run that meets the target for good at most `--margin` times the cheapest's sweep median
(at most `--candidates` of them, cheapest first). Every distinct run of a case is timed once a
round, ours and Exudyn's in turns, and serves every cell it is a candidate of (two cells with
the same runs read the same timings); a round's ratio for a cell is the fastest of its
candidates of ours over the fastest of Exudyn's in that round, and the table names, for each
tool, the candidate with the least median over the rounds (the others and their medians in the
runs' table). Both tools are treated alike.

Ours: `target/release/fmu-bench peer-run` in a subprocess, one sample per call (the thread's
CPU time from building the unit to its last step, as `fmu-bench peer` times it; a run shorter
than 0.1 s is timed in a batch and divided). Exudyn's: `exudyn_cases.run` in this process
(process CPU time of SolveSystem alone, as bench/peer/sweep.py times it), a run shorter than
0.1 s also in a batch.

Cost: a case's cells whose cheapest run takes more than 1 s are timed in a group of their own;
a group whose round would take more than --long seconds (from the sweep's medians) gets 3
rounds instead of --repeats; a group whose round would take more than --skip seconds is timed
on the cheapest run of each tool alone, and left out (and listed) if that still would; the
estimate is printed before it starts. With the defaults the whole takes about 5-10 minutes on
a 2-core machine.

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
LONG_CELL = 1.0      # s: cells whose cheapest run takes longer are timed in a group of their own
SUBPROCESS_OVERHEAD = 0.05   # s per call of ours beyond its runs (start, scene, first run)


def read_points(path):
    """A points CSV (ours or the peer's: the same columns) as sweep.py reads it, steps as int."""
    rows = sweep.read_points(path)
    for r in rows:
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


def meeting(points, tool, case, output, target):
    """The runs of `tool` that meet the target for good, cheapest (sweep median) first."""
    runs = [p for p in points if p['tool'] == tool and p['case'] == case
            and p['output'] == output and meets(points, p, target)]
    return sorted(runs, key=lambda p: p['cpu_median'])


def candidates(points, tool, case, output, target, margin, most):
    """The runs within `margin` of the cheapest's sweep median, at most `most`, cheapest first
    (each formulation and setting once)."""
    runs, seen = [], set()
    for p in meeting(points, tool, case, output, target):
        if runs and p['cpu_median'] > margin * runs[0]['cpu_median']:
            break
        name = (p['formulation'], p['setting'])
        if name not in seen:
            seen.add(name)
            runs.append(p)
        if len(runs) == most:
            break
    return runs


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
                    help='a group of runs whose round takes longer (s, from the sweep) gets 3 '
                         'rounds')
    ap.add_argument('--skip', type=float, default=40.0,
                    help='a group whose round takes longer (s, from the sweep) is timed on its '
                         'cheapest runs alone, and left out if that still does')
    ap.add_argument('--cells', default='', help='only these cases, comma-separated')
    ap.add_argument('--margin', type=float, default=1.25,
                    help='candidates: runs meeting the target within this factor of the '
                         'cheapest sweep median (default 1.25; 1 times the cheapest alone)')
    ap.add_argument('--candidates', type=int, default=3,
                    help='at most this many candidates per tool and cell (default 3)')
    ap.add_argument('--points', default=BENCH, help='where ours_points.csv and peer_points.csv are')
    ap.add_argument('--output', default=BENCH)
    a = ap.parse_args()
    if not os.path.exists(FMU_BENCH):
        sys.exit('%s not built (make release)' % FMU_BENCH)
    ours = read_points(os.path.join(a.points, 'ours_points.csv'))
    theirs = read_points(os.path.join(a.points, 'peer_points.csv'))
    md = peer_md_choices(os.path.join(a.points, 'PEER.md'))
    wanted = [c for c in a.cells.split(',') if c]

    # the cells, each with its candidates
    cells, keys = [], []
    for p in ours:
        k = (p['case'], p['output'])
        if k not in keys:
            keys.append(k)
    for case, output in keys:
        if wanted and case not in wanted:
            continue
        for t in TARGETS:
            os_ = candidates(ours, 'fmu-beam', case, output, t, a.margin, a.candidates)
            xs = candidates(theirs, 'exudyn', case, output, t, a.margin, a.candidates)
            if not os_ or not xs:
                continue
            o, x = os_[0], xs[0]
            label = ('%s %s' % (case, output), '%.0e' % t)
            chosen = ('%s at %s' % (o['formulation'], o['setting']),
                      '%s at %s' % (x['formulation'], x['setting']))
            if label in md and md[label] != chosen:
                print('note: %s %s: PEER.md chose %s, here %s' % (label + (md[label], chosen)),
                      flush=True)
            cells.append(dict(
                case=case, output=output, target=t,
                ours=[(p['formulation'], p['setting']) for p in os_],
                theirs=[p['setting'] for p in xs],
                cost={('ours',) + (p['formulation'], p['setting']): p['cpu_median'] for p in os_},
                xcost={p['setting']: p['cpu_median'] for p in xs},
                ours_error={(p['formulation'], p['setting']): p['error'] for p in os_},
                theirs_error={p['setting']: p['error'] for p in xs},
                sweep_ratio=o['cpu_median'] / x['cpu_median']))

    # Every distinct run of a case is timed once a round and serves every cell it is a
    # candidate of, so that two cells with the same runs read the same timings. A case's cells
    # whose cheapest run (either tool) takes more than LONG_CELL are timed in a group of their
    # own, with fewer rounds.
    def round_cost(group):
        ours_round = sum(o * (1 + (batch(o) if o < MIN_SAMPLE else 0)) + SUBPROCESS_OVERHEAD
                         for o in group['ours'].values())
        return ours_round + sum(x * batch(x) for x in group['theirs'].values())

    def grouped(cells):
        groups = {}
        for c in cells:
            slow = max(min(c['cost'].values()), min(c['xcost'].values())) > LONG_CELL
            g = groups.setdefault((c['case'], slow), dict(ours={}, theirs={}, cells=[]))
            for run in c['ours']:
                g['ours'][run] = c['cost'][('ours',) + run]
            for run in c['theirs']:
                g['theirs'][run] = c['xcost'][run]
            g['cells'].append(c)
        return groups

    groups = grouped(cells)
    plan, skipped, estimate = [], [], 0.0
    for gkey, g in list(groups.items()):
        if round_cost(g) > a.skip:
            # the cheapest of each tool alone, for this group's cells
            for c in g['cells']:
                c['ours'], c['theirs'] = c['ours'][:1], c['theirs'][:1]
            g.update(grouped(g['cells'])[gkey])
        round_s = round_cost(g)
        if round_s > a.skip:
            skipped.append((gkey, round_s))
            continue
        n = a.repeats if round_s <= a.long else min(3, a.repeats)
        plan.append((gkey, n))
        estimate += n * round_s
    print('%d cells, %d groups of runs (%d of ours, %d of Exudyn\'s), %d left out; estimated '
          '%.0f s' % (len(cells), len(groups), sum(len(g['ours']) for g in groups.values()),
                      sum(len(g['theirs']) for g in groups.values()), len(skipped), estimate),
          flush=True)
    for gkey, s in skipped:
        print('  left out (a round would take %.0f s): %s' % (s, gkey), flush=True)

    load0, wall0, date = os.getloadavg(), time.time(), time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    results = {}
    runs_o = sum(len(groups[gkey]['ours']) for gkey, _ in plan)
    runs_x = sum(len(groups[gkey]['theirs']) for gkey, _ in plan)
    for gkey, n in plan:
        g, case = groups[gkey], gkey[0]
        os_, xs = list(g['ours']), list(g['theirs'])
        xb = {x: batch(g['theirs'][x]) for x in xs}
        ours_s, theirs_s = {o: [] for o in os_}, {x: [] for x in xs}
        info_o, info_x = {}, {}
        for _ in range(n):
            # ours and Exudyn's in turns
            for i in range(max(len(os_), len(xs))):
                if i < len(os_):
                    r = run_ours(case, *os_[i])
                    ours_s[os_[i]].append(r['cpu'])
                    info_o[os_[i]] = r
                if i < len(xs):
                    c, res = run_theirs(case, xs[i], xb[xs[i]])
                    theirs_s[xs[i]].append(c)
                    info_x[xs[i]] = res
        for cell in g['cells']:
            ratios = [min(ours_s[o][r] for o in cell['ours']) /
                      min(theirs_s[x][r] for x in cell['theirs']) for r in range(n)]
            win_o = min(cell['ours'], key=lambda o: statistics.median(ours_s[o]))
            win_x = min(cell['theirs'], key=lambda x: statistics.median(theirs_s[x]))
            ne, h, rho = exudyn_args(case, win_x)
            _, mbs, _ = ec.build(case, ne)
            res = info_x[win_x]
            results[(case, cell['output'], cell['target'])] = dict(
                ours=ours_s[win_o], theirs=theirs_s[win_x], ratios=ratios, win_o=win_o,
                win_x=win_x, info_ours=info_o[win_o],
                info_theirs=dict(res.info, steps=res.steps, ae_size=mbs.systemData.AEsize()),
                others_o=['%s at %s %.4f' % (o + (statistics.median(ours_s[o]),))
                          for o in cell['ours'] if o != win_o],
                others_x=['%s %.4f' % (x, statistics.median(theirs_s[x]))
                          for x in cell['theirs'] if x != win_x])
            print('%-10s %-18s %.0e %-56s | %-40s ours %.4f s exudyn %.4f s ratio %.2f '
                  '(%.2f-%.2f)%s' % (
                      case, cell['output'], cell['target'], '%s at %s' % win_o, win_x,
                      statistics.median(ours_s[win_o]), statistics.median(theirs_s[win_x]),
                      statistics.median(ratios), min(ratios), max(ratios),
                      ' (of %d and %d)' % (len(cell['ours']), len(cell['theirs']))
                      if len(cell['ours']) + len(cell['theirs']) > 2 else ''), flush=True)
    load1, wall = os.getloadavg(), time.time() - wall0

    os.makedirs(a.output, exist_ok=True)
    cols = ['case', 'output', 'target', 'ratio_median', 'ratio_min', 'ratio_max', 'rounds',
            'sweep_ratio', 'ours_formulation', 'ours_setting', 'ours_cpu_median', 'ours_error',
            'ours_steps', 'ours_rejected', 'ours_newton', 'ours_jacobians', 'ours_n', 'ours_m',
            'ours_sparse', 'exudyn_setting', 'exudyn_cpu_median', 'exudyn_error', 'exudyn_steps',
            'exudyn_newton', 'exudyn_jacobians', 'exudyn_ode2', 'exudyn_ae', 'ours_others',
            'exudyn_others']
    rows = []
    for c in cells:
        r = results.get((c['case'], c['output'], c['target']))
        # the sweep's cheapest where the cell was not timed
        (formulation, setting), xsetting = c['ours'][0], c['theirs'][0]
        if r is not None:
            (formulation, setting), xsetting = r['win_o'], r['win_x']
        row = dict(case=c['case'], output=c['output'], target='%.0e' % c['target'],
                   sweep_ratio='%.2f' % c['sweep_ratio'], ours_formulation=formulation,
                   ours_setting=setting,
                   ours_error='%.2e' % c['ours_error'][(formulation, setting)],
                   exudyn_setting=xsetting, exudyn_error='%.2e' % c['theirs_error'][xsetting])
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
                       exudyn_ae=x['ae_size'], ours_others='; '.join(r['others_o']),
                       exudyn_others='; '.join(r['others_x']))
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
        '%s; %d cells, their runs (%d of ours, %d of Exudyn\'s) in turns, case by case; %.0f s '
        'wall; load average %.2f at the start, %.2f at the end (1 min). Candidates: each tool\'s '
        'runs that meet the target within %.2f x the cheapest\'s sweep median, at most %d; a '
        'round\'s ratio is the fastest of the cell\'s candidates of ours over the fastest of '
        'Exudyn\'s.' % (date, len(results), runs_o, runs_x, wall, load0[0], load1[0], a.margin,
                         a.candidates),
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
                 '| n + m | Exudyn | CPU s | steps | Newton | Jacobians | n + m | also timed, '
                 'CPU s (ours; Exudyn\'s) |',
                 '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|']
    for row in rows:
        if row['ratio_median'] == 'left out':
            continue
        md_lines.append('| %s %s | %s | %s at %s | %s | %s (%s) | %s | %s | %s + %s%s | %s | %s '
                        '| %s | %s | %s | %s + %s | %s; %s |' % (
                            row['case'], row['output'], row['target'], row['ours_formulation'],
                            row['ours_setting'], row['ours_cpu_median'], row['ours_steps'],
                            row['ours_rejected'], row['ours_newton'], row['ours_jacobians'],
                            row['ours_n'], row['ours_m'], ' sparse' if row['ours_sparse'] else '',
                            row['exudyn_setting'], row['exudyn_cpu_median'], row['exudyn_steps'],
                            row['exudyn_newton'], row['exudyn_jacobians'], row['exudyn_ode2'],
                            row['exudyn_ae'], row['ours_others'] or '-',
                            row['exudyn_others'] or '-'))
    with open(os.path.join(a.output, 'INTERLEAVED.md'), 'w') as f:
        f.write('\n'.join(md_lines) + '\n')
    print('\n'.join(md_lines))
    print('wrote %s and interleaved.csv' % os.path.join(a.output, 'INTERLEAVED.md'))


if __name__ == '__main__':
    main()
