"""One joint's estimated effort with its +-2 sigma band: the JOINT.effort and
JOINT.effort_stddev columns of process_bag --csv with uncertainty enabled (the band is
the propagated uncertainty; tools/uncertainty_band.sh makes the input).
usage: plot_uncertainty.py LOADS.csv JOINT OUT.png"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(path, joint, out):
    t, effort, sd = [], [], []
    with open(path) as f:
        rows = csv.DictReader(f)
        for row in rows:
            t.append(float(row["t"]))
            effort.append(float(row[joint + ".effort"]))
            sd.append(float(row[joint + ".effort_stddev"]))
    t0 = t[0]
    t = [x - t0 for x in t]
    lo = [e - 2 * s for e, s in zip(effort, sd)]
    hi = [e + 2 * s for e, s in zip(effort, sd)]
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.fill_between(t, lo, hi, color="tab:blue", alpha=0.3, linewidth=0, label="±2σ (propagated)")
    ax.plot(t, effort, color="tab:blue", linewidth=1.0, label="estimated effort")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(joint + " effort [N m]")
    ax.set_title("Demo bag, %s: estimate and its uncertainty (mean σ = %.3f N m)"
                 % (joint, sum(sd) / len(sd)))
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("%s: %d samples, sigma %.4f .. %.4f N m -> %s" % (joint, len(t), min(sd), max(sd), out))


if __name__ == "__main__":
    main(*sys.argv[1:4])
