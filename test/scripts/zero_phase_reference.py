#!/usr/bin/env python3
"""joint_loads on positions only against an independently written pipeline.

The reference is scipy.signal.butter (second-order sections) run forward and backward by
scipy.signal.sosfiltfilt, with the end treatment, resampling and differentiation that
docs/studies/zero_phase.md defines written here again in numpy, and the inverse dynamics of the
planar arm (test/data/urdf/planar_arm.urdf) written here in closed form. Positions-only
CSVs are built here (regular and jittered stamps with a gap, a wrench and a force plate),
joint_loads smooths them (--write-kinematics) and computes the loads, and every number is
compared:

  - the smoothed q, qd, qdd and the filtered wrench and plate columns, to 1e-9 of each
    column's largest magnitude (at least 1);
  - the efforts of the three joints, to 1e-9 of their largest magnitude (at least 1 N m);
  - with --cutoff auto, the cutoff chosen by each rule satisfies that rule as written here
    (the residual equals the noise line's intercept; the GCV score is at a minimum).

Exit status 0 when everything agrees, 1 otherwise (the test test_zero_phase_reference runs
this script and fails with it). Prints the largest relative difference of every check.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy import signal

TOLERANCE = 1e-9

# planar_arm.urdf, read by hand: per moving link, mass, centre of mass in the link frame,
# izz; joint origins; the tool frame. Every axis is z, gravity along -z does no work.
L1_MASS, L1_COM, L1_IZZ = 2.0, np.array([0.2, 0.0]), 0.055
L3_MASS, L3_COM, L3_IZZ = 1.0, np.array([0.15, 0.01]), 0.021
J2_ORIGIN, J3_ORIGIN, J3_YAW, TOOL = np.array([0.4, 0.0]), np.array([0.05, 0.0]), 0.5, np.array(
    [0.3, 0.0])


# --- the smoother (docs/studies/zero_phase.md) ------------------------------------------------
def padding_of(order, samples, padding=0):
    return min(max(2, padding if padding > 0 else 3 * (order + 1)), samples - 1)


def filtfilt_padded(x, fc, fs, order, pad):
    """One channel on a uniform grid: the line through the ends out, scipy's odd-padded
    forward-backward filter, the line back in; the padded output."""
    sos = signal.butter(order, fc, btype="low", fs=fs, output="sos")
    n = len(x)
    line = x[0] + (x[-1] - x[0]) * np.arange(-pad, n + pad) / (n - 1)
    d = x - line[pad:pad + n]
    # scipy's own padding (odd, padlen) gives the middle; the ends' neighbours come from
    # the same extension written out and filtered without further padding.
    middle = signal.sosfiltfilt(sos, d, padtype="odd", padlen=pad)
    ext = np.concatenate([2 * d[0] - d[pad:0:-1], d, 2 * d[-1] - d[-2:-pad - 2:-1]])
    y = signal.sosfiltfilt(sos, ext, padlen=0)
    assert np.max(np.abs(y[pad:pad + n] - middle)) <= 1e-12 * max(1.0, np.max(np.abs(d)))
    return y + line


def derivatives(y, pad, h):
    """5-point central differences at the unpadded samples."""
    n = len(y) - 2 * pad
    s = lambda d: y[pad + d:pad + d + n]
    rate = (s(-2) - 8 * s(-1) + 8 * s(1) - s(2)) / (12 * h)
    accel = (-s(-2) + 16 * s(-1) - 30 * s(0) + 16 * s(1) - s(2)) / (12 * h * h)
    return s(0), rate, accel


def grid_of(t):
    median = np.median(np.diff(t))
    m = max(2, int(np.floor((t[-1] - t[0]) / median + 0.5)))
    h = (t[-1] - t[0]) / m
    grid = t[0] + np.arange(m + 1) * h
    uniform = m + 1 == len(t) and bool(np.all(np.abs(t - grid) <= 1e-4 * h))
    return grid, h, uniform


def to_grid(t, x, grid):
    g = grid.copy()
    g[-1] = t[-1]
    return np.column_stack([np.interp(g, t, x[:, c]) for c in range(x.shape[1])])


def interval(t, grid, h):
    k = np.clip(np.floor((t - grid[0]) / h).astype(int), 0, len(grid) - 2)
    return k, (t - (grid[0] + k * h)) / h


def smooth(t, x, fc, order, derivs=True):
    """q (or forces, derivs False) smoothed at the stamps t: value[, rate, accel]."""
    grid, h, uniform = grid_of(t)
    xg = x if uniform else to_grid(t, x, grid)
    pad = padding_of(order, len(grid))
    cols = [derivatives(filtfilt_padded(xg[:, c], fc, 1.0 / h, order, pad), pad, h)
            for c in range(x.shape[1])]
    v, r, a = (np.column_stack([c[i] for c in cols]) for i in range(3))
    if uniform:
        return (v, r, a) if derivs else v
    k, s = interval(t, grid, h)
    s = s[:, None]
    if not derivs:
        return (1 - s) * v[k] + s * v[k + 1]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, 3 * s**2 - 2 * s**3, s**3 - s**2
    herm = lambda y, d: h00 * y[k] + h10 * h * d[k] + h01 * y[k + 1] + h11 * h * d[k + 1]
    return herm(v, r), herm(r, a), (1 - s) * a[k] + s * a[k + 1]


# --- the automatic cutoffs, written again ---------------------------------------------
def margin_of(t):
    """[s] left out of the residual at each end: 2 / w_lo samples, at most a quarter."""
    grid, h, _ = grid_of(t)
    m = len(grid) - 1
    w_lo = max(1e-3, 1.0 / m)
    return h * min(int(np.ceil(2.0 / w_lo)), (m + 1) // 4)


def mean_square_residual(t, x, w, order, margin):
    """Against the samples at their stamps: the grid's smoothed value interpolated back."""
    s = smooth(t, x, w / grid_of(t)[1], order, derivs=False)
    inner = (t - t[0] >= margin) & (t[-1] - t >= margin)
    return np.mean((x - s)[inner]**2)


