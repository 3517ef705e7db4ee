#!/usr/bin/python3
"""Turns the CSV of bench/accuracy into docs/studies/accuracy.md and the two figures.

usage: plot_accuracy.py ACCURACY.csv --md OUT.md --png-prefix PREFIX [--command TEXT]

Writes OUT.md (the tables), PREFIX_error_vs_time.png and PREFIX_error_vs_delay.png
(RMS effort error against run time per sample and against delay, main scene, with the
Pareto fronts). Needs matplotlib (Debian: python3-matplotlib); run with /usr/bin/python3.
"""
import argparse
import csv
import math
import os
import platform
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from study_page import cpu_name  # noqa: E402

MAIN = "panda"
DELAY_BUDGET_MS = 5.0  # the recommendation: least error with at most this delay
FAMILY_NAMES = {
    "default": "node default",
    "default_smoothed": "node default, smoothed stream",
    "fd": "finite difference",
    "sg causal": "Savitzky-Golay causal",
    "sg centred": "Savitzky-Golay centred",
    "kalman_ca": "Kalman const. acceleration",
    "kalman_cj": "Kalman const. jerk",
    "kalman_cj_smooth": "Kalman smoother const. jerk (lag)",
    "adaptive": "adaptive (Kalman bank)",
    "adaptive_smooth": "adaptive smoother (Kalman bank, lag)",
    "zero_phase": "zero-phase Butterworth (offline)",
}
OFFLINE = "zero_phase"
COLOURS = {
    "default": "tab:brown",
    "default_smoothed": "tab:gray",
    "fd": "tab:red",
    "sg causal": "tab:orange",
    "sg centred": "tab:green",
    "kalman_ca": "tab:blue",
    "kalman_cj": "tab:purple",
    "kalman_cj_smooth": "tab:pink",
    "adaptive": "tab:olive",
    "adaptive_smooth": "tab:cyan",
}
NUMERIC = [
    "window", "order", "delay_samples", "process_noise", "measurement_noise", "samples", "rms_effort", "max_effort",
    "rms_force", "max_force", "rms_moment", "max_moment", "rel_rms_effort", "rel_rms_force",
    "rel_rms_moment", "stamp_lag_ms", "phase_lag_ms", "delay_ms", "time_per_sample_us",
    "cpu_per_sample_us", "rate_hz", "shipped_default", "planar_share", "overshoot", "cutoff_hz",
]


