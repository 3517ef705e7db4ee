"""The Kalman smoother's tables of docs/studies/differentiators.md, from the accuracy study's
CSV (docs/studies/accuracy.csv, written by tools/accuracy.sh, which runs this script after
the study): RMS effort error / overshoot / delay of the smoother's configurations beside
the causal default and the best offline zero-phase result, per scene.

usage: differentiator_tables.py ACCURACY.csv DIFFERENTIATORS.md
Rewrites the page's blocks ks_cj, ks_stamp_lag, ks_adaptive and ks_gcv (tools/study_page.py).
Run with /usr/bin/python3 (plot_accuracy.py imports matplotlib).
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from plot_accuracy import OFFLINE, load, pareto  # noqa: E402
from study_page import fill, g3, table  # noqa: E402

SOURCE = ("Generated from docs/studies/accuracy.csv by `bench/differentiator_tables.py` "
          "(`bash tools/accuracy.sh` runs the study and then it); do not edit.")
KS_CJ_SCENES = ["arm_jitter_1khz", "arm_jitter_200hz", "arm_noise_1e-3", "arm_impact_200hz",
                "arm_impact_1khz", "leg_running_200hz", "panda"]
KS_ADAPTIVE_SCENES = ["arm_jitter_1khz", "arm_jitter_200hz", "arm_jitter_100hz", "arm_noise_1e-3",
                      "arm_impact_200hz", "arm_impact_1khz", "leg_running_200hz", "panda", "planar"]
LAGS = [20, 50, 100, 200]
FIXED = "KS-CJ q=1e+02 lag=200ms r=1e-04"


class Study:
    """The ALL rows (every joint) of each scene, double precision, default savings, without
    the configurations that also read measured velocities (the others do not)."""

    def __init__(self, path):
        self.rows = {}
        self.scenes = []
        for r in load(path):
            if (r["joint"] != "ALL" or r["precision"] != "double" or r["savings"] != "default"
                    or "velocities" in r["config"]):
                continue
            if r["scene"] not in self.scenes:
                self.scenes.append(r["scene"])
            self.rows.setdefault(r["scene"], {})[r["config"]] = r

    def row(self, scene, config):
        try:
            return self.rows[scene][config]
        except KeyError:
            sys.exit("differentiator_tables: no row %s in scene %s" % (config, scene))

    def best_offline(self, scene):
        return min((r for r in self.rows[scene].values() if r["family"] == OFFLINE),
                   key=lambda r: r["rms_effort"])

    def ratio(self, scene, config):
        return self.row(scene, config)["rms_effort"] / self.best_offline(scene)["rms_effort"]

    def on_delay_front(self, scene, config):
        online = [r for r in self.rows[scene].values()
                  if r["family"] != OFFLINE and not math.isnan(r["delay_ms"])]
        return any(r["config"] == config for r in pareto(online, "delay_ms"))


def cell(r, delay=True):
    text = "%s / %.0f%%" % (g3(r["rms_effort"]), 100 * r["overshoot"])
    return text + (" / %.0f" % r["delay_ms"] if delay else "")


def ks_table(study, scenes, configs):
    rows = [["`%s`" % c] + [cell(study.row(s, c)) for s in scenes] for c in configs]
    rows.append(["best offline zero-phase"] + [cell(study.best_offline(s), False) for s in scenes])
    return table(["config"] + ["`%s`" % s for s in scenes], rows)


def ks_cj_block(study):
    configs = ["default"] + ["KS-CJ q=1e+0%d lag=%dms r=1e-04" % (q, lag)
                             for q in (2, 3, 4) for lag in LAGS]
    head = (SOURCE + " Rows `KS-CJ` (measurement noise 1e-4 rad, the default's: untuned): "
            "RMS effort error [N m] / overshoot of the truth's range / delay [ms] (stamp lag "
            "plus phase lag); the best offline zero-phase result is the least error of the "
            "scene's `ZP` rows.\n\n")
    within = ["`%s` %.2f×" % (s, study.ratio(s, FIXED)) for s in
              ["arm_jitter_1khz", "arm_jitter_200hz", "arm_jitter_100hz", "arm_noise_1e-4",
               "arm_noise_1e-3"]]
    beaten = [s for s in study.scenes if s in study.rows and "default" in study.rows[s]
              and FIXED in study.rows[s]
              and study.row(s, "default")["rms_effort"] < study.row(s, FIXED)["rms_effort"]]
    bullets = (
        "\n- `lag: 0.2`, q = 1e2, over the best offline zero-phase result: %s. It overshoots "
        "the impact at 200 Hz by %.0f%% (the causal default %.0f%%).\n"
        "- Scenes where the causal default has less error than `lag: 0.2`, q = 1e2: %s.\n"
        % (", ".join(within), 100 * study.row("arm_impact_200hz", FIXED)["overshoot"],
           100 * study.row("arm_impact_200hz", "default")["overshoot"],
           ", ".join("`%s`" % s for s in beaten) or "none"))
    return head + ks_table(study, KS_CJ_SCENES, configs) + bullets


def stamp_lag_block(study):
    scenes = ["arm_jitter_1khz", "arm_jitter_200hz", "arm_long_holds", "arm_impact_1khz"]
    lags = ", ".join("%.1f ms on `%s`" % (study.row(s, FIXED)["stamp_lag_ms"], s) for s in scenes)
    return ("In the accuracy study (`bash tools/accuracy.sh`, `lag: 0.2`, q = 1e2) the mean "
            "stamp lag is %s (bench/differentiator_tables.py); the mean includes the last 0.2 s "
            "that `flush()` publishes with less delay at the end." % lags)


def ks_adaptive_block(study):
    configs = ["default", "adaptive"] + ["KS-adaptive lag=%dms" % lag for lag in LAGS[:3]] + [FIXED]
    head = (SOURCE + " Rows `KS-adaptive` (nothing tuned): RMS effort error [N m] / "
            "overshoot of the truth's range / delay [ms].\n\n")
    lag100 = "KS-adaptive lag=100ms"
    fronts = [s for s in study.scenes if lag100 in study.rows.get(s, {})
              and study.on_delay_front(s, lag100)]
    bullets = (
        "\n- On `leg_running_200hz` (clean, impacts): `lag: 0.1` %s N m against %s N m for the "
        "fixed q = 1e2 smoother at 0.2 s. On the jittered arm at 1 kHz: %.2f× the best "
        "offline result at `lag: 0.1` (the fixed smoother at 0.2 s: %.2f×); overshoot of the "
        "200 Hz impact %.0f%% (the fixed one %.0f%%).\n"
        "- `lag: 0.1` is on the error–delay Pareto front (among the scene's online "
        "configurations) of: %s.\n"
        % (g3(study.row("leg_running_200hz", lag100)["rms_effort"]),
           g3(study.row("leg_running_200hz", FIXED)["rms_effort"]),
           study.ratio("arm_jitter_1khz", lag100), study.ratio("arm_jitter_1khz", FIXED),
           100 * study.row("arm_impact_200hz", lag100)["overshoot"],
           100 * study.row("arm_impact_200hz", FIXED)["overshoot"],
           ", ".join("`%s`" % s for s in fronts) or "no scene"))
    return head + ks_table(study, KS_ADAPTIVE_SCENES, configs) + bullets


def gcv_block(study):
    config = "KS-adaptive lag=200ms"
    rows, fronts = [], 0
    for s in study.scenes:
        if s.endswith("_savings") or config not in study.rows.get(s, {}):
            continue
        r = study.row(s, config)
        text = "%.2f×" % study.ratio(s, config)
        if "impact" in s or "running" in s:
            text += ", overshoot %.0f%%" % (100 * r["overshoot"])
        if study.on_delay_front(s, config):
            text += " (front)"
            fronts += 1
        rows.append(["`%s`" % s, text])
    head = (SOURCE + " RMS effort error over the joints as a multiple of the scene's best "
            "offline zero-phase result, overshoot of the truth's range on the impact scenes, "
            "`lag: 0.2`; (front): on the scene's error–delay Pareto front among the online "
            "configurations.\n\n")
    return head + table(["scene", "`%s`" % config], rows) + \
        "\nOn the error–delay front of %d of %d scenes.\n" % (fronts, len(rows))


def main(csv_path, page):
    study = Study(csv_path)
    fill(page, {"ks_cj": ks_cj_block(study), "ks_stamp_lag": stamp_lag_block(study),
                "ks_adaptive": ks_adaptive_block(study), "ks_gcv": gcv_block(study)})
    print("differentiator_tables: wrote the smoother's tables of %s" % page)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(*sys.argv[1:])
