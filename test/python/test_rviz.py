"""rviz for any robot in one command (docs/rviz.md): `estimator.launch model:=URDF
rviz:=true` for a robot the package does not otherwise use (test/data/urdf/upright_arm.urdf,
its meshes package:// URIs of a package that does not exist), fed by make_example_bag's
bag played with --clock --loop, on a roscore and an Xvfb of its own. Once the smoothed
wrenches flow, screenshots (ImageMagick's import) of rviz's 3-D view must show the robot
(the shapes' steel blue, wholly inside the view), the force arrows' red and the joint
names' white; and rviz's logs no mesh or resource error. Fails, not skips, without rviz,
Xvfb, import, roscore or make_example_bag (JLE_MAKE_EXAMPLE_BAG: test/CMakeLists.txt
sets it; tools/install_deps.sh installs the rest)."""

import glob
import os
import shutil
import signal
import subprocess
import tempfile
import time

import numpy as np
import pytest

from test_master_restart import ROSCORE, Master, free_port

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
URDF = os.path.join(REPO, "test", "data", "urdf", "upright_arm.urdf")
MAKE_EXAMPLE_BAG = os.environ.get("JLE_MAKE_EXAMPLE_BAG", "")
BIN = "/usr/bin:/opt/ros/noetic/bin"
TOOLS = {name: shutil.which(name, path=BIN) for name in ("rviz", "Xvfb", "import", "convert",
                                                          "roslaunch", "rosbag", "rostopic")}
BACKGROUND = 48  # rviz_config's Background Color, grey
# What rviz's mesh loader and rospack say of a mesh that does not resolve.
MESH_ERRORS = ("Could not load resource", "Error retrieving file", "[rospack] Error")


def start(command, env, log, **kwargs):
    """`command` in its own process group (roslaunch's children with it)."""
    return subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True, **kwargs)


def stop(process):
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def xvfb(env, log):
    """Xvfb on a free display (it picks one: -displayfd); the process and DISPLAY."""
    read, write = os.pipe()
    process = start([TOOLS["Xvfb"], "-displayfd", str(write), "-screen", "0", "1200x800x24",
                     "-nolisten", "tcp"], env, log, pass_fds=(write,))
    os.close(write)
    with os.fdopen(read) as f:
        number = f.readline().strip()
    assert number, "Xvfb gave no display number (log: %s)" % log.name
    return process, ":" + number


def screenshot(path, env):
    """The screen as an H x W x 3 array of 0..255 (import, then convert to PPM)."""
    subprocess.run([TOOLS["import"], "-window", "root", path], env=env, check=True, timeout=30)
    ppm = subprocess.run([TOOLS["convert"], path, "-depth", "8", "ppm:-"], env=env,
                         check=True, capture_output=True, timeout=30).stdout
    magic, size, depth, data = ppm.split(b"\n", 3)
    assert magic == b"P6" and depth == b"255", ppm[:20]
    width, height = map(int, size.split())
    return np.frombuffer(data, np.uint8).reshape(height, width, 3).astype(int)


def longest_run(mask):
    """First and last index of the longest run of True in a 1-D mask ((0, -1): none)."""
    best, start_index = (0, -1), None
    for i, on in enumerate(list(mask) + [False]):
        if on and start_index is None:
            start_index = i
        elif not on and start_index is not None:
            if i - start_index > best[1] - best[0] + 1:
                best = (start_index, i - 1)
            start_index = None
    return best


