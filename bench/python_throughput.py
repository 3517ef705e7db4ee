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
           defaults (filters and loads) over the positions alone
Each is timed REPEAT times, the best run counts. Prints samples per second and the
ratio python / cli. Run in a sourced workspace:
  /usr/bin/python3 bench/python_throughput.py [--samples 100000] [--repeat 3]
      [--joint-loads $JLE_WS/devel/lib/joint_load_estimator/joint_loads]
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import joint_load_estimator as jle

HERE = os.path.dirname(os.path.abspath(__file__))
PANDA = os.path.join(HERE, "..", "test", "data", "urdf", "panda.urdf")


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
    args = parser.parse_args()
    if not os.access(args.joint_loads, os.X_OK):
        sys.exit("python_throughput: joint_loads not found at %s (--joint-loads PATH, or set "
                 "JLE_WS)" % args.joint_loads)

    model = jle.Model(PANDA)
    n, rng = args.samples, np.random.default_rng(1)
    q, qd = rng.uniform(-2, 2, (n, model.nq)), rng.uniform(-3, 3, (n, model.nq))
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

        def estimator():
            jle.estimate(jle.Estimator(model), 1e-3 * np.arange(n), q)

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


if __name__ == "__main__":
    main()
