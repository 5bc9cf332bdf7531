#!/usr/bin/python3
"""What a loop-closing back end could at best make of a trajectory estimate, given the truth.

Takes keyframes every --keyframe-distance metres of the estimate, links consecutive ones by the estimate's
own motion, and adds an ideal loop closure wherever the true path comes back within --closure-radius of an
earlier keyframe at least --min-separation metres of path before: the true relative pose plus Gaussian
noise (seeded). A pose graph over those (Gauss-Newton, first keyframe fixed) is then scored by ATE after
SE(2) alignment, as tools/evaluate_trajectory scores it. If this bound is far above a target, a back end
alone (pose graph + loop closure) cannot reach the target from that front end: its local accuracy must
improve first. Prints JSON: keyframes, closures, ate_estimate_m (at the keyframes), ate_bound_m.

The odometry edges weigh the same everywhere unless --match-log gives dpslam_offline's match log of the
same run: each edge then carries the odometry's own covariance (its per-scan delta variances summed between
the keyframes), so a correction goes where the odometry was unsure (corridors, a start from rest) instead
of being spread evenly.

Usage: loop_closure_bound.py --estimate odometry.tum --reference ground_truth.tum [--match-log m.csv] [options]
"""
import argparse
import importlib.machinery
import importlib.util
import json
import math
import os
import sys

import numpy as np


def _evaluate_trajectory():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tools', 'evaluate_trajectory')
    loader = importlib.machinery.SourceFileLoader('evaluate_trajectory', path)
    module = importlib.util.module_from_spec(importlib.util.spec_from_loader('evaluate_trajectory', loader))
    loader.exec_module(module)
    return module


ET = _evaluate_trajectory()