def residual_rule_error(t, x, fc, order):
    """|R(fc) - a| / a, a the intercept of the line fitted to R over 0.2 .. 0.4 fs."""
    h, m = grid_of(t)[1], margin_of(t)
    ws = 0.2 + 0.025 * np.arange(9)
    r = np.array([np.sqrt(mean_square_residual(t, x, w, order, m)) for w in ws])
    slope, intercept = np.polyfit(ws, r, 1)
    return abs(np.sqrt(mean_square_residual(t, x, fc * h, order, m)) - intercept) / intercept


def gcv(t, x, w, order, margin):
    n = len(grid_of(t)[0])
    ratio = np.tan(np.pi * np.arange(n) / n) / np.tan(np.pi * w)
    dof = 1 - np.sum(1 / (1 + ratio**(2 * order))) / n
    return mean_square_residual(t, x, w, order, margin) / dof**2


def gcv_rule_excess(t, x, fc, order):
    """How much lower the GCV score is 1 % either side of fc (<= 0 at a minimum)."""
    h, m = grid_of(t)[1], margin_of(t)
    at = gcv(t, x, fc * h, order, m)
    return max((at - gcv(t, x, fc * h * f, order, m)) / at for f in (0.99, 1.01))


# --- the planar arm's inverse dynamics -----------------------------------------------
def apply(phi, v):
    """R(phi) v for every sample: (n, 2)."""
    c, s = np.cos(phi), np.sin(phi)
    return np.column_stack([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def perp(v):
    return np.column_stack([-v[:, 1], v[:, 0]])


def cross_z(r, f):
    return r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]


def efforts(q, qd, qdd, wrench):
    """tau_1..3: sum over the links beyond the joint of (c - p) x m a + izz alpha, minus
    the tool wrench's moment about the joint (wrench in the tool frame, as l3's)."""
    phi = [q[:, 0], q[:, 0] + q[:, 1], q[:, 0] + q[:, 1] + J3_YAW + q[:, 2]]
    w = [qd[:, 0], qd[:, 0] + qd[:, 1], qd[:, 0] + qd[:, 1] + qd[:, 2]]
    al = [qdd[:, 0], qdd[:, 0] + qdd[:, 1], qdd[:, 0] + qdd[:, 1] + qdd[:, 2]]
    # Points as sums of rotated vectors: position, velocity and acceleration.
    def point(terms):
        p = sum(apply(phi[i], v) for i, v in terms)
        a = sum(al[i][:, None] * perp(apply(phi[i], v)) - (w[i]**2)[:, None] * apply(phi[i], v)
                for i, v in terms)
        return p, a
    p1 = np.zeros((len(q), 2))
    p2, _ = point([(0, J2_ORIGIN)])
    p3, _ = point([(0, J2_ORIGIN), (1, J3_ORIGIN)])
    c1, a1 = point([(0, L1_COM)])
    c3, a3 = point([(0, J2_ORIGIN), (1, J3_ORIGIN), (2, L3_COM)])
    xt, _ = point([(0, J2_ORIGIN), (1, J3_ORIGIN), (2, TOOL)])
    f_world = apply(phi[2], wrench[:, 0:2].T)
    tau = []
    for j, p in enumerate([p1, p2, p3]):
        t = L3_MASS * cross_z(c3 - p, a3) + L3_IZZ * al[2]
        if j == 0:
            t = t + L1_MASS * cross_z(c1 - p, a1) + L1_IZZ * al[0]
        tau.append(t - cross_z(xt - p, f_world) - wrench[:, 5])
    return np.column_stack(tau)


# --- the scenes and the comparison ----------------------------------------------------
def scene(jitter, gap, seed):
    rng = np.random.default_rng(seed)
    fs, n = 200.0, 600
    dt = np.full(n - 1, 1 / fs) * (1 + (rng.uniform(-0.3, 0.3, n - 1) if jitter else 0))
    if gap:
        dt[300] = 5 / fs
    t = 0.25 + np.concatenate([[0], np.cumsum(dt)])
    q = np.column_stack([0.4 * np.sin(2 * np.pi * 0.8 * t) + 0.3 * t,
                         -0.6 + 0.5 * np.cos(2 * np.pi * 1.3 * t),
                         0.2 * np.sin(2 * np.pi * 2.1 * t + 0.4)])
    q += 5e-4 * rng.standard_normal(q.shape)
    wrench = np.column_stack([3 * np.sin(2 * np.pi * 1.1 * t), -2 + np.cos(t), 0.5 * t,
                              0.1 * np.sin(t), -0.2 * t, 0.3 * np.cos(2 * np.pi * 0.7 * t)])
    wrench += 0.05 * rng.standard_normal(wrench.shape)
    plate = np.column_stack([np.sin(t), np.cos(t), 150 + 100 * np.sin(2 * np.pi * t),
                             2 * np.sin(t), -3 * np.cos(t), 0.5 * t])
    plate += 0.5 * rng.standard_normal(plate.shape)
    return t, q, wrench, plate


def write_csv(path, t, q, wrench, plate):
    names = ["t"] + ["j%d.q" % (i + 1) for i in range(3)]
    names += ["wrench@tool." + c for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    if plate is not None:
        names += ["plate@p." + c for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    cols = [t[:, None], q, wrench] + ([plate] if plate is not None else [])
    np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(names), comments="",
               fmt="%.17g")


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(names)}


def relative(a, b):
    return np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b)))


