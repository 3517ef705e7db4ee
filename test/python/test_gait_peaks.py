"""The gait demo's peak-moment table (tools/gait_peaks.py):
docs/biomechanics.md and docs/gait_demo.md hold what the script prints today (regenerated, never edited by hand);
every moment table of theirs has the sign convention beside it; and the table's peaks
have the signs and instants that the trial's mechanics demand, argued here without the
tools: in the heel rocker (0 - 10 % of the cycle) the ground reaction acts at the heel,
behind the ankle, and turns the foot down, so the ankle's moment on the foot is a
dorsiflexor one (positive); in terminal stance (30 - 60 %) it acts at the forefoot, ahead
of the ankle, so the ankle's is a plantarflexor one (negative). Run by pytest with
JLE_JOINT_LOADS (its workspace's make_gait_bag beside it)."""

import os
import re
import subprocess

import pytest

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCRIPT = os.path.join(REPO, "tools", "gait_peaks.py")
BEGIN = "<!-- tools/gait_peaks.py: begin (generated; do not edit) -->"
END = "<!-- tools/gait_peaks.py: end -->"
DOCS = [os.path.join(REPO, "docs", "biomechanics.md"), os.path.join(REPO, "docs", "gait_demo.md")]


@pytest.fixture(scope="module")
def table():
    joint_loads = os.environ.get("JLE_JOINT_LOADS")
    if not joint_loads:  # test/CMakeLists.txt sets it; a run without it must not pass
        pytest.fail("JLE_JOINT_LOADS (the path of the joint_loads tool) is not set")
    ws = os.path.abspath(os.path.join(os.path.dirname(joint_loads), "..", "..", ".."))
    r = subprocess.run(["/usr/bin/python3", SCRIPT, "--ws", ws], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


def rows(text):
    """{(joint, sense): (peak, percent)} of the generated table."""
    out = {}
    for m in re.finditer(r"^\| ([a-z ]+), ([a-z ]+) \| ([+-][0-9.]+) \| ([0-9]+) \|", text, re.M):
        out[(m.group(1), m.group(2))] = (float(m.group(3)), float(m.group(4)))
    return out


def without_machine(text):
    """The table without the machine named in its last line: the figures are exact
    (deterministic), the same on any machine; the line records where they were made."""
    return re.sub(r"^(Made by .*; ).*(\)\.)$", r"\1MACHINE\2", text, flags=re.M)


def test_docs_hold_the_scripts_table(table):
    assert without_machine(table) != table, "the table names no machine"
    for path in DOCS:
        text = open(path).read()
        begin, end = text.find(BEGIN), text.find(END)
        assert 0 <= begin < end, "%s: no generated block" % path
        assert without_machine(text[begin + len(BEGIN) + 1:end]) == without_machine(table), (
            "%s: the peak table is not what tools/gait_peaks.py prints (run it with "
            "--update %s)" % (path, os.path.relpath(path, REPO)))


def test_every_peak_of_either_sign_is_listed(table):
    peaks = rows(table)
    for joint, senses in [("hip flexion", ("flexor", "extensor")),
                          ("hip adduction", ("adductor", "abductor")),
                          ("hip rotation", ("internal rotator", "external rotator")),
                          ("knee flexion", ("flexor", "extensor")),
                          ("ankle flexion", ("dorsiflexor", "plantarflexor"))]:
        assert peaks[(joint, senses[0])][0] >= 0.0, joint
        assert peaks[(joint, senses[1])][0] <= 0.0, joint


def test_ankle_peaks_have_the_mechanics_signs_and_instants(table):
    peaks = rows(table)
    dorsi, at = peaks[("ankle flexion", "dorsiflexor")]
    assert dorsi > 0.5 and 0.0 <= at <= 10.0, (dorsi, at)  # heel rocker: +1.10 at 9 %
    plantar, at = peaks[("ankle flexion", "plantarflexor")]
    assert plantar < -1.0 and 30.0 <= at <= 60.0, (plantar, at)


def test_every_moment_table_has_the_sign_convention_beside_it():
    for path in DOCS:
        lines = open(path).read().split("\n")
        for i, line in enumerate(lines):
            header = line.strip()
            previous = lines[i - 1].strip() if i else ""
            if not header.startswith("|") or previous.startswith("|"):
                continue
            if not re.search(r"moment|ankle flexion|knee flexion", header):
                continue
            nearby = " ".join(lines[max(0, i - 8):i]).lower()
            assert "sign convention" in nearby, "%s:%d: a moment table without the sign " \
                "convention in the 8 lines above it" % (path, i + 1)
