"""A restarted roscore knows none of a running node's topics (roscpp registers them once):
the node must say so. The test starts its own master (roscore -p on a free port), the real
node against it (JLE_NODE, the node's executable; the test fails without it), stops the master
and starts it again, and reads the node's errors: the master that stops answering, then
the restart (another /run_id); with exit_on_master_restart the node shuts down (so that
respawn="true" starts it again, registered)."""

import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import xmlrpc.client

import pytest

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
URDF = os.path.join(REPO, "test", "data", "urdf", "chains", "ur5_chain.urdf")
NODE = os.environ.get("JLE_NODE", "")
ROSCORE = shutil.which("roscore", path="/usr/bin:/opt/ros/noetic/bin") or ""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, timeout, what):
    end = time.time() + timeout
    while time.time() < end:
        if condition():
            return
        time.sleep(0.1)
    raise AssertionError("timed out after %g s waiting for %s" % (timeout, what))


class Master:
    """roscore on `port`, in its own process group (its rosmaster and rosout with it)."""

    def __init__(self, port, env, log):
        self.uri = "http://127.0.0.1:%d" % port
        self.proc = subprocess.Popen([ROSCORE, "-p", str(port)], env=env,
                                     stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        wait_for(self.answers, 30, "roscore on port %d" % port)

    def proxy(self):
        return xmlrpc.client.ServerProxy(self.uri)

    def answers(self):
        try:
            return self.proxy().getPid("/test")[0] == 1
        except OSError:
            return False

    def set(self, name, value):
        assert self.proxy().setParam("/test", name, value)[0] == 1

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            self.proc.wait(timeout=30)


def test_a_restarted_master_is_said_and_exit_on_master_restart_shuts_down():
    # test/CMakeLists.txt sets JLE_NODE and install_deps.sh installs roscore: a run
    # without them must not pass.
    if not ROSCORE or not NODE:
        pytest.fail("roscore (%r) or the node (JLE_NODE=%r) not available" % (ROSCORE, NODE))
    port = free_port()
    work = tempfile.mkdtemp(prefix="jle_master_")
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=work,
               ROS_HOSTNAME="127.0.0.1")
    master_log = open(os.path.join(work, "roscore.log"), "w")
    node_log_path = os.path.join(work, "node.log")
    master = Master(port, env, master_log)
    node = None
    try:
        with open(URDF) as f:
            master.set("/robot_description", f.read())
        master.set("/joint_load_estimator/diagnostic_period", 0.2)
        master.set("/joint_load_estimator/exit_on_master_restart", True)
        node_log = open(node_log_path, "w")
        node = subprocess.Popen([NODE], env=env, stdout=node_log, stderr=subprocess.STDOUT,
                                start_new_session=True)

        def registered():
            code, _, uri = master.proxy().lookupNode("/test", "/joint_load_estimator")
            return code == 1 and bool(uri)

        wait_for(registered, 30, "the node to register")

        def said(text):
            with open(node_log_path) as f:
                return text in f.read()

        master.stop()
        wait_for(lambda: said("does not answer"), 10, "the node to say its master is gone")
        assert node.poll() is None, "the node exited while the master was down"
        master = Master(port, env, master_log)
        wait_for(lambda: said("was restarted"), 10, "the node to say its master was restarted")
        wait_for(lambda: node.poll() is not None, 10, "exit_on_master_restart to shut it down")
        with open(node_log_path) as f:
            text = f.read()
        assert "Restart this node" in text, text
        assert "exit_on_master_restart: shutting down" in text, text
        # The two run_ids named, and they differ (not the old one read twice).
        said_ids = text.split("was restarted (run_id '")[1].split("'")
        assert said_ids[0] != said_ids[2] and "unknown" not in said_ids[:3], text
    finally:
        if node is not None and node.poll() is None:
            os.killpg(node.pid, signal.SIGINT)
            node.wait(timeout=30)
        master.stop()
        master_log.close()
