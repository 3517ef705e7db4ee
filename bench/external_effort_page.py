"""The tables of docs/studies/external_effort.md from the outputs of bench_external_effort and
test_external_effort (run by bench/external_effort.sh --page).

    external_effort_page.py speed BENCH.json     the time per sample (Google Benchmark JSON)
    external_effort_page.py free TEST.txt        the free-motion table (the test's lines)
"""
import json
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import study_page  # noqa: E402

ROWS = [("BM_OursExternalEffort",
         "ours: forward pass, M, Cᵀq̇, g, observer, residual, one DLS solve"),
        ("BM_OursJointSpaceTerms", "ours: the joint-space terms alone (forward pass, M, Cᵀq̇, g, p)"),
        ("BM_KdlExternalWrenchEstimator", "KDL `ChainExternalWrenchEstimator::JntToExtWrench`"),
        ("BM_LoadsAlone", "the loads alone (`jle::rnea`, forward + backward pass)")]
SCALE = {"ns": 1e-3, "us": 1.0, "ms": 1e3}


def speed(path):
    with open(path) as f:
        runs = json.load(f)["benchmarks"]
    median = {}
    for r in runs:
        if r.get("aggregate_name") == "median":
            median[r["run_name"]] = r["cpu_time"] * SCALE[r["time_unit"]]
    kdl, loads = median["BM_KdlExternalWrenchEstimator"], median["BM_LoadsAlone"]
    rows = [(label, "%.2f µs" % median[name], "%.2f" % (median[name] / kdl),
             "%.2g" % (median[name] / loads)) for name, label in ROWS]
    return study_page.table(["per sample", "CPU time", "ratio to KDL's estimator",
                             "ratio to the loads alone"], rows)


def free(path):
    text = open(path).read()
    rows = []
    for method in ("residual", "observer"):
        m = re.search(r"^%s: free samples (\d+), false-contact samples (\d+), RMS tau_ext "
                      r"\[N m\]: (.*)$" % method, text, re.MULTILINE)
        c = re.search(r"^%s: contacts started \d+ at .*, RMS force error (\S+) N$" % method,
                      text, re.MULTILINE)
        if not m or not c:
            sys.exit("external_effort_page: no %s lines in %s" % (method, path))
        rows.append((method, m.group(3), "%s / %s" % (m.group(2), m.group(1)), c.group(1)))
    return study_page.table(["method", "RMS τ_ext per joint in free motion [N m] (joints 1..7)",
                             "false-contact samples", "RMS force error in contact [N]"], rows)


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("speed", "free"):
        sys.exit(__doc__)
    sys.stdout.write({"speed": speed, "free": free}[sys.argv[1]](sys.argv[2]))