def run_case(args, tmp, name, jitter, gap, plate, cutoff):
    t, q, wrench, plate_cols = scene(jitter, gap, seed=len(name))
    states = os.path.join(tmp, name + ".csv")
    kin, loads = os.path.join(tmp, name + "_kin.csv"), os.path.join(tmp, name + "_loads.csv")
    write_csv(states, t, q, wrench, plate_cols if plate else None)
    cmd = [args.joint_loads, "--urdf", args.urdf, "--input", states, "--output", loads,
           "--write-kinematics", kin] + cutoff
    if plate:
        cmd += ["--plate", "p=l3,0.1,0.2,0"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        print("%s: joint_loads failed: %s" % (name, run.stderr.strip()))
        return False
    fc = float(run.stderr.split("cutoff ")[1].split(" Hz")[0])
    order = 4
    k, l = read_csv(kin), read_csv(loads)
    v, r, a = smooth(t, q, fc, order)
    worst = {}
    for i in range(3):
        j = "j%d" % (i + 1)
        worst[j + ".q"] = relative(k[j + ".q"], v[:, i])
        worst[j + ".qd"] = relative(k[j + ".qd"], r[:, i])
        worst[j + ".qdd"] = relative(k[j + ".qdd"], a[:, i])
    fw = smooth(t, wrench, fc, order, derivs=False)
    for c, comp in enumerate(("fx", "fy", "fz", "mx", "my", "mz")):
        worst["wrench." + comp] = relative(k["wrench@tool." + comp], fw[:, c])
    ok = True
    if plate:
        fp = smooth(t, plate_cols, fc, order, derivs=False)
        for c, comp in enumerate(("fx", "fy", "fz", "mx", "my", "mz")):
            worst["plate." + comp] = relative(k["plate@p." + comp], fp[:, c])
    else:
        tau = efforts(v, r, a, fw)
        for i in range(3):
            worst["j%d.effort" % (i + 1)] = relative(l["j%d.effort" % (i + 1)], tau[:, i])
    key = max(worst, key=worst.get)
    print("%-22s cutoff %.6g Hz: largest relative difference %.2e (%s)" %
          (name, fc, worst[key], key))
    ok = worst[key] <= TOLERANCE
    if "residual" in cutoff:
        e = residual_rule_error(t, q, fc, order)
        print("%-22s residual rule: |R(fc) - a| / a = %.2e" % (name, e))
        ok = ok and e <= 1e-6
    if "gcv" in cutoff:
        e = gcv_rule_excess(t, q, fc, order)
        print("%-22s GCV rule: score 1 %% away lower by %.2e (<= 0 at a minimum)" % (name, e))
        ok = ok and e <= 1e-9
    return ok


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--joint-loads", required=True)
    parser.add_argument("--urdf", required=True, help="test/data/urdf/planar_arm.urdf")
    args = parser.parse_args()
    cases = [
        ("regular_6hz", False, False, False, ["--cutoff", "6"]),
        ("jittered_gap_6hz", True, True, False, ["--cutoff", "6"]),
        ("regular_plate_4hz", False, False, True, ["--cutoff", "4"]),
        ("jittered_plate_residual", True, False, True, ["--cutoff-rule", "residual"]),
        ("regular_gcv", False, False, False, ["--cutoff-rule", "gcv"]),
        ("jittered_gap_default", True, True, False, ["--cutoff", "auto"]),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        results = [run_case(args, tmp, *case) for case in cases]
    print("zero_phase_reference: %d of %d cases agree" % (sum(results), len(results)))
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