def view_problems(image):
    """What the 3-D view lacks: [] when rviz shows the robot, its arrows and its labels.
    The view is the longest run of columns, then of rows, where the background grey is
    common (the panels beside it hold little of it)."""
    background = np.abs(image - BACKGROUND).max(axis=2) <= 2
    x0, x1 = longest_run(background.mean(axis=0) > 0.3)
    y0, y1 = longest_run(background[:, x0:x1 + 1].mean(axis=1) > 0.3) if x1 > x0 else (0, -1)
    if x1 - x0 < 200 or y1 - y0 < 200:
        return ["no 3-D view (no region of rviz's background grey: blank or black screen)"]
    view = image[y0:y1 + 1, x0:x1 + 1]
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    robot = (b > r + 40) & (b > g + 15)  # steel blue, shaded
    arrows = (r > g + 60) & (r > b + 60)  # the force arrows' red
    labels = (r > 220) & (g > 220) & (b > 220)  # the joint names' white
    problems = []
    for name, mask, least in (("robot", robot, 500), ("force arrows", arrows, 500),
                              ("joint names", labels, 100)):
        if mask.sum() < least:
            problems.append("%s: %d pixels of its colour in the view, fewer than %d"
                            % (name, mask.sum(), least))
    if robot.any():
        ys, xs = np.nonzero(robot)
        margin = 3
        if (xs.min() < margin or ys.min() < margin or xs.max() > view.shape[1] - 1 - margin
                or ys.max() > view.shape[0] - 1 - margin):
            problems.append("robot not inside the view: pixels x %d..%d, y %d..%d of %dx%d"
                            % (xs.min(), xs.max(), ys.min(), ys.max(), view.shape[1],
                               view.shape[0]))
    return problems


def mesh_errors(log_dir):
    found = []
    for path in glob.glob(os.path.join(log_dir, "**", "*.log"), recursive=True):
        with open(path, errors="replace") as f:
            found += ["%s: %s" % (os.path.basename(path), line.strip()[:200])
                      for line in f if any(e in line for e in MESH_ERRORS)]
    return found


def test_one_command_shows_the_robot_its_wrenches_and_their_names_without_meshes():
    missing = [n for n, p in TOOLS.items() if not p] + [n for n, p in (
        ("roscore", ROSCORE), ("JLE_MAKE_EXAMPLE_BAG", MAKE_EXAMPLE_BAG)) if not p]
    if missing:  # tools/install_deps.sh installs them, test/CMakeLists.txt sets the bag's
        pytest.fail("not available: %s" % ", ".join(missing))
    work = tempfile.mkdtemp(prefix="jle_rviz_")
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_HOSTNAME="127.0.0.1",
               ROS_LOG_DIR=os.path.join(work, "log"), ROS_HOME=work, LIBGL_ALWAYS_SOFTWARE="1")
    env.pop("ROS_NAMESPACE", None)
    bag = os.path.join(work, "arm.bag")
    subprocess.run([MAKE_EXAMPLE_BAG, "--urdf", URDF, "--output", bag, "--duration", "20",
                    "--sensor-frame", "tool", "--tcp-frame", "tool"], env=env, check=True,
                   capture_output=True, timeout=60)
    logs = {name: open(os.path.join(work, name + ".log"), "w")
            for name in ("roscore", "xvfb", "launch", "play")}
    processes = []
    try:
        processes.append(Master(port, env, logs["roscore"]))
        display_process, env["DISPLAY"] = xvfb(env, logs["xvfb"])
        processes.append(display_process)
        processes.append(start([TOOLS["roslaunch"], os.path.join(REPO, "launch", "estimator.launch"),
                                "model:=" + URDF, "rviz:=true", "use_sim_time:=true"],
                               env, logs["launch"]))
        processes.append(start([TOOLS["rosbag"], "play", "--clock", "--loop", "--quiet", bag],
                               env, logs["play"]))
        echo = subprocess.run([TOOLS["rostopic"], "echo", "-n", "1",
                               "/joint_load_estimator/smoothed/wrench/wrist_roll"],
                              env=env, capture_output=True, text=True, timeout=120)
        assert 'frame_id: "hand"' in echo.stdout, (echo.stdout, echo.stderr)
        shot = os.path.join(work, "rviz.png")
        problems = ["no screenshot taken"]
        end = time.time() + 90
        while problems and time.time() < end:
            problems = view_problems(screenshot(shot, env))
            if problems:
                time.sleep(1)
        assert not problems, "%s (screenshot %s)" % ("; ".join(problems), shot)
        errors = mesh_errors(env["ROS_LOG_DIR"])
        assert not errors, "\n".join(errors)
    finally:
        for process in reversed(processes):
            process.stop() if isinstance(process, Master) else stop(process)
        for log in logs.values():
            log.close()
    shutil.rmtree(work, ignore_errors=True)
