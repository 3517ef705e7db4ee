#!/usr/bin/env python3
"""Batch throughput of the Python bindings beside the C++ command-line tool, same run,
same data (docs/python.md, "Throughput").

The Panda (test/data/urdf/panda.urdf), N random states (q, qd, qdd) with a wrench at the
hand, child-frame loads of every moving joint:
  python   joint_load_estimator.inverse_dynamics over numpy arrays in memory
  cli      joint_loads --input STATES.csv --output LOADS.csv (parsing and writing the
           CSV files included: what a script calling the tool pays)
  python+csv  numpy.loadtxt of the same CSV, the bindings, numpy.savetxt of the loads
  estimator   joint_load_estimator.estimate: the online Estimator with the node's
           defaults (filters and loads) over the positions alone of a smooth motion (sines
           within the limits: it refuses random jumps), every sample published
Each is timed REPEAT times, the best run counts. Prints samples per second and the
ratio python / cli. Run in a sourced workspace:
  /usr/bin/python3 bench/python_throughput.py [--samples 100000] [--repeat 3]
      [--joint-loads $JLE_WS/devel/lib/joint_load_estimator/joint_loads] [--page]
--page: builds the bindings and joint_loads first (tools/build.sh, JLE_WS as there), then
writes the figures, the machine and its load into the generated block of docs/python.md
(about a minute of machine time).
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PANDA = os.path.join(HERE, "..", "test", "data", "urdf", "panda.urdf")
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
import study_page  # noqa: E402


def limits(urdf, names):
    """The URDF's limits of the coordinates `names`: lower and upper position, and speed
    (the tools refuse states beyond their joints' limits); a joint without limits: +-2 rad
    and 3 rad/s."""
    import xml.etree.ElementTree as ET
    found = {}
    for joint in ET.parse(urdf).getroot().iter("joint"):
        limit = joint.find("limit")
        if limit is not None and "lower" in limit.attrib and "upper" in limit.attrib:
            found[joint.get("name")] = (float(limit.get("lower")), float(limit.get("upper")),
                                        min(3.0, float(limit.get("velocity", 3.0))))
    bounds = np.array([found.get(name, (-2.0, 2.0, 3.0)) for name in names])
    return bounds[:, 0], bounds[:, 1], bounds[:, 2]


def best_of(repeat, run):
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=100000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--joint-loads", default=os.path.join(
        os.environ.get("JLE_WS", ""), "devel", "lib", "joint_load_estimator", "joint_loads"))
    parser.add_argument("--page", action="store_true",
                        help="build, then write the block of docs/python.md")
    args = parser.parse_args()
    if args.page:
        build()
    sys.path.insert(0, os.path.join(os.environ.get("JLE_WS", ""), "devel", "lib", "python3",
                                    "dist-packages"))
    global jle
    import joint_load_estimator as jle
    load_before = study_page.load()
    if not os.access(args.joint_loads, os.X_OK):
        sys.exit("python_throughput: joint_loads not found at %s (--joint-loads PATH, or set "
                 "JLE_WS)" % args.joint_loads)

    model = jle.Model(PANDA)
    n, rng = args.samples, np.random.default_rng(1)
    lower, upper, speed = limits(PANDA, model.coordinate_names)
    q, qd = rng.uniform(lower, upper, (n, model.nq)), rng.uniform(-speed, speed, (n, model.nq))
    qdd, wrench = rng.uniform(-20, 20, (n, model.nq)), rng.uniform(-30, 30, (n, 6))
    header = ["t"] + ["%s.%s" % (c, d) for c in model.coordinate_names for d in ("q", "qd", "qdd")]
    header += ["wrench@panda_hand." + c for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    rows = np.column_stack([1e-3 * np.arange(n)] + [np.stack([q[:, k], qd[:, k], qdd[:, k]], 1)
                                                    for k in range(model.nq)] + [wrench])
    with tempfile.TemporaryDirectory() as tmp:
        states, loads_csv = os.path.join(tmp, "states.csv"), os.path.join(tmp, "loads.csv")
        np.savetxt(states, rows, delimiter=",", header=",".join(header), comments="",
                   fmt="%.17g")

        def python():
            jle.inverse_dynamics(model, q, qd, qdd, wrenches={"panda_hand": wrench})

        def cli():
            subprocess.run([args.joint_loads, "--urdf", PANDA, "--input", states, "--output",
                            loads_csv], check=True)

        def python_csv():
            x = np.loadtxt(states, delimiter=",", skiprows=1)
            cols = x[:, 1:1 + 3 * model.nq].reshape(n, model.nq, 3)
            r = jle.inverse_dynamics(model, cols[:, :, 0], cols[:, :, 1], cols[:, :, 2],
                                     wrenches={"panda_hand": x[:, -6:]})
            np.savetxt(os.path.join(tmp, "py.csv"),
                       np.column_stack([x[:, 0], r.wrench.reshape(n, -1), r.effort]),
                       delimiter=",", fmt="%.17g")

        # The online estimator takes a motion, not random states (it refuses jumps no
        # joint makes): sines within the limits, at most 0.26 Hz (within the speed limits).
        t = 1e-3 * np.arange(n)
        k = np.arange(model.nq)
        motion = 0.5 * (lower + upper) + 0.2 * (upper - lower) * np.sin(
            2 * np.pi * (0.1 + 0.02 * k) * t[:, None] + k)

        def estimator():
            return jle.estimate(jle.Estimator(model), t, motion)

        published = len(estimator().t)
        if published < 0.99 * n:
            sys.exit("python_throughput: the estimator published %d of %d samples" % (published, n))

        t_python = best_of(args.repeat, python)
        t_cli = best_of(args.repeat, cli)
        t_python_csv = best_of(args.repeat, python_csv)
        t_estimator = best_of(args.repeat, estimator)
    print("Panda, %d samples, %d joints, best of %d:" % (n, len(model.joint_names), args.repeat))
    print("  python inverse_dynamics (arrays in memory): %12.0f samples/s" % (n / t_python))
    print("  C++ joint_loads CLI (CSV in, CSV out):      %12.0f samples/s" % (n / t_cli))
    print("  python with numpy CSV in and out:           %12.0f samples/s" % (n / t_python_csv))
    print("  python Estimator (node's defaults):         %12.0f samples/s" % (n / t_estimator))
    print("  ratio python / CLI: %.2f" % (t_cli / t_python))
    if args.page:
        rates = [("`inverse_dynamics`, numpy arrays in memory", n / t_python),
                 ("`joint_loads` CLI, CSV in and CSV out (`%.17g`)", n / t_cli),
                 ("`inverse_dynamics` with `numpy.loadtxt` / `savetxt` of the same CSV",
                  n / t_python_csv),
                 ("`estimate` (online `Estimator`, the node's defaults: both streams, the "
                  "positions of a smooth motion alone)", n / t_estimator)]
        text = ("Generated by `/usr/bin/python3 bench/python_throughput.py --page` (JLE_WS set); "
                "do not edit. Panda, %d samples, best of %d; machine: %s; %s.\n\n"
                % (n, args.repeat, study_page.machine(),
                   study_page.load_span(load_before, study_page.load())))
        text += study_page.table(["Path (same run: random states within the limits, a wrench "
                                  "at the hand, child frame)", "samples/s"],
                                 [[label, "%.0f" % rate] for label, rate in rates])
        text += ("\nThe bindings run %.1f× the CLI's rate in this run: they skip the CSV "
                 "parsing and formatting that dominate the CLI; the dynamics are the same code.\n"
                 % (t_cli / t_python))
        study_page.fill(os.path.join(HERE, "..", "docs", "python.md"), {"throughput": text})
        print("python_throughput: wrote docs/python.md")


def build():
    repo = os.path.join(HERE, "..")
    ws = os.environ.setdefault("JLE_WS", os.path.join(
        os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "joint_load_estimator", "ws"))
    with open(os.path.join(ws, "python_throughput_build.log"), "w") as log:
        if subprocess.run(["bash", os.path.join(repo, "tools", "build.sh"),
                           "-j" + os.environ.get("JLE_JOBS", "2"), "joint_load_estimator_python",
                           "joint_loads"], stdout=log, stderr=subprocess.STDOUT).returncode:
            sys.exit("python_throughput: build failed (log: %s)" % log.name)


if __name__ == "__main__":
    main()