def relative(a, b):
    """Pose b in the frame of pose a (x, y, theta)."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return np.array([c * dx + s * dy, -s * dx + c * dy, ET.wrap(b[2] - a[2])])


def optimize(x, edges, iterations=20):
    """Gauss-Newton on SE(2) relative-pose edges (i, j, z, information); x[0] stays fixed."""
    n = len(x)
    x = x.copy()
    for _ in range(iterations):
        H = np.zeros((3 * n, 3 * n))
        b = np.zeros(3 * n)
        for i, j, z, info in edges:
            e = relative(x[i], x[j]) - z
            e[2] = ET.wrap(e[2])
            c, s = math.cos(x[i][2]), math.sin(x[i][2])
            dx, dy = x[j][0] - x[i][0], x[j][1] - x[i][1]
            A = np.array([[-c, -s, -s * dx + c * dy], [s, -c, -c * dx - s * dy], [0.0, 0.0, -1.0]])
            B = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
            for p, Jp in ((i, A), (j, B)):
                b[3 * p:3 * p + 3] += Jp.T @ info @ e
                for q, Jq in ((i, A), (j, B)):
                    H[3 * p:3 * p + 3, 3 * q:3 * q + 3] += Jp.T @ info @ Jq
        H[:3, :3] += 1e12 * np.eye(3)  # gauge: the first keyframe
        step = np.linalg.solve(H, -b).reshape(-1, 3)
        x += step
        if np.abs(step).max() < 1e-9:
            break
    return x


def ate(x, g):
    ang, t = ET.se2_alignment(x[:, 0], x[:, 1], x[:, 2], g[:, 0], g[:, 1], g[:, 2])
    c, s = math.cos(ang), math.sin(ang)
    ax, ay = c * x[:, 0] - s * x[:, 1] + t[0], s * x[:, 0] + c * x[:, 1] + t[1]
    return float(np.sqrt(np.mean((ax - g[:, 0]) ** 2 + (ay - g[:, 1]) ** 2)))


def load_match_log(path):
    """stamp -> diagonal (x, y, theta) variance of that scan's delta (previous base frame), from
    dpslam_offline --match-log."""
    try:
        rows = np.genfromtxt(path, delimiter=',', names=True, dtype=None, encoding=None)
        return {round(float(r['stamp']), 6): (float(r['sxx']), float(r['syy']), float(r['stt'])) for r in np.atleast_1d(rows)}
    except (OSError, ValueError, KeyError) as e:
        raise ET.InputError('%s: not a readable dpslam_offline match log (%s)' % (path, e))


def edge_information(est, first, last, variances):
    """Information of the motion from pose `first` to pose `last`: the per-scan delta covariances in
    between, rotated into the frame of pose `first` and summed."""
    S = np.zeros((3, 3))
    for i in range(first + 1, last + 1):
        a = est[i - 1, 2] - est[first, 2]
        R = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        S += R @ np.diag(variances[i]) @ R.T
    return np.linalg.inv(S + 1e-12 * np.eye(3))


def bound(est_path, ref_path, keyframe_distance=1.0, closure_radius=1.0, min_separation=20.0, closure_every=4,
          odom_sigma=(0.01, 0.002), closure_sigma=(0.01, 0.002), seed=1, match_log=None):
    et, ex, ey, eth = ET.load_tum(est_path, 'estimate')
    rt, rx, ry, rth = ET.load_tum(ref_path, 'reference')
    keep = (et >= rt[0]) & (et <= rt[-1])
    et, ex, ey, eth = et[keep], ex[keep], ey[keep], eth[keep]
    if len(et) < 2:
        raise ET.InputError('fewer than 2 estimate poses within the reference\'s time span')
    est = np.stack([ex, ey, eth], 1)
    ref = np.stack([np.interp(et, rt, rx), np.interp(et, rt, ry), np.interp(et, rt, rth)], 1)

    kf, travelled = [0], 0.0
    for i in range(1, len(et)):
        travelled += math.hypot(est[i, 0] - est[i - 1, 0], est[i, 1] - est[i - 1, 1])
        if travelled >= keyframe_distance:
            kf.append(i)
            travelled = 0.0
    kf = np.array(kf)
    x, g = est[kf], ref[kf]
    info_odom = np.diag([odom_sigma[0] ** -2, odom_sigma[0] ** -2, odom_sigma[1] ** -2])
    info_loop = np.diag([closure_sigma[0] ** -2, closure_sigma[0] ** -2, closure_sigma[1] ** -2])
    if match_log is None:
        edges = [(k, k + 1, relative(x[k], x[k + 1]), info_odom) for k in range(len(kf) - 1)]
    else:
        log = load_match_log(match_log)
        missing = [t for t in et if round(float(t), 6) not in log]
        if missing:
            raise ET.InputError('%s has no line for %d estimate stamps (first %.6f): not the same run?'
                                % (match_log, len(missing), missing[0]))
        variances = [log[round(float(t), 6)] for t in et]
        edges = [(k, k + 1, relative(x[k], x[k + 1]), edge_information(est, kf[k], kf[k + 1], variances))
                 for k in range(len(kf) - 1)]
    path = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(g[:, 0]), np.diff(g[:, 1])))])
    rng = np.random.default_rng(seed)
    closures = 0
    for j in range(len(kf)):
        for i in range(0, j, closure_every):
            if path[j] - path[i] >= min_separation and math.hypot(*(g[i, :2] - g[j, :2])) <= closure_radius:
                noise = rng.normal(0.0, [closure_sigma[0], closure_sigma[0], closure_sigma[1]])
                edges.append((i, j, relative(g[i], g[j]) + noise, info_loop))
                closures += 1
    return {'keyframes': int(len(kf)), 'closures': closures, 'ate_estimate_m': ate(x, g),
            'ate_bound_m': ate(optimize(x, edges), g)}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument('--estimate', required=True, help='TUM trajectory of the front end (e.g. odometry.tum)')
    p.add_argument('--reference', required=True, help='TUM ground truth')
    p.add_argument('--keyframe-distance', type=float, default=1.0, help='m of estimated path between keyframes')
    p.add_argument('--closure-radius', type=float, default=1.0, help='m; true distance of a revisit')
    p.add_argument('--min-separation', type=float, default=20.0, help='m of path before a revisit counts')
    p.add_argument('--seed', type=int, default=1, help='seed of the closures\' noise')
    p.add_argument('--match-log', help='dpslam_offline --match-log of the same run: weight the odometry edges '
                   'by its covariance (default: the same weight everywhere)')
    a = p.parse_args(argv)
    try:
        out = bound(a.estimate, a.reference, a.keyframe_distance, a.closure_radius, a.min_separation, seed=a.seed,
                    match_log=a.match_log)
    except ET.InputError as e:
        print('loop_closure_bound.py: %s' % e, file=sys.stderr)
        return 1
    print(json.dumps(out))
    return 0


if __name__ == '__main__':
    sys.exit(main())