def load(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k in NUMERIC:
                r[k] = float(r[k])
            r["group"] = family(r)
            rows.append(r)
    if not rows:
        sys.exit(f"plot_accuracy: no rows in {path}")
    return rows


def family(r):
    if r["family"] == "sg":
        return "sg centred" if r["delay_samples"] > 0 else "sg causal"
    return r["family"]


def pareto(rows, x_key, y_key="rms_effort"):
    """Rows not dominated in (x, y), both minimised; returned sorted by x."""
    front = []
    for r in sorted(rows, key=lambda r: (r[x_key], r[y_key])):
        if not front or r[y_key] < front[-1][y_key]:
            front.append(r)
    return front


def fmt(x, digits=3):
    if isinstance(x, str):
        return x
    if math.isnan(x):
        return "n/a"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def ms(x):
    return "n/a" if math.isnan(x) else f"{x:.2f}"


def us(x):
    return f"{x:.2f}"


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        out.append("| " + " | ".join(str(c) for c in r) + " |")
    return "\n".join(out) + "\n"


def overall(rows, scene, savings="default", precision=None, offline=False):
    """The scene's ALL rows; online differentiators only, or offline ones only."""
    return [r for r in rows if r["scene"] == scene and r["joint"] == "ALL" and r["savings"] == savings
            and (precision is None or r["precision"] == precision)
            and (r["family"] == OFFLINE) == offline]


def label(r, with_precision=True):
    return r["config"] + (f" ({r['precision']})" if with_precision else "")


def recommend(rows):
    """Among the main scene's configurations (double, default savings) on the error-delay
    Pareto front with at most DELAY_BUDGET_MS of delay, the one whose error is closest to
    the best in every scene (least geometric mean of error / scene's least)."""
    main = [r for r in overall(rows, MAIN, precision="double") if not math.isnan(r["delay_ms"])]
    front = [r for r in pareto(main, "delay_ms") if r["delay_ms"] <= DELAY_BUDGET_MS]
    if not front:
        return None
    score = {c: gm for gm, _, c, _ in robustness(rows)[1]}
    return min(front, key=lambda r: (score.get(r["config"], math.inf), r["rms_effort"]))


def robustness(rows):
    """Per differentiator (double, default savings): the geometric mean and the worst, over
    the noisy scenes, of its RMS effort error divided by the scene's least."""
    scenes = sorted({r["scene"] for r in rows if r["scene"] != "exact" and not r["scene"].endswith("_savings")})
    best = {s: min(r["rms_effort"] for r in overall(rows, s, precision="double")) for s in scenes}
    out = []
    for c in sorted({r["config"] for r in overall(rows, MAIN, precision="double")}):
        ratios = []
        for s in scenes:
            hit = [r for r in overall(rows, s, precision="double") if r["config"] == c]
            if hit and best[s] > 0:
                ratios.append(hit[0]["rms_effort"] / best[s])
        if len(ratios) == len(scenes):
            gm = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
            out.append((gm, max(ratios), c, ratios))
    out.sort()
    return scenes, out


def label_front(fig, ax, front, x_key):
    """Names the Pareto points, each label where it overlaps no earlier one."""
    fig.canvas.draw()  # fixes the scales, so that data map to display points
    to_points = 72.0 / fig.dpi
    placed = []
    offsets = [(6, 4), (6, -11), (-6, 4), (-6, -11), (6, 15), (6, -22), (-6, 15), (-6, -22)]
    for r in front:
        text = label(r)
        x, y = ax.transData.transform((r[x_key], r["rms_effort"]))
        x, y = x * to_points, y * to_points
        width, height = 4.1 * len(text), 8.0
        for dx, dy in offsets:
            left = x + dx if dx > 0 else x + dx - width
            box = (left, y + dy, left + width, y + dy + height)
            if all(box[2] < b[0] or box[0] > b[2] or box[3] < b[1] or box[1] > b[3] for b in placed):
                break
        placed.append(box)
        ax.annotate(text, (r[x_key], r["rms_effort"]), textcoords="offset points",
                    xytext=(dx, dy), fontsize=7, ha="left" if dx > 0 else "right")


def plot(rows, x_key, x_label, path, recommended, log_x):
    fig, ax = plt.subplots(figsize=(9, 7), dpi=110)
    for g, colour in COLOURS.items():
        for precision, marker in (("double", "o"), ("float", "^")):
            pts = [r for r in rows if r["group"] == g and r["precision"] == precision]
            if pts:
                ax.scatter([r[x_key] for r in pts], [r["rms_effort"] for r in pts], c=colour,
                           marker=marker, s=28, alpha=0.75,
                           label=f"{FAMILY_NAMES[g]}, {precision}", edgecolors="none")
    front = pareto(rows, x_key)
    xs, ys = [], []
    for r in front:  # a staircase: each point is as good as it gets up to the next one
        if xs:
            xs.append(r[x_key])
            ys.append(ys[-1])
        xs.append(r[x_key])
        ys.append(r["rms_effort"])
    ax.plot(xs, ys, color="black", lw=1.0, ls="--", label="Pareto front", zorder=1)
    for r in front:
        ax.scatter([r[x_key]], [r["rms_effort"]], s=90, facecolors="none", edgecolors="black")
    if not log_x:
        ax.axvline(DELAY_BUDGET_MS, color="grey", lw=0.8, ls=":")
        ax.text(DELAY_BUDGET_MS, 0.98, f" {DELAY_BUDGET_MS:g} ms budget", color="grey", fontsize=7,
                va="top", transform=ax.get_xaxis_transform())
    ax.set_yscale("log")
    if log_x:
        ax.set_xscale("log")
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
        leading = matplotlib.ticker.FuncFormatter(
            lambda v, _: f"{v:g}" if v > 0 and round(v / 10 ** math.floor(math.log10(v))) in (2, 3, 5) else "")
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(leading)
    else:  # delays crowd near 0: linear within 1 ms, logarithmic beyond
        ax.set_xscale("symlog", linthresh=1.0, linscale=1.5)
    label_front(fig, ax, front, x_key)
    if recommended is not None:
        rec = [r for r in rows if r["config"] == recommended["config"] and r["precision"] == "double"]
        ax.scatter([r[x_key] for r in rec], [r["rms_effort"] for r in rec], marker="*", s=260,
                   c="gold", edgecolors="black", zorder=5, label="recommended default")
    ax.set_xlabel(x_label)
    ax.set_ylabel("RMS joint effort error [N m] (all joints)")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(f"Panda, stop-and-go, 1 kHz, realistic encoder and F/T noise: "
                 f"{len(rows)} configurations", fontsize=10)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, frameon=False)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def scored_scenes(scenes):
    return [s for s in scenes if s != "exact" and not s.endswith("_savings")]


