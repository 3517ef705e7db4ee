"""Writes docs/studies/speed.md from one run of `bash tools/speed.sh --page`: Google
Benchmark's JSON of bench_speed_core and of bench_speed_messages. Each row is the median
of its repetitions (CPU time per sample); every ratio is of two rows of the same run.

usage: speed_page.py CORE.json MESSAGES.json --load-before L --load-after L --command C
                     --output PAGE
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from speed_summary import ARMS, LINEAR_PER_JOINT, TARGETS, load  # noqa: E402
from study_page import load_span, machine, table  # noqa: E402

LINKING = """
## Linking

The core library's objects hold fixed-size Eigen members and inline code, so a client
must share its Eigen alignment. The package fixes it
(`EIGEN_MAX_ALIGN_BYTES=16 EIGEN_MAX_STATIC_ALIGN_BYTES=16 EIGEN_MALLOC_ALREADY_ALIGNED=1`,
amd64's and arm64's defaults, what Debian's libraries use) and exports it: a PUBLIC
compile definition of the CMake target `joint_load_estimator_core` and the catkin
package's CMake extras; `eigen_abi.hpp` refuses to compile without it. `test_link_client`
builds a client with `-march=native` (or `-mavx2`) and compares its run of the estimator
on the Panda with its own.
"""

LEAN = """
What keeps the passes lean: a joint axis along ±x/±y/±z (every revolute joint of the
four robots) mixes two columns of the joint rotation and skips the axis' zeros (12
products instead of 39 for the rotation); world poses in their own pass; the backward
sums started by the first child instead of a clearing pass; the per-segment steps forced
inline; sin and cos of each joint from fdlibm's kernels after a Cody–Waite reduction, 8,
4 or 2 joints per vector register before the segment loop (`sinCosArray`, bit for bit the
one-joint code; in the core library, compiled for AVX-512F, AVX2 and SSE2 and chosen once
at run time by the CPU, so a client's compiler flags do not change it), the root set
directly when no base state is given (`trig.hpp`, within 1 ulp, checked against long
double in `test_trig`). What decides the passes' time is the chain of dependent stores
and loads from each segment to the next more than the count of floating-point operations.
"""


class Runs:
    def __init__(self, path):
        self.path = path
        self.rows = load(path)
        with open(path) as f:
            self.context = json.load(f)["context"]

    def cpu(self, name):
        b = self.rows.get(name)
        if b is None:
            sys.exit("speed_page: no row %s" % name)
        return b["cpu_time"]

    def spread(self):
        """The median over the rows of the repetitions' standard deviation over their
        median (CPU time): how far one run of a row moves on this machine now."""
        with open(self.path) as f:
            runs = json.load(f)["benchmarks"]
        sd = {b["run_name"]: b["cpu_time"] for b in runs
              if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "stddev"}
        ratios = [sd[n] / self.rows[n]["cpu_time"] for n in sd
                  if n in self.rows and self.rows[n].get("cpu_time")]
        return statistics.median(ratios) if ratios else float("nan")

    def wall_over_cpu(self):
        ratios = [b["real_time"] / b["cpu_time"] for b in self.rows.values()
                  if b.get("aggregate_name") == "median" and b.get("cpu_time")]
        return statistics.median(ratios) if ratios else float("nan")


def ns(x):
    return "%.0f ns" % x if x < 1e4 else "%.1f µs" % (x / 1e3)


def verdict(ratio, target):
    return "%.3f (%g: %s)" % (ratio, target, "met" if ratio <= target else "missed")


def loads_table(r):
    rows = []
    models = [("Panda chain (7 joints)", "panda_chain", "kdlChain", "ChainIdSolver_RNE",
               TARGETS["kdl_chain"]),
              ("UR5 chain (6)", "ur5_chain", "kdlChain", "ChainIdSolver_RNE", TARGETS["kdl_chain"]),
              ("Kinova chain (6)", "kinova_chain", "kdlChain", "ChainIdSolver_RNE",
               TARGETS["kdl_chain"]),
              ("Panda with hand (9)", "panda", "kdlTree", "TreeIdSolver_RNE", None),
              ("Talos, fixed pelvis (32)", "talos", "kdlTree", "TreeIdSolver_RNE",
               TARGETS["kdl_tree_talos"])]
    for label, model, peer, solver, target in models:
        ours, theirs = r.cpu("coreDouble/" + model), r.cpu(peer + "/" + model)
        ratio = ours / theirs
        rows.append([label, ns(ours), ns(r.cpu("coreDoubleWorld/" + model)),
                     "%s (`%s`)" % (ns(theirs), solver),
                     verdict(ratio, target) if target else "%.3f" % ratio])
    return table(["model", "ours", "with world poses", "KDL, efforts only", "ratio (target)"], rows)


def step_sentences(r):
    full = ", ".join("%.2f× (%s)" % (r.cpu("fullStep/" + a) / r.cpu("coreDouble/" + a), a)
                     for a, _ in ARMS)
    filt = ", ".join("%.0f ns, %.2f× (%s, %d channels)"
                     % (r.cpu("filterBank/kalman_cj/%d" % n),
                        r.cpu("filterBank/kalman_cj/%d" % n) / r.cpu("coreDouble/" + a), a, n)
                     for a, n in ARMS)
    return ("The full estimator step with every default (`fullStep`: the constant-jerk Kalman "
            "filter and the exact savings, a moving arm) over the loads alone: %s (target %g). "
            "The default filter alone (`filterBank/kalman_cj`) over the loads alone: %s "
            "(target %g): its step multiplies by the nonzero entries of the integrator chain's "
            "transition matrix only and writes the estimate in the same pass.\n"
            % (full, TARGETS["full_step"], filt, TARGETS["filter"]))


def filter_table(r):
    names = [("Kalman, constant jerk (default)", "filterBank/kalman_cj"),
             ("Kalman, constant acceleration", "filterBank/kalman_ca"),
             ("Savitzky–Golay 9, causal", "filterBank/savitzky_golay_9"),
             ("finite difference, 3 points", "filterBank/finite_difference"),
             ("adaptive (8 Kalman filters)", "filterBank/adaptive"),
             ("Kalman smoother, constant jerk, `lag: 0.1`", "smootherBank"),
             ("adaptive smoother, `lag: 0.1`", "adaptiveSmootherBank")]
    rows = [[label] + [ns(r.cpu("%s/%d" % (name, n))) for n in (6, 7, 19, 50)]
            for label, name in names]
    return table(["filter", "6 ch", "7 ch", "19 ch", "50 ch"], rows)


def smoother_sentence(r):
    cells = ", ".join("%.2f× against %.2f× (%s)"
                      % (r.cpu("fullStepSmoother/" + a) / r.cpu("coreDouble/" + a),
                         r.cpu("fullStep/" + a) / r.cpu("coreDouble/" + a), a) for a, _ in ARMS)
    return ("With the Kalman smoother (`differentiator/lag: 0.1`, `fullStepSmoother`) the full "
            "step over the loads alone is %s with the causal default.\n" % cells)


def scaling_sentence(r):
    parts = []
    for shape in ("chain", "tree"):
        fit = r.rows.get("scaling/%s_BigO" % shape)
        growth = (r.cpu("scaling/%s/1000" % shape) / 1000) / (r.cpu("scaling/%s/100" % shape) / 100)
        parts.append("%ss %.0f ns per joint (Google Benchmark's O(N) fit), the per-joint cost "
                     "at 1000 joints %.2f× that at 100 (linear: at most %g)"
                     % (shape, fit["cpu_coefficient"] if fit else float("nan"), growth,
                        LINEAR_PER_JOINT))
    return "Random chains and trees of 1 to 1000 joints: " + "; ".join(parts) + ".\n"


def change(on, off):
    return "%s / %s (%+.0f%%)" % (ns(on), ns(off), 100 * (on / off - 1))


def savings_table(r):
    def step(name):
        return r.cpu("estimatorStep/" + name)

    rows = [
        ["`prune`", "the published joints are a subset",
         "Talos, one knee published: " + change(step("talos_one_knee_moving_defaults"),
                                                 step("talos_one_knee_moving_prune_off")),
         "Talos, all joints: " + change(step("talos_all_moving_defaults"),
                                        step("talos_all_moving_prune_off"))],
        ["`reuse_unchanged`", "the filtered inputs repeat (robot still, no noisy sensor)",
         "Talos still: %s; Panda still: %s"
         % (change(step("talos_all_still_defaults"), step("talos_all_still_reuse_off")),
            change(step("panda_chain_still_defaults"), step("panda_chain_still_reuse_off"))),
         "Talos moving: " + change(step("talos_all_moving_defaults"),
                                   step("talos_all_moving_reuse_off"))],
        ["`massless_chains`", "segments without mass",
         "planar arm: " + change(step("planar_arm_moving_defaults"),
                                 step("planar_arm_moving_massless_off")),
         "Panda moving: " + change(step("panda_chain_moving_defaults"),
                                   step("panda_chain_moving_massless_off"))],
        ["`gyroscopic`", "ω along a principal axis (planar chains)",
         "planar arm: " + change(step("planar_arm_moving_defaults"),
                                 step("planar_arm_moving_gyroscopic_off")),
         "Panda moving: " + change(step("panda_chain_moving_defaults"),
                                   step("panda_chain_moving_gyroscopic_off"))],
        ["`planar` (`auto`)", "every computed joint turns about one normal, gravity and applied "
         "wrenches in the plane",
         "12-link planar chain, gravity in the plane: %s; planar arm: %s"
         % (change(step("planar_chain_vertical_planar_auto"),
                   step("planar_chain_vertical_planar_off")),
            change(step("planar_arm_vertical_planar_auto"), step("planar_arm_vertical_planar_off"))),
         "Panda moving (refused at start-up): " + change(step("panda_chain_moving_planar_auto"),
                                                          step("panda_chain_moving_planar_off"))],
        ["`static_velocity/acceleration` (off: not exact)", "every q̇, q̈ below the thresholds",
         "Panda still, switched on: " + change(step("panda_chain_still_static_on"),
                                               step("panda_chain_still_defaults")),
         "Talos moving, switched on: " + change(step("talos_all_moving_static_on"),
                                                step("talos_all_moving_defaults"))],
        ["every saving off (`none`)", "", "Talos moving, defaults / none: "
         + change(step("talos_all_moving_defaults"), step("talos_all_moving_none")), ""],
        ["`precision: float`", "", "Talos moving, float / double: "
         + change(step("talos_all_moving_float"), step("talos_all_moving_defaults")), ""],
    ]
    return table(["saving", "applies when", "where it applies: on / off (change)",
                  "where it does not: on / off (change)"], rows)


def messages_table(m):
    est = m.cpu("estimatorOnly")
    rows = [["the Estimator alone", ns(est), "1"]]
    for arg, label in ((0, "the message path, immediate stream only"),
                       (1, "the message path, both streams (default)")):
        t = m.cpu("nodeMessagePath/%d" % arg)
        rows.append([label + " (`nodeMessagePath/%d`)" % arg, ns(t), "%.2f" % (t / est)])
    return table(["per sample, 7-joint arm", "CPU time", "over the Estimator alone"], rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("core")
    parser.add_argument("messages")
    for key in ("load-before", "load-after", "command", "output"):
        parser.add_argument("--" + key, required=True)
    args = parser.parse_args()
    r, m = Runs(args.core), Runs(args.messages)
    reps = max((b.get("repetitions", 1) for b in r.rows.values()), default=1)
    text = ["# Speed\n",
            "Generated by `%s` (bench/speed_core.cpp, bench/speed_messages.cpp, "
            "tools/speed_page.py); do not edit. Machine: %s; %s; median wall / CPU time of "
            "the rows %.2f (above 1: the benchmark waited for a core). Google Benchmark, "
            "Release, CPU time per sample, medians of %d interleaved repetitions; absolute "
            "times move between machines and loads, the ratios are of rows of the same run. "
            "The repetitions of a row differ by %.0f%% (median over the rows of their "
            "standard deviation over their median): a difference of two rows below about "
            "twice that is noise of this run.\n"
            % (args.command, machine(), load_span(args.load_before, args.load_after),
               r.wall_over_cpu(), reps, 100 * r.spread()),
            "\"Ours\" is every joint's 6-D wrench over the segment-frame kinematics "
            "(`localKinematics` + `inverseDynamics`); KDL's recursive Newton–Euler (Debian's "
            "liborocos-kdl, measured in the same process on the same 256 random states, same "
            "compiler and flags) computes the torques over the same kinematics; neither "
            "computes world poses (`worldPoses()`, a pass of its own, adds them where a "
            "world-frame input or output needs them; `forwardKinematics` does both).\n",
            "## The loads against KDL\n", loads_table(r), LEAN,
            "## The estimator step and its filters\n", step_sentences(r),
            "\nPer sample and channel count (`filterBank/<type>/<channels>`, `smootherBank`, "
            "`adaptiveSmootherBank`):\n", filter_table(r), "\n" + smoother_sentence(r),
            "\n" + scaling_sentence(r),
            "\n`process_bag`'s throughput: [offline_throughput.md](offline_throughput.md); the "
            "node end to end: [node_latency.md](node_latency.md).\n",
            "## The message path\n",
            "`bench_speed_messages` (the node's own code, 7-joint arm, default settings): a "
            "`sensor_msgs/JointState` through `jle::feed` (the Pipeline), the record into "
            "`~joint_loads` (`jle::toMessage`) and its serialisation, against the same "
            "samples given to the Estimator alone:\n", messages_table(m),
            "## Savings\n",
            "What the estimator skips when a scene does not need it (`savings/*` parameters; "
            "the exact ones are on by default, and `test/algorithms/test_savings.cpp` checks "
            "that each leaves the loads bit-identical). Time per joint sample through the "
            "estimator (filter, kinematics, dynamics), `estimatorStep/<scene>_<setting>`:\n",
            savings_table(r),
            "\n`decimation` computes every n-th sample (the filters see all); "
            "`~wrench/<joint>` is computed only when subscribed. The planar reduction "
            "publishes the same 6-D wrenches within 1e-12 relative "
            "(`test/algorithms/test_planar.cpp`; conditions in "
            "`include/joint_load_estimator/model/planar.hpp`); its effect on accuracy and run time "
            "in the accuracy study: [accuracy.md](accuracy.md), scene `planar_savings`.\n",
            LINKING]
    with open(args.output, "w", encoding="utf-8") as f:
        f.write("\n".join(text))
    print("speed_page: wrote %s" % args.output)


if __name__ == "__main__":
    main()
