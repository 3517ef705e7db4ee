"""The launch files' arguments as a user meets them (roslaunch --ros-args): every declared
argument has a doc, none has an empty default (roslaunch lists such an argument as
required), and estimator.launch, the node beside a robot's stack, requires none."""

import glob
import os
import subprocess
import xml.etree.ElementTree as ET

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
LAUNCH = sorted(glob.glob(os.path.join(REPO, "launch", "*.launch")))


def declared(path):
    """The <arg> declarations of a launch file (not the values given to an include)."""
    return [a for a in ET.parse(path).getroot().iter("arg") if "value" not in a.attrib]


def test_every_argument_is_documented_and_no_default_is_empty():
    assert len(LAUNCH) >= 4
    found = []
    for path in LAUNCH:
        for arg in declared(path):
            where = "%s: %s" % (os.path.basename(path), arg.get("name"))
            if not arg.get("doc"):
                found.append(where + ": no doc")
            if arg.get("default") == "":
                found.append(where + ": an empty default (listed as required)")
    assert not found, "\n".join(found)


def test_estimator_launch_requires_no_argument():
    run = subprocess.run(["/usr/bin/roslaunch", "--ros-args",
                          os.path.join(REPO, "launch", "estimator.launch")],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert "Required Arguments" not in run.stdout, run.stdout
    for name in ("model", "ns", "config", "joint_states", "robot_description"):
        assert "  %s (default " % name in run.stdout, (name, run.stdout)