def per_rate(rows, scenes, only_prefix=None):
    """Per scene (by rate, then name): the online default, the best online and the best
    offline zero-phase row (double, default savings)."""
    out = []
    for s in scored_scenes(scenes):
        if only_prefix and not s.startswith(only_prefix):
            continue
        online = overall(rows, s, precision="double")
        offline = overall(rows, s, precision="double", offline=True)
        default = next((r for r in online if r["family"] == "default"), None)
        if default is None or not offline:
            continue
        out.append((default["rate_hz"], s, default, min(online, key=lambda r: r["rms_effort"]),
                    min(offline, key=lambda r: r["rms_effort"])))
    out.sort(key=lambda x: (x[0], x[1]))
    return out


def per_rate_table(entries):
    body = []
    for rate, s, d, best, zp in entries:
        body.append([fmt(rate), f"`{s}`", f"{fmt(d['rms_effort'])} / {ms(d['delay_ms'])}",
                     f"{100 * d['overshoot']:.0f} %",
                     f"{best['config']}: {fmt(best['rms_effort'])} / {ms(best['delay_ms'])}",
                     f"{zp['config']} ({zp['cutoff_hz']:.3g} Hz): {fmt(zp['rms_effort'])}",
                     f"{100 * zp['overshoot']:.0f} %", f"{d['rms_effort'] / zp['rms_effort']:.2f}"])
    return table(["rate [Hz]", "scene", "online default: RMS effort [N m] / delay [ms]",
                  "default overshoot", "best online: RMS / delay", "best offline zero-phase: RMS",
                  "zero-phase overshoot", "default / offline"], body)


def per_rate_section(rows, scenes):
    entries = per_rate(rows, scenes)
    if not entries:
        return ""
    return ("## Online default against offline zero-phase, per rate\n\n"
            "Per scene, ordered by joint rate (double, default savings): the node's default "
            "differentiator (`default`, untouched), the best online configuration, and the "
            "best offline zero-phase smoothing of the whole record (the cutoff it used: fixed, "
            "or chosen by its rule) on the same readings; *default / offline* = the ratio of "
            "their RMS effort errors. docs/studies/accuracy_overview.md quotes the `arm_*` "
            "rows.\n\n"
            + per_rate_table(entries) + "\n")


def ratio(a, b):
    return f"{a / b:.2f}" if b > 0 else "n/a"


def defaults_entry(rows, s):
    """One scene of defaults_section: the rows, or None when the scene lacks them."""
    online = overall(rows, s, precision="double")
    offline = overall(rows, s, precision="double", offline=True)
    by = {r["config"]: r for r in online + offline}
    imm, smo = by.get("default + velocities"), by.get("smoothed default + velocities")
    if imm is None or smo is None or not offline:
        return None
    others = [r for r in online if r["group"] not in ("default", "default_smoothed")
              and not math.isnan(r["delay_ms"])]
    # The best of the study picked with the truth at the same or a shorter delay (+0.5 ms:
    # the delay is measured, not set).
    at = lambda d: [r for r in others if r["delay_ms"] <= d + 0.5]
    best_imm = min(at(imm["delay_ms"]) or [imm], key=lambda r: r["rms_effort"])
    best_smo = min(at(smo["delay_ms"]) or [smo], key=lambda r: r["rms_effort"])
    zp = min(offline, key=lambda r: r["rms_effort"])
    fixed = [r for r in offline if r["config"].endswith(" Hz")]
    auto = [by[c] for c in ("ZP auto", "ZP auto with velocities") if c in by]
    return imm, best_imm, smo, best_smo, zp, fixed, auto


