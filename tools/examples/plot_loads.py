#!/usr/bin/env python3
"""Joint loads of a Panda arm from Python, plotted to a PNG (docs/python.md, "Python").

The arm follows an analytic trajectory for 4 s; its exact loads come from
joint_load_estimator.inverse_dynamics with the exact derivatives, and its estimated
loads from the online Estimator (the node's defaults) fed noisy positions at 1 kHz, as a
robot's encoders would give them, and from the offline zero-phase smoother
(smooth_zero_phase) over the same record. Plots the effort of joints 2 and 4 and the
force magnitude through joint 2.
  /usr/bin/python3 tools/examples/plot_loads.py [--output loads.png] [--urdf ROBOT.urdf]
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")  # a file, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import joint_load_estimator as jle  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def trajectory(model, t):
    """q = c + A sin(w t) per coordinate, and its exact derivatives."""
    k = np.arange(model.nq)
    amplitude = np.where(["finger" in c for c in model.coordinate_names], 0.01, 0.4)
    centre = np.zeros(model.nq)
    centre[:7] = [0, -np.pi / 4, 0, -3 * np.pi / 4, 0, np.pi / 2, np.pi / 4][:min(7, model.nq)]
    w = 2 * np.pi * (0.2 + 0.07 * k)
    phase = np.outer(t, w)
    return (centre + amplitude * np.sin(phase), amplitude * w * np.cos(phase),
            -amplitude * w ** 2 * np.sin(phase))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--urdf", default=os.path.join(HERE, "..", "..", "test", "data", "urdf",
                                                        "panda.urdf"))
    parser.add_argument("--output", default="loads.png")
    args = parser.parse_args()

    model = jle.Model(args.urdf)
    t = np.arange(0.0, 4.0, 0.001)
    q, qd, qdd = trajectory(model, t)
    exact = jle.inverse_dynamics(model, q, qd, qdd)
    noisy = q + np.random.default_rng(0).normal(0.0, 2e-5, q.shape)  # encoder-like noise
    online = jle.estimate(jle.Estimator(model), t, noisy)
    value, rate, accel, cutoff = jle.smooth_zero_phase(t, noisy)
    offline = jle.inverse_dynamics(model, value, rate, accel)

    joints = [j for j in ("panda_joint2", "panda_joint4") if j in exact.joints] or exact.joints[:2]
    fig, axes = plt.subplots(len(joints) + 1, 1, sharex=True, figsize=(8, 7))
    for ax, joint in zip(axes, joints):
        ax.plot(t, exact[joint].effort, "k", lw=2, label="exact")
        ax.plot(online.t, online[joint].effort, "C0", lw=1, label="online Estimator")
        ax.plot(t, offline[joint].effort, "C1--", lw=1,
                label="zero-phase (%.1f Hz)" % cutoff)
        ax.set_ylabel("%s effort [N m]" % joint)
        ax.legend(loc="upper right", fontsize=8)
    joint = joints[0]
    axes[-1].plot(t, np.linalg.norm(exact[joint].force, axis=1), "k", lw=2)
    axes[-1].plot(online.t, np.linalg.norm(online[joint].force, axis=1), "C0", lw=1)
    axes[-1].set_ylabel("|force| %s [N]" % joint)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle("%s: joint loads (child link frame)" % os.path.basename(args.urdf))
    fig.tight_layout()
    fig.savefig(args.output, dpi=100)
    print("plot_loads: wrote %s" % args.output)


if __name__ == "__main__":
    main()
