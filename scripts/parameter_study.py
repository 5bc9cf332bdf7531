#!/usr/bin/python3
"""Laser-odometry parameter study (the thesis's DE population / generations and NDT cell-size studies).

    scripts/parameter_study.py --dataset NAME BAG TRUTH [--dataset ...] [--out DIR] [--full] [--jobs N]
                               [--seeds N] [--dpslam-offline CMD] [--from-results]

Normally run through scripts/parameter_study.sh, which builds the workspace, simulates the default bag and
sources the workspace (dpslam_offline is run as `rosrun laser_dpslam dpslam_offline` unless
--dpslam-offline says otherwise).

For every dataset and setting: writes DIR/NAME/SETTING/config.yaml (only the studied keys; everything else
keeps config/laser_odometry.yaml's defaults), runs `dpslam_offline --bag BAG --out ... --odometry-only
--config config.yaml --quiet`, then tools/evaluate_trajectory against TRUTH (SE(2)-aligned ATE, drift in %
of the distance, RPE per metre), once per DE seed 1..N (--seeds, default 3: single runs of this odometry
differ a lot from seed to seed, so the table shows medians over the seeds and the worst drift). Settings
(default: one factor at a time around the defaults NP 20, G 30, cells [1.0, 0.5], saliency, plus the full NP x G grid):
  NP in {10, 20, 40} x G in {10, 20, 30, 50}         (cells [1.0, 0.5], saliency)
  cells in {[0.5], [1.0], [2.0, 1.0, 0.5]}           (NP 20, G 30, saliency)
  resampling uniform                                  (NP 20, G 30, cells [1.0, 0.5])
--full runs the whole factorial design instead (3 x 4 x 4 x 2 = 96 runs per dataset).
Writes DIR/table.md, DIR/results.json and DIR/parameter_study.png.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
EVALUATE = os.path.join(REPO, 'tools', 'evaluate_trajectory')

POPULATIONS = (10, 20, 40)
GENERATIONS = (10, 20, 30, 50)
CELL_SETS = ((1.0, 0.5), (0.5,), (1.0,), (2.0, 1.0, 0.5))
RESAMPLINGS = ('saliency', 'uniform')
DEFAULT = {'de_population': 20, 'de_generations': 30, 'ndt_cell_sizes': (1.0, 0.5), 'resampling': 'saliency'}


def setting(np_, g, cells, resampling):
    return {'de_population': np_, 'de_generations': g, 'ndt_cell_sizes': tuple(cells), 'resampling': resampling}


def settings(full):
    if full:
        return [setting(p, g, c, r) for r in RESAMPLINGS for c in CELL_SETS for p in POPULATIONS for g in GENERATIONS]
    out = [setting(p, g, DEFAULT['ndt_cell_sizes'], 'saliency') for p in POPULATIONS for g in GENERATIONS]
    out += [setting(20, 30, c, 'saliency') for c in CELL_SETS[1:]]
    out += [setting(20, 30, DEFAULT['ndt_cell_sizes'], 'uniform')]
    return out


def cells_str(cells):
    return '[' + ', '.join('%g' % c for c in cells) + ']'


def name_of(s):
    return 'np%d_g%d_cells%s_%s' % (s['de_population'], s['de_generations'],
                                     '-'.join('%g' % c for c in s['ndt_cell_sizes']), s['resampling'])


def run_one(dpslam_cmd, dataset, bag, truth, out_dir, s, seed):
    d = os.path.join(out_dir, dataset, name_of(s), 'seed%d' % seed)
    os.makedirs(d, exist_ok=True)
    cfg = os.path.join(d, 'config.yaml')
    with open(cfg, 'w') as f:
        f.write('# parameter_study.py setting %s\n' % name_of(s))
        f.write('de_population: %d\nde_generations: %d\nndt_cell_sizes: %s\nresampling: %s\n'
                % (s['de_population'], s['de_generations'], cells_str(s['ndt_cell_sizes']), s['resampling']))
    row = dict(s, dataset=dataset, bag=bag, truth=truth, seed=seed, dir=d, ok=False)
    for stale in ('stats.json', 'odometry.tum'):
        if os.path.exists(os.path.join(d, stale)):
            os.remove(os.path.join(d, stale))
    t0 = time.time()
    with open(os.path.join(d, 'stderr.txt'), 'w') as err:
        p = subprocess.run(dpslam_cmd + ['--bag', bag, '--out', d, '--odometry-only', '--config', cfg, '--quiet',
                                         '--seed', str(seed)],
                           stdout=subprocess.DEVNULL, stderr=err)
    row['run_s'] = time.time() - t0
    if p.returncode != 0:
        row['error'] = 'dpslam_offline exit %d (see %s)' % (p.returncode, os.path.join(d, 'stderr.txt'))
        return row
    with open(os.path.join(d, 'stats.json')) as f:
        st = json.load(f)
    row.update(scans=st.get('scans'), median_ms=st['odometry_ms']['median'], p95_ms=st['odometry_ms']['p95'],
               bad_match_percent=st.get('bad_match_percent'), wall_s=st.get('wall_s'))
    p = subprocess.run(['/usr/bin/python3', EVALUATE, '--estimate', os.path.join(d, 'odometry.tum'),
                        '--reference', truth], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    if p.returncode != 0:
        row['error'] = 'evaluate_trajectory: %s' % p.stderr.strip()
        return row
    ev = json.loads(p.stdout)
    with open(os.path.join(d, 'evaluation.json'), 'w') as f:
        f.write(p.stdout)
    row.update(ate_rmse_m=ev['ate_rmse_m'], ate_max_m=ev['ate_max_m'], drift_percent=ev['drift_percent'],
               rpe_trans_per_m=ev['rpe_trans_per_m'], rpe_rot_deg_per_m=ev['rpe_rot_deg_per_m'],
               distance_m=ev['distance_m'], ok=True)
    return row


def fmt(v, spec):
    return '—' if v is None else spec % v


def is_default(r):
    return all(r[k] == v for k, v in DEFAULT.items())


def median(values):
    v = sorted(x for x in values if x is not None)
    if not v:
        return None
    m = len(v) // 2
    return v[m] if len(v) % 2 else 0.5 * (v[m - 1] + v[m])


def aggregate(rows):
    """One entry per (dataset, setting): medians over the seeds, and the worst drift."""
    groups = {}
    for r in rows:
        key = (r['dataset'], name_of(r))
        groups.setdefault(key, []).append(r)
    out = []
    for key, rs in groups.items():
        ok = [r for r in rs if r.get('ok')]
        a = {k: rs[0][k] for k in ('dataset', 'de_population', 'de_generations', 'ndt_cell_sizes', 'resampling')}
        a.update(runs=len(rs), ok_runs=len(ok), errors=[r.get('error') for r in rs if not r.get('ok')])
        for k in ('ate_rmse_m', 'drift_percent', 'rpe_trans_per_m', 'rpe_rot_deg_per_m', 'bad_match_percent',
                  'median_ms', 'p95_ms', 'distance_m', 'scans'):
            a[k] = median(r.get(k) for r in ok)
        a['worst_drift_percent'] = max((r['drift_percent'] for r in ok if r['drift_percent'] is not None),
                                       default=None)
        out.append(a)
    return out


def write_table(path, rows, datasets, full, jobs, seeds, elapsed):
    agg = aggregate(rows)
    lines = ['# Laser-odometry parameter study', '',
             'Generated by `scripts/parameter_study.sh` (%s design, DE seeds %s, %d run%s at a time, %.0f s in '
             'all). Each row is the median over the seeds. Errors from `tools/evaluate_trajectory` against the '
             'ground truth: ATE = RMSE of the positions after the SE(2) least-squares alignment; drift = final '
             'position error / distance travelled x 100 with the first poses aligned (worst = the largest over '
             'the seeds); RPE = translation error per metre over 1 m segments. Time = CPU ms per scan of the '
             'laser odometry (median, p95) from `stats.json`; bad %% = share of weak or degenerate matches. '
             'Timings were taken on a shared 2-core machine (other builds running) and are noisy (roughly '
             '+-20 %%); compare errors more than times. **Bold** = the defaults of `config/laser_odometry.yaml`.'
             % ('full factorial' if full else 'one-factor-at-a-time + NP x G grid', ', '.join(map(str, seeds)),
                jobs, 's' if jobs > 1 else '', elapsed), '']
    for name, bag, truth in datasets:
        rs = [r for r in agg if r['dataset'] == name]
        dist = next((r['distance_m'] for r in rs if r['distance_m']), None)
        scans = next((r['scans'] for r in rs if r['scans']), None)
        lines += ['## %s' % name, '', 'bag `%s`, truth `%s`%s' % (
            os.path.relpath(bag, REPO), os.path.relpath(truth, REPO),
            (', %.1f m travelled, %d scans' % (dist, scans)) if dist else ''), '',
            '| NP | G | NDT cells [m] | resampling | ATE RMSE [m] | drift [%] | worst drift [%] | RPE [m/m] '
            '| RPE [deg/m] | bad [%] | median [ms] | p95 [ms] |',
            '|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|']
        for r in rs:
            b = '**' if is_default(r) else ''
            if r['ok_runs']:
                cols = [fmt(r['ate_rmse_m'], '%.3f'), fmt(r['drift_percent'], '%.2f'),
                        fmt(r['worst_drift_percent'], '%.2f'), fmt(r['rpe_trans_per_m'], '%.4f'),
                        fmt(r['rpe_rot_deg_per_m'], '%.3f'), fmt(r['bad_match_percent'], '%.1f'),
                        fmt(r['median_ms'], '%.2f'), fmt(r['p95_ms'], '%.2f')]
                if r['ok_runs'] < r['runs']:
                    cols[0] += ' (%d of %d runs failed)' % (r['runs'] - r['ok_runs'], r['runs'])
            else:
                cols = ['failed: %s' % r['errors'][0]] + [''] * 7
            lines.append('| %s%d%s | %s%d%s | %s%s%s | %s%s%s | %s |' % (
                b, r['de_population'], b, b, r['de_generations'], b, b, cells_str(r['ndt_cell_sizes']), b,
                b, r['resampling'], b, ' | '.join(cols)))
        lines.append('')
    with open(path, 'w') as f:
        f.write('\n'.join(lines))


def plot(path, rows, datasets):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    agg = aggregate(rows)
    n = len(datasets)
    fig, axes = plt.subplots(n, 4, figsize=(18, 3.8 * n), squeeze=False)
    for k, (name, _, _) in enumerate(datasets):
        rs = [r for r in agg if r['dataset'] == name and r['ok_runs']]
        grid = [r for r in rs if r['ndt_cell_sizes'] == DEFAULT['ndt_cell_sizes'] and r['resampling'] == 'saliency']
        for col, key, label in ((0, 'ate_rmse_m', 'ATE RMSE [m]'), (1, 'drift_percent', 'drift [% of distance]'),
                                (2, 'median_ms', 'median CPU per scan [ms]')):
            ax = axes[k][col]
            for np_ in POPULATIONS:
                pts = sorted((r['de_generations'], r[key]) for r in grid if r['de_population'] == np_)
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], 'o-', label='NP %d' % np_)
            ax.set_xlabel('DE generations G')
            ax.set_ylabel(label)
            ax.set_title('%s: cells [1, 0.5] m, saliency (median over seeds)' % name, fontsize=9)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
        ax = axes[k][3]
        variants = [r for r in rs if r['de_population'] == 20 and r['de_generations'] == 30]
        variants.sort(key=lambda r: (r['resampling'] != 'saliency', CELL_SETS.index(r['ndt_cell_sizes'])
                                     if r['ndt_cell_sizes'] in CELL_SETS else 99))
        labels = ['%s\n%s' % (cells_str(r['ndt_cell_sizes']), r['resampling']) for r in variants]
        xs = range(len(variants))
        ax.bar(xs, [r['ate_rmse_m'] for r in variants], color='steelblue')
        for x, r in zip(xs, variants):
            ax.annotate('%.2f ms' % r['median_ms'], (x, r['ate_rmse_m']), ha='center', va='bottom', fontsize=7)
        ax.set_xticks(list(xs))
        ax.set_xticklabels(labels, fontsize=7)
        ax.set_ylabel('ATE RMSE [m]')
        ax.set_title('%s: NDT cells / resampling (NP 20, G 30)' % name, fontsize=9)
        ax.grid(True, axis='y', alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0], epilog='\n\n'.join(__doc__.split('\n\n')[1:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--dataset', nargs=3, action='append', default=[], metavar=('NAME', 'BAG', 'TRUTH'))
    p.add_argument('--out', default=os.path.join(REPO, 'out', 'parameter_study'))
    p.add_argument('--full', action='store_true', help='full factorial design (slow)')
    p.add_argument('--jobs', type=int, default=2, help='runs at a time (default 2)')
    p.add_argument('--seeds', type=int, default=3, help='DE seeds 1..N per setting (default 3)')
    p.add_argument('--dpslam-offline', default='rosrun laser_dpslam dpslam_offline', metavar='CMD')
    p.add_argument('--from-results', action='store_true',
                   help='only redraw table.md and the plot from DIR/results.json of an earlier run')
    a = p.parse_args()
    if a.from_results:
        with open(os.path.join(a.out, 'results.json')) as f:
            data = json.load(f)
        rows = [dict(r, ndt_cell_sizes=tuple(r['ndt_cell_sizes'])) for r in data['runs']]
        datasets = []
        for r in rows:
            if r['dataset'] not in [d[0] for d in datasets]:
                datasets.append((r['dataset'], r['bag'], r['truth']))
        write_table(os.path.join(a.out, 'table.md'), rows, datasets, data['full'], data['jobs'], data['seeds'],
                    data['elapsed_s'])
        plot(os.path.join(a.out, 'parameter_study.png'), rows, datasets)
        return 0
    if not a.dataset:
        p.error('at least one --dataset NAME BAG TRUTH is needed')
    datasets = [(n, os.path.abspath(b), os.path.abspath(t)) for n, b, t in a.dataset]
    for n, b, t in datasets:
        for f in (b, t):
            if not os.path.isfile(f):
                p.error('dataset %s: no file %s' % (n, f))
    cmd = shlex.split(a.dpslam_offline)
    os.makedirs(a.out, exist_ok=True)
    seeds = list(range(1, max(1, a.seeds) + 1))
    todo = [(n, b, t, s, seed) for n, b, t in datasets for s in settings(a.full) for seed in seeds]
    rows = [None] * len(todo)
    t0 = time.time()

    def work(i):
        n, b, t, s, seed = todo[i]
        r = run_one(cmd, n, b, t, a.out, s, seed)
        rows[i] = r
        status = ('ATE %.3f m, drift %.2f %%, %.2f ms' % (r['ate_rmse_m'], r['drift_percent'] or 0, r['median_ms'])
                  if r['ok'] else r.get('error'))
        sys.stderr.write('[%d/%d] %s %s seed %d: %s (%.1f s)\n'
                         % (i + 1, len(todo), n, name_of(s), seed, status, r['run_s']))
        return r

    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        list(ex.map(work, range(len(todo))))
    elapsed = time.time() - t0
    with open(os.path.join(a.out, 'results.json'), 'w') as f:
        json.dump({'full': a.full, 'jobs': a.jobs, 'seeds': seeds, 'elapsed_s': elapsed,
                   'runs': [dict(r, ndt_cell_sizes=list(r['ndt_cell_sizes'])) for r in rows]}, f, indent=1)
    write_table(os.path.join(a.out, 'table.md'), rows, datasets, a.full, a.jobs, seeds, elapsed)
    plot(os.path.join(a.out, 'parameter_study.png'), rows, datasets)
    with open(os.path.join(a.out, 'table.md')) as f:
        sys.stdout.write(f.read())
    print('\n(%d runs in %.0f s; outputs in %s: table.md, results.json, parameter_study.png)'
          % (len(rows), elapsed, a.out))
    return 0 if all(r['ok'] for r in rows) else 1


if __name__ == '__main__':
    sys.exit(main())