def defaults_section(rows, scenes):
    """Per scene: what the node publishes by default (both streams, with the joint states'
    velocities where the scene has them) against the best configuration of the study at
    the same or a shorter delay and the best offline zero-phase row; and the offline
    automatic cutoff against the best fixed one."""
    body = []
    for s in scored_scenes(scenes):
        e = defaults_entry(rows, s)
        if e is None:
            continue
        imm, best_imm, smo, best_smo, zp, fixed, auto = e
        best_fixed = min(fixed, key=lambda r: r["rms_effort"]) if fixed else None
        autos = ", ".join(f"{r['cutoff_hz']:.3g} Hz: {ratio(r['rms_effort'], best_fixed['rms_effort'])}"
                          for r in auto) if best_fixed else ""
        body.append([f"`{s}`", f"{fmt(imm['rms_effort'])} / {ms(imm['delay_ms'])}",
                     f"{ratio(imm['rms_effort'], best_imm['rms_effort'])} ({best_imm['config']})",
                     ratio(imm["rms_effort"], zp["rms_effort"]),
                     f"{fmt(smo['rms_effort'])} / {ms(smo['delay_ms'])}",
                     f"{ratio(smo['rms_effort'], best_smo['rms_effort'])} ({best_smo['config']})",
                     ratio(smo["rms_effort"], zp["rms_effort"]), autos])
    if not body:
        return ""
    return ("## The defaults against the best of the study\n\n"
            "Per scene (double, default savings; RMS effort error [N m]): the immediate stream's "
            "default (`default + velocities`: the joint states' velocities where the scene's "
            "sensor reports them) and the smoothed stream's (`smoothed default + velocities`), each "
            "against the best configuration of the study, picked with the truth, at the same or a "
            "shorter delay (+0.5 ms), and against the best offline zero-phase row; and the "
            "offline automatic cutoff (`ZP auto`, then `ZP auto with velocities`) over the best "
            "fixed cutoff of the study (3, 5, 8, 12 Hz).\n\n"
            + table(["scene", "immediate: RMS / delay [ms]", "/ best at its delay",
                     "/ offline", "smoothed: RMS / delay [ms]", "/ best at its delay",
                     "/ offline", "ZP auto: cutoff: / best fixed"], body) + "\n")


