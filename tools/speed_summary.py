"""The summary of tools/speed.sh: ratios against the targets of issue 15, before/after.

Reads Google Benchmark's JSON output of bench_speed_core. With repetitions, each row's
median is used; without, its single run. Exits 1 if a target is missed (or its rows are
missing), so that the script can gate a change.
"""
import json
import sys

ARMS = [("panda_chain", 7), ("ur5_chain", 6), ("kinova_chain", 6)]
TARGETS = {"kdl_chain": 0.20, "kdl_tree_talos": 0.025, "full_step": 1.3, "filter": 0.3}
# Linear: the per-joint cost at 1000 joints over that at 100. The O(N) fit's RMS is
# printed too, but it also holds the fixed cost of the small models (1 and 3 joints) and
# the noise of a shared machine, so it does not decide.
LINEAR_PER_JOINT = 1.5


def load(path):
    rows, medians = {}, {}
    for b in json.load(open(path))["benchmarks"]:
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                medians[b["run_name"]] = b
            elif b.get("aggregate_name") in ("BigO", "RMS"):
                rows[b["name"]] = b
        else:
            rows.setdefault(b.get("run_name", b["name"]), b)
    rows.update(medians)
    return rows


def main():
    runs = load(sys.argv[1])
    failed = []

    def cpu(name):
        b = runs.get(name)
        return None if b is None else b["cpu_time"]

    def check(label, ours, theirs, target):
        a, b = cpu(ours), cpu(theirs)
        if a is None or b is None:
            print(f"  {label:44s} missing rows ({ours}, {theirs})")
            failed.append(label)
            return
        ratio = a / b
        ok = ratio <= target
        if not ok:
            failed.append(label)
        print(f"  {label:44s} {a:9.0f} / {b:9.0f} ns = {ratio:6.3f}  (target <= {target}) "
              f"{'pass' if ok else 'FAIL'}")

    print("\nTargets (CPU time per sample; ours: all 6-D joint wrenches, KDL: the torques):")
    for arm, _ in ARMS:
        check(f"{arm}: ours / KDL ChainIdSolver_RNE", f"coreDouble/{arm}", f"kdlChain/{arm}",
              TARGETS["kdl_chain"])
    check("talos: ours / KDL TreeIdSolver_RNE", "coreDouble/talos", "kdlTree/talos",
          TARGETS["kdl_tree_talos"])
    for arm, _ in ARMS:
        check(f"{arm}: full step (defaults) / loads alone", f"fullStep/{arm}", f"coreDouble/{arm}",
              TARGETS["full_step"])
    for arm, nq in ARMS:
        check(f"{arm}: default filter ({nq} ch) / loads alone", f"filterBank/kalman_cj/{nq}",
              f"coreDouble/{arm}", TARGETS["filter"])
    for shape in ("chain", "tree"):
        fit, rms = runs.get(f"scaling/{shape}_BigO"), runs.get(f"scaling/{shape}_RMS")
        t100, t1000 = cpu(f"scaling/{shape}/100"), cpu(f"scaling/{shape}/1000")
        if not (fit and rms and t100 and t1000):
            print(f"  scaling {shape}: missing rows")
            failed.append(f"scaling {shape}")
            continue
        growth = (t1000 / 1000) / (t100 / 100)
        ok = growth <= LINEAR_PER_JOINT
        if not ok:
            failed.append(f"scaling {shape}")
        print(f"  scaling {shape:5s} to 1000 joints: {fit['cpu_coefficient']:.1f} ns per joint, "
              f"RMS of the O(N) fit {100 * rms['rms']:.1f}%, "
              f"per joint at 1000 / at 100 {growth:.2f} (<= {LINEAR_PER_JOINT}) "
              f"{'pass' if ok else 'FAIL'}")

    print("\nWith world poses (forwardKinematics) and the filter bank, CPU time per sample:")
    for model in [a for a, _ in ARMS] + ["panda", "talos"]:
        new, world = cpu(f"coreDouble/{model}"), cpu(f"coreDoubleWorld/{model}")
        if new and world:
            print(f"  {model:13s} loads {new:7.0f} ns; with world poses {world:7.0f} ns "
                  f"({world / new:.2f}x)")
    for name in ("kalman_cj", "kalman_ca", "savitzky_golay_9", "finite_difference", "adaptive"):
        cells = [f"{ch:2d} ch {cpu(f'filterBank/{name}/{ch}'):6.0f} ns" for ch in (6, 7, 19, 50)
                 if cpu(f"filterBank/{name}/{ch}")]
        if cells:
            print(f"  filter {name:17s} " + ", ".join(cells))

    print("\nAll 6-D joint wrenches (ours) against KDL's efforts, CPU time per sample:")
    pairs = [("panda_chain", "kdlChain"), ("ur5_chain", "kdlChain"), ("kinova_chain", "kdlChain"),
             ("panda_chain", "kdlTree"), ("panda", "kdlTree"), ("talos", "kdlTree")]
    for model, peer in pairs:
        ours, theirs = cpu("coreDouble/" + model), cpu(peer + "/" + model)
        if ours and theirs:
            print(f"  {model:13s} ours {ours:9.0f} ns   {peer:9s} {theirs:9.0f} ns"
                  f"   ratio {ours / theirs:.3f}")
    if failed:
        print("\nmissed: " + "; ".join(failed))
        return 1
    print("\nevery target met")
    return 0


if __name__ == "__main__":
    sys.exit(main())