def losses_section(rows, scenes):
    """Per scene and family: the family's best RMS effort error over the scene's best
    (online or offline), and its overshoot; > 2 is where the family loses."""
    families = ["default", "default_smoothed", "fd", "sg causal", "sg centred", "kalman_ca", "kalman_cj",
                "kalman_cj_smooth", "adaptive", "adaptive_smooth", OFFLINE]
    body = []
    for s in scored_scenes(scenes):
        every = overall(rows, s, precision="double") + overall(rows, s, precision="double", offline=True)
        if not every:
            continue
        least = min(r["rms_effort"] for r in every)
        cells = [f"`{s}`", fmt(least)]
        for g in families:
            group = [r for r in every if r["group"] == g]
            if not group or least <= 0:
                cells.append("")
                continue
            b = min(group, key=lambda r: r["rms_effort"])
            ratio = b["rms_effort"] / least
            text = f"{ratio:.2f} ({100 * b['overshoot']:.0f} %)"
            cells.append(f"**{text}**" if ratio > 2.0 else text)
        body.append(cells)
    return ("## Where each differentiator loses\n\n"
            "Per scene, each family's best configuration: its RMS effort error over the least "
            "of any row of the scene, online or offline (overshoot in brackets); **bold** "
            "where it is more than twice the least: the scenes where that family loses.\n\n"
            + table(["scene", "least RMS effort [N m]"] + [FAMILY_NAMES[g] for g in families], body)
            + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--md", required=True)
    parser.add_argument("--png-prefix", required=True)
    parser.add_argument("--command", default="tools/accuracy.sh")
    args = parser.parse_args()
    rows = load(args.csv)
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    main_rows = overall(rows, MAIN)
    if not main_rows:
        sys.exit(f"plot_accuracy: no overall rows of scene {MAIN}")
    rec = recommend(rows)
    shipped_rows = [r for r in main_rows if r["shipped_default"] == 1 and r["precision"] == "double"]
    shipped = shipped_rows[0]["config"] if shipped_rows else None
    busy = sorted(r["time_per_sample_us"] / r["cpu_per_sample_us"] for r in main_rows
                  if r["cpu_per_sample_us"] > 0)
    busy = busy[len(busy) // 2] if busy else float("nan")
    front_time = {id(r) for r in pareto(main_rows, "time_per_sample_us")}
    front_delay = {id(r) for r in pareto([r for r in main_rows if not math.isnan(r["delay_ms"])],
                                         "delay_ms")}

    png_time = args.png_prefix + "_error_vs_time.png"
    png_delay = args.png_prefix + "_error_vs_delay.png"
    plot(main_rows, "time_per_sample_us", "run time per joint sample [us] (wall clock, fastest run)",
         png_time, rec, log_x=True)
    plot([r for r in main_rows if not math.isnan(r["delay_ms"])], "delay_ms",
         "delay of the estimate [ms] (stamp lag + measured phase lag of qdd)", png_delay, rec,
         log_x=False)

    md = []
    w = md.append
    w("# Accuracy against run time and delay\n\n")
    w(f"Generated by `{args.command}` (bench/accuracy.cpp, bench/plot_accuracy.py); do not edit. "
      f"Errors are deterministic (seeded ground truth); run times are of this machine: "
      f"{cpu_name()}, {platform.system()} {platform.machine()}; median wall / CPU time of "
      f"the main scene's runs {busy:.2f}"
      + (" (the machine was busy: the wall-clock times are inflated, the CPU times in the CSV "
         "less so)" if busy > 1.1 else "") + ".\n\n")
    w("Every online configuration runs the scene's sensor readings through `jle::Pipeline`, "
      "the message path the node and `process_bag` drive, with the node's settings but for "
      "the differentiator: joint states (positions only, named as the URDF's joints) and "
      "F/T wrench messages in stamp order, each with its stamp in ns as a message carries "
      "it. The row `default` is `jle::Settings`' differentiator untouched, what a user who "
      "sets nothing runs. Each published estimate is compared with the exact loads at the "
      "**true instant** of the sample whose stamp it carries (or, should the pipeline publish "
      "its estimate of the sample's instant instead, of the sample whose true instant is "
      "nearest; the loads published with a sample's stamp describe that sample; where stamps are taken on receipt the stamp "
      "and the instant differ, and an estimator that recovers the instant is not "
      "penalised): the analytic q, qd, qdd and wrenches of the scene through the core's "
      "forward kinematics, `addExternalWrench` and inverse dynamics "
      "(test/support/jle_testing/ground_truth.hpp). *Offline* rows (family zero_phase, "
      "`ZP ...`) smooth the whole record instead: `jle::smoothZeroPhase` (4th-order "
      "Butterworth per pass, forward and backward) of the positions at their stamps at a "
      "fixed cutoff or the automatic one, every wrench input through `lowPassZeroPhase` "
      "with the same cutoff (interpolated linearly to the joint stamps), then the same "
      "inverse dynamics; an estimate for every sample, no delay by construction. They are "
      "kept out of the online rankings, fronts and recommendation.\n\n")

    w("## Metrics\n\n")
    w("- **effort**: error of the joint effort (axis . moment) [N m; N for prismatic joints]; "
      "**force**, **moment**: norm of the error of the full 3-D joint force [N] and moment "
      "[N m] (child frame, about the joint origin). RMS over all published samples whose true "
      "instant lies between the first and the last 0.5 s (10 % of shorter scenes) and over the "
      "joints; max = largest single error. *rel* = RMS error / RMS of the true value. Not "
      "scored: the online filters' start-up, and the offline smoother's two record ends, "
      "where its padding (odd reflection) errs most: scored to the end, its error on "
      "`panda_sines` at 3 Hz is 0.79 N m instead of 0.024 N m, and on `arm_noise_1e-4` at 8 Hz "
      "0.94 N m instead of 0.019 N m (the online default's hardly changes: 0.331 N m both).\n"
      "- **delay** = stamp lag + phase lag. *Stamp lag*: newest sample's stamp minus the "
      "estimate's stamp (the Savitzky-Golay `delay`; 0 for Kalman filters, which estimate the "
      "newest sample). *Phase lag*: the lag L maximising the cross-covariance of the estimated "
      "qdd (at its stamps) with the true qdd at stamp - L, all coordinates pooled, searched "
      "over -40..300 ms (2 ms, then 0.25 ms steps, parabolic refinement). It is what a Kalman "
      "filter's nominal 0 hides, and it also shows that a causal quadratic fit's qdd describes "
      "the middle of its window. n/a where the true qdd is constant.\n"
      "- **time**: wall clock (`std::chrono::steady_clock`) over the whole run divided by the "
      "number of joint samples, including the F/T samples' `addWrench` and the copy of the "
      "outputs; in the main scene and the savings sweeps the fastest of 5 runs (the "
      "precisions and savings of one differentiator take turns, so that a slow spell of a "
      "shared machine hits them alike), elsewhere of one run. The CSV also has the thread's "
      "CPU time.\n"
      "- **Pareto**: T = not beaten in both error and time, D = not beaten in both error and "
      "delay, among the rows of the table.\n"
      "- **overshoot**: per joint, how far the estimated effort leaves the range of the true "
      "effort, max(est max - true max, true min - est min, 0) / (true max - true min), "
      "both taken over the after-impact windows (each impact's start to 0.25 s after its "
      "end) in the impact scenes, over the whole scored record elsewhere; ALL = the worst "
      "joint's.\n\n")

    w("## Recommendation\n\n")
    if rec is not None:
        gm = {c: (g, worst) for g, worst, c, _ in robustness(rows)[1]}.get(rec["config"])
        w(f"Rule: among the main scene's configurations (double, default savings) on the "
          f"error-delay Pareto front with at most {DELAY_BUDGET_MS:g} ms of delay, the one "
          f"closest to the best in every scene (least geometric mean of its error over the "
          f"scene's least, see *Robustness*). **{rec['config']}**")
        if rec["family"].startswith("kalman"):
            w(f" (process_noise {rec['process_noise']:g}, measurement_noise "
              f"{rec['measurement_noise']:.2g} rad: the gain depends on their ratio only)")
        w(f": RMS effort error {fmt(rec['rms_effort'])} N m (max {fmt(rec['max_effort'])}), "
          f"force {fmt(rec['rms_force'])} N, moment {fmt(rec['rms_moment'])} N m, delay "
          f"{ms(rec['delay_ms'])} ms, {us(rec['time_per_sample_us'])} us per sample"
          + (f"; across scenes {gm[0]:.2f} times the best on geometric mean, {gm[1]:.2f} at "
             f"worst." if gm else "."))
        least = min(main_rows, key=lambda r: r["rms_effort"])
        if least["config"] != rec["config"]:
            w(f" The least error on the main scene: {least['config']} ({least['precision']}), "
              f"{fmt(least['rms_effort'])} N m with {ms(least['delay_ms'])} ms of delay.")
        if shipped_rows:
            r = shipped_rows[0]
            w(f" For comparison, the textbook causal fit {shipped}: {fmt(r['rms_effort'])} N m, delay "
              f"{ms(r['delay_ms'])} ms, {us(r['time_per_sample_us'])} us.")
        w(" Per scene: *Other scenes* below.\n\n")
    else:
        w(f"No configuration has a delay of at most {DELAY_BUDGET_MS:g} ms.\n\n")

    w("## Scenes\n\n")
    scene_rows = []
    for s in scenes:
        r = next(x for x in rows if x["scene"] == s)
        description = next((x["scene_description"] for x in rows
                            if x["scene"] == s and x["scene_description"]), "")
        scene_rows.append([f"`{s}`", description, fmt(r["rate_hz"]),
                           len({x['joint'] for x in rows if x['scene'] == s} - {'ALL'})])
    w(table(["scene", "description", "joint rate [Hz]", "joints"], scene_rows))
    w("\nScenes of real logs (`arm_*`): the encoder is sampled at k / rate and stamped on "
      "receipt, stamp error 5% of the period (1 sigma, truncated at 20%; about +-10%), "
      "bursts of 50 samples at 15%, gaps of up to the stated number of periods, 0.1% "
      "single drops, the stated noise before 2^17-count quantisation. "
      "Other scenes: encoder: 2^17 counts per revolution (4.8e-5 rad per count) after 5e-6 rad of "
      "Gaussian noise. Kalman filters get measurement_noise = sqrt(noise^2 + count^2 / 12) "
      "= 1.5e-5 rad (1e-6 rad for exact inputs; the scene's noise in the `arm_*` scenes), but "
      "those labelled r=1e-04 and `default`, which keep their own. Trajectories, wrenches and sensors: "
      "test/support/jle_testing/ground_truth.hpp.\n\n")

    w(f"## Main scene: `{MAIN}`, default savings\n\n")
    w(f"![RMS effort error vs run time]({os.path.basename(png_time)})\n\n")
    w(f"![RMS effort error vs delay]({os.path.basename(png_delay)})\n\n")
    body = []
    for i, r in enumerate(sorted(main_rows, key=lambda r: r["rms_effort"]), 1):
        marks = ("T" if id(r) in front_time else "") + ("D" if id(r) in front_delay else "")
        if rec is not None and r["config"] == rec["config"] and r["precision"] == "double":
            marks += " *"
        body.append([i, r["config"], r["precision"], fmt(r["rms_effort"]), fmt(r["max_effort"]),
                     fmt(r["rms_force"]), fmt(r["max_force"]), fmt(r["rms_moment"]),
                     fmt(r["max_moment"]), fmt(r["rel_rms_effort"]), ms(r["stamp_lag_ms"]),
                     ms(r["phase_lag_ms"]), ms(r["delay_ms"]), us(r["time_per_sample_us"]), marks])
    w(table(["#", "configuration", "precision", "RMS effort", "max effort", "RMS force",
             "max force", "RMS moment", "max moment", "rel effort", "stamp lag [ms]",
             "phase lag [ms]", "delay [ms]", "time [us]", "Pareto"], body))
    w("\nUnits: N m (effort, moment), N (force). * = recommended.\n\n")

    if rec is not None:
        w(f"### Per joint: {rec['config']} (double)\n\n")
        per = [r for r in rows if r["scene"] == MAIN and r["config"] == rec["config"]
               and r["precision"] == "double" and r["savings"] == "default"]
        w(table(["joint", "RMS effort", "max effort", "RMS force", "max force", "RMS moment",
                 "max moment", "rel effort"],
                [[r["joint"], fmt(r["rms_effort"]), fmt(r["max_effort"]), fmt(r["rms_force"]),
                  fmt(r["max_force"]), fmt(r["rms_moment"]), fmt(r["max_moment"]),
                  fmt(r["rel_rms_effort"])] for r in per]))
        w("\n")

    w("## Savings and precision\n\n")
    w("Each switch of `EstimatorConfig::savings` off on its own, all five exact ones off, the "
      "static thresholds on (0.02 rad/s, 0.5 rad/s^2), and pruning measured where it acts: "
      "loads wanted for the last three joints only (errors then over those three). Time "
      "relative to the default savings of the same differentiator and precision; *CPU*: the "
      "thread's CPU time per sample (fastest run), which a busy machine's preemption does "
      "not inflate as it does the wall time. *3x3*: share "
      "of the estimates computed by the planar path (`savings.planar`; float keeps 6x6).\n\n")
    for s in scenes:
        sweep = [r for r in rows if r["scene"] == s and r["joint"] == "ALL" and r["savings"] != "default"]
        if not sweep:
            continue
        configs = []
        for r in sweep:
            if r["config"] not in configs:
                configs.append(r["config"])
        w(f"### `{s}`\n\n")
        body = []
        for c in configs:
            for precision in ("double", "float"):
                group = [r for r in rows if r["scene"] == s and r["joint"] == "ALL"
                         and r["config"] == c and r["precision"] == precision]
                base = next((r for r in group if r["savings"] == "default"), None)
                for r in group:
                    rel = (f"{100 * (r['time_per_sample_us'] / base['time_per_sample_us'] - 1):+.1f} %"
                           if base else "")
                    body.append([c, precision, r["savings"], fmt(r["rms_effort"], 4),
                                 fmt(r["rms_force"], 4), us(r["time_per_sample_us"]), rel,
                                 us(r["cpu_per_sample_us"]), f"{100 * r['planar_share']:.0f} %"])
        w(table(["configuration", "precision", "savings", "RMS effort", "RMS force",
                 "time [us]", "time vs default", "CPU [us]", "3x3"], body))
        w("\n")

    w("## Exact inputs\n\n")
    exact = [r for r in rows if r["scene"] == "exact" and r["joint"] == "ALL"]
    if exact:
        w("Quadratic q (finite differences and every Savitzky-Golay fit are exact for it), no "
          "noise, quantisation, jitter or drops, a constant wrench sampled at the joint stamps. "
          "What remains is rounding: a second difference divides a few ulps of q (~1e-16 rad) "
          "by h^2 = 1e-6 s^2, so qdd carries ~1e-10 rad/s^2 at 1 kHz (less for the wider "
          "fits, which average it); the loads carry that times the inertias, against loads "
          "of ~10 N m. Kalman filters are not exact by construction; on a quadratic they "
          "converge to it. Float: the dynamics in single precision (~1e-7).\n\n")
        body = [[r["config"], r["precision"], fmt(r["rel_rms_effort"]), fmt(r["rel_rms_force"]),
                 fmt(r["rel_rms_moment"]), fmt(r["max_effort"]), fmt(r["max_force"]),
                 fmt(r["max_moment"])] for r in exact]
        w(table(["configuration", "precision", "rel RMS effort", "rel RMS force",
                 "rel RMS moment", "max effort [N m]", "max force [N]", "max moment [N m]"], body))
        w("\n")

    scenes_r, robust = robustness(rows)
    if robust:
        w("## Robustness\n\n")
        w("Per differentiator, its RMS effort error divided by the least of any differentiator "
          f"in the same scene, over the {len(scenes_r)} noisy scenes ({', '.join(scenes_r)}): "
          "geometric mean and worst case; the ten best.\n\n")
        w(table(["configuration", "geometric mean", "worst"] + scenes_r,
                [[c, f"{gm:.2f}", f"{worst:.2f}"] + [f"{x:.2f}" for x in ratios]
                 for gm, worst, c, ratios in robust[:10]]))
        w("\n")

    w("## Other scenes (double, default savings)\n\n")
    body = []
    for s in scenes:
        if s in ("exact",) or s.endswith("_savings"):
            continue
        ranked = sorted(overall(rows, s, precision="double"), key=lambda r: r["rms_effort"])
        if not ranked:
            continue
        best = ranked[0]
        low_delay = min((r for r in ranked if not math.isnan(r["delay_ms"])
                         and r["delay_ms"] <= DELAY_BUDGET_MS), key=lambda r: r["rms_effort"],
                        default=None)
        cells = [f"`{s}`", f"{best['config']}: {fmt(best['rms_effort'])} / {ms(best['delay_ms'])}"]
        cells.append(f"{low_delay['config']}: {fmt(low_delay['rms_effort'])} / "
                     f"{ms(low_delay['delay_ms'])}" if low_delay else "none")
        for name in ([rec["config"]] if rec else []) + ([shipped] if shipped else []):
            hit = [(i, r) for i, r in enumerate(ranked, 1) if r["config"] == name]
            cells.append(f"#{hit[0][0]}: {fmt(hit[0][1]['rms_effort'])} / {ms(hit[0][1]['delay_ms'])}"
                         if hit else "")
        body.append(cells)
    header = ["scene", "least error: RMS effort [N m] / delay [ms]",
              f"least error with delay <= {DELAY_BUDGET_MS:g} ms"]
    if rec:
        header.append(f"{rec['config']}: rank, error / delay")
    if shipped:
        header.append(f"{shipped}: rank, error / delay")
    w(table(header, body))
    w(f"\nRanks among {len(overall(rows, MAIN, precision='double'))} differentiators by RMS "
      "effort error. All rows of every scene, per joint too, are in accuracy.csv.\n")

    w(defaults_section(rows, scenes))
    w(per_rate_section(rows, scenes))
    w(losses_section(rows, scenes))

    with open(args.md, "w") as f:
        f.write("".join(md))


if __name__ == "__main__":
    main()
