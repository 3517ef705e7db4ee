"""The Python bindings (joint_load_estimator) against the C++ tools on the same inputs
(joint_loads on the same CSV, process_bag on the same bag: the same numbers to 1e-12)
and against a closed form (a pendulum). Run by test/CMakeLists.txt under pytest, with
the tools' paths in JLE_JOINT_LOADS, JLE_PROCESS_BAG, JLE_MAKE_EXAMPLE_BAG and the test
data in JLE_TEST_DATA."""

import csv
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import joint_load_estimator as jle

DATA = os.environ.get("JLE_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "data"))
REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
PANDA = os.path.join(DATA, "urdf", "panda.urdf")
BODY = os.path.join(DATA, "urdf", "body_75kg_175cm.urdf")
# Same code on the same inputs: equal to rounding. The bound is relative to the size of
# each number (at least 1 N or N m).
TOLERANCE = 1e-12


def tool(name):
    path = os.environ.get("JLE_" + name.upper())
    if not path:  # test/CMakeLists.txt sets them; a run without them must not pass
        pytest.fail("JLE_%s (the path of the %s tool) is not set" % (name.upper(), name))
    return path


def assert_same(actual, expected, what):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, what
    error = np.abs(actual - expected) / np.maximum(1.0, np.abs(expected))
    assert error.max(initial=0.0) <= TOLERANCE, "%s: largest relative difference %g" % (
        what, error.max())


def write_csv(path, header, rows):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(repr(float(x)) for x in row) + "\n")  # repr: exact round trip


def read_csv(path):
    with open(path) as f:
        reader = csv.reader(f)
        header = [h.strip() for h in next(reader)]
        values = np.array([[float(x) for x in row] for row in reader if row])
    return {h: values[:, i] for i, h in enumerate(header)}


def random_states(model, n, seed):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-2.0, 2.0, (n, model.nq)), rng.uniform(-3.0, 3.0, (n, model.nq)),
            rng.uniform(-20.0, 20.0, (n, model.nq)))


def plausible_states(model, n, seed):
    """Random states that joint_loads takes (docs/node.md "Never silently wrong": a position
    beyond the URDF limits by more than 1 rad, or a velocity beyond 3 times the limit, is
    refused): within [-0.9, 0.9] rad (every Panda and body joint's limits widened by the
    margin hold it) and [-0.5, 0.5] rad/s (the Panda's fingers: 3 x 0.2 m/s)."""
    rng = np.random.default_rng(seed)
    return (rng.uniform(-0.9, 0.9, (n, model.nq)), rng.uniform(-0.5, 0.5, (n, model.nq)),
            rng.uniform(-20.0, 20.0, (n, model.nq)))


# --- the package layout ------------------------------------------------------------
def test_package_exposes_the_core_beside_the_messages():
    assert jle.Model and jle.inverse_dynamics and jle.Estimator and jle.process_bag
    from joint_load_estimator.msg import JointLoads  # the generated message still imports
    assert "effort" in JointLoads.__slots__


def test_model_names_and_errors():
    model = jle.Model(PANDA)
    assert model.nq == 8 and model.coordinate_names[0] == "panda_joint1"
    assert model.joint_names[-1] == "panda_finger_joint2"  # a mimic joint's loads too
    assert "panda_hand" in model.link_names and model.total_mass > 10
    with open(PANDA) as f:
        assert jle.Model.from_string(f.read()).joint_names == model.joint_names
    with pytest.raises(ValueError, match="no_such.urdf"):
        jle.Model("no_such.urdf")
    with pytest.raises(ValueError, match="mass"):
        jle.Model.from_string('<robot name="r"><link name="a"><inertial><mass value="-1"/>'
                              '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
                              '</inertial></link></robot>')
    q, qd, qdd = random_states(model, 3, 0)
    with pytest.raises(ValueError, match=r"qd must have shape \(3, 8\)"):
        jle.inverse_dynamics(model, q, qd[:, :7], qdd)
    with pytest.raises(ValueError, match="unknown link 'nowhere'"):
        jle.inverse_dynamics(model, q, qd, qdd, wrenches={"nowhere": np.zeros((3, 6))})
    with pytest.raises(ValueError, match="frame"):
        jle.inverse_dynamics(model, q, qd, qdd, frame="tool")



def test_identified_inertia_needs_the_option():
    """identified_pendulum.urdf (test/data/urdf/SOURCE.md): 'arm' not positive
    semi-definite, 'hand' breaking the triangle inequality. Refused by default; accepted
    with a warning per violation; the effort about the axis is then the closed form
    (0.3 + 2 * 0.5^2 + 0.01 + 1 * 1^2) q'' - (2 * 0.5 + 1 * 1) g cos q, where the
    offending ixx and izz do not enter."""
    path = os.path.join(DATA, "urdf", "identified_pendulum.urdf")
    with pytest.raises(ValueError, match="link 'arm': inertia is not positive semi-definite"):
        jle.Model(path)
    model = jle.Model(path, accept_nonphysical_inertia=True)
    for part in ("link 'arm': inertia is not positive semi-definite",
                 "link 'hand': inertia violates the triangle inequality"):
        assert any(part in w for w in model.warnings), (part, model.warnings)
    with open(path) as f:
        assert jle.Model.from_string(f.read(), accept_nonphysical_inertia=True).nq == 1
    q, qd, qdd = (x[:, :1] for x in random_states(model, 50, 3))
    g = -jle.default_gravity[2]
    tau = 1.81 * qdd[:, 0] - 2.0 * g * np.cos(q[:, 0])
    loads = jle.inverse_dynamics(model, q, qd, qdd)
    np.testing.assert_allclose(loads.effort[:, 0], tau, rtol=0, atol=1e-12 * 60)
    # The node's path takes the model as accepted.
    est = jle.Estimator(model)
    assert est.joints == ["shoulder"]

# --- an independent reference: a pendulum in closed form ---------------------------
PENDULUM = """<robot name="pendulum">
  <link name="base"/>
  <link name="bob"><inertial><origin xyz="0 0 -{l}"/><mass value="{m}"/>
    <inertia ixx="0.01" iyy="{i}" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="swing" type="continuous"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/></joint>
</robot>"""


def test_pendulum_against_its_closed_form():
    m, l, i_yy, g = 1.7, 0.45, 0.03, 9.80665
    model = jle.Model.from_string(PENDULUM.format(m=m, l=l, i=i_yy))
    q, qd, qdd = (x[:, :1] for x in random_states(model, 200, 1))
    world = jle.inverse_dynamics(model, q, qd, qdd, frame="world")
    s, c = np.sin(q[:, 0]), np.cos(q[:, 0])
    # Centre of mass at (-l sin q, 0, -l cos q) in the world; tau = (I + m l^2) q'' + m g l sin q.
    tau = (i_yy + m * l * l) * qdd[:, 0] + m * g * l * s
    a_com = np.stack([-l * c * qdd[:, 0] + l * s * qd[:, 0] ** 2, 0 * s,
                      l * s * qdd[:, 0] + l * c * qd[:, 0] ** 2], axis=1)
    force = m * (a_com - np.array([0.0, 0.0, -g]))
    scale = 1e-12 * (1.0 + np.abs(tau).max())
    np.testing.assert_allclose(world.effort[:, 0], tau, rtol=0, atol=scale)
    np.testing.assert_allclose(world.force[:, 0], force, rtol=0, atol=scale)
    np.testing.assert_allclose(world.moment[:, 0], np.stack([0 * s, tau, 0 * s], 1), atol=scale)
    # The parent (base) frame is the world's; in the child frame the force turns by -q
    # about y.
    parent = jle.inverse_dynamics(model, q, qd, qdd, frame="parent")
    np.testing.assert_allclose(parent.wrench, world.wrench, rtol=0, atol=scale)
    child = jle.inverse_dynamics(model, q, qd, qdd)
    fx = c * force[:, 0] - s * force[:, 2]
    np.testing.assert_allclose(child["swing"].force[:, 0], fx, rtol=0, atol=scale)
    assert child.joints == ["swing"] and child.links == ["bob"]
    # Gravity given: none, the moment is the inertial one alone.
    free = jle.inverse_dynamics(model, q, qd, qdd, gravity=[0, 0, 0])
    np.testing.assert_allclose(free.effort[:, 0], (i_yy + m * l * l) * qdd[:, 0], atol=scale)


# --- joint_loads on the same CSV -----------------------------------------------------
def state_header(model, wrench_links=()):
    header = ["t"]
    for name in model.coordinate_names:
        header += [name + ".q", name + ".qd", name + ".qdd"]
    for link in wrench_links:
        header += ["wrench@%s.%s" % (link, c) for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    return header


def joint_loads(tmp_path, args, header, rows):
    states, loads = str(tmp_path / "states.csv"), str(tmp_path / "loads.csv")
    write_csv(states, header, rows)
    run = subprocess.run([tool("joint_loads"), "--input", states, "--output", loads] + args,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return read_csv(loads), run.stderr


def compare_with_columns(loads, columns):
    for j, joint in enumerate(loads.joints):
        for c, name in enumerate(("fx", "fy", "fz", "mx", "my", "mz")):
            assert_same(loads.wrench[:, j, c], columns[joint + "." + name], joint + "." + name)
        assert_same(loads.effort[:, j], columns[joint + ".effort"], joint + ".effort")


@pytest.mark.parametrize("frame", ["child", "parent", "world"])
def test_inverse_dynamics_is_joint_loads(tmp_path, frame):
    model = jle.Model(PANDA)
    n = 300
    q, qd, qdd = plausible_states(model, n, 2)
    wrench = np.random.default_rng(3).uniform(-30.0, 30.0, (n, 6))
    t = 0.001 * np.arange(n)
    rows = np.column_stack([t] + [np.stack([q[:, k], qd[:, k], qdd[:, k]], 1)
                                  for k in range(model.nq)] + [wrench])
    columns, _ = joint_loads(tmp_path, ["--urdf", PANDA, "--frame", frame],
                             state_header(model, ["panda_hand"]), rows)
    loads = jle.inverse_dynamics(model, q, qd, qdd, wrenches={"panda_hand": wrench}, frame=frame)
    assert loads.joints == model.joint_names
    compare_with_columns(loads, columns)


def test_floating_base_is_joint_loads(tmp_path):
    model = jle.Model(BODY, floating_base=True)
    n = 100
    q, qd, qdd = plausible_states(model, n, 4)
    rng = np.random.default_rng(5)
    quaternion = rng.normal(size=(n, 4))
    quaternion /= np.linalg.norm(quaternion, axis=1)[:, None]
    pose = np.column_stack([rng.uniform(-1, 1, (n, 3)), quaternion])
    twist, acceleration = rng.uniform(-2, 2, (n, 6)), rng.uniform(-5, 5, (n, 6))
    header = state_header(model) + ["base." + c for c in (
        "x y z qx qy qz qw vx vy vz wx wy wz ax ay az alx aly alz".split())]
    rows = np.column_stack([0.01 * np.arange(n)] + [np.stack([q[:, k], qd[:, k], qdd[:, k]], 1)
                                                    for k in range(model.nq)] +
                           [pose, twist, acceleration])
    columns, _ = joint_loads(tmp_path, ["--urdf", BODY, "--floating-base"], header, rows)
    loads = jle.inverse_dynamics(model, q, qd, qdd, base_pose=pose, base_twist=twist,
                                 base_acceleration=acceleration)
    compare_with_columns(loads, columns)
    for c, name in enumerate(("fx", "fy", "fz", "mx", "my", "mz")):
        assert_same(loads.base_residual[:, c], columns["base." + name], "base." + name)
    with pytest.raises(ValueError, match="base_pose"):
        jle.inverse_dynamics(model, q, qd, qdd)


def test_zero_phase_is_joint_loads_positions_only(tmp_path):
    model = jle.Model(PANDA)
    n = 400
    t = 0.002 * np.arange(n) + 0.0001 * np.sin(np.arange(n))  # irregular stamps
    rng = np.random.default_rng(6)
    q = 0.4 * np.sin(2 * np.pi * np.outer(t, rng.uniform(0.2, 1.5, model.nq))) + \
        rng.normal(0, 1e-3, (n, model.nq))
    wrench = 10 * np.sin(2 * np.pi * np.outer(t, rng.uniform(0.2, 1.5, 6))) + \
        rng.normal(0, 0.5, (n, 6))
    wrench_columns = ["wrench@panda_hand." + c for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    header = ["t"] + [name + ".q" for name in model.coordinate_names] + wrench_columns
    kinematics = str(tmp_path / "kinematics.csv")
    columns, stderr = joint_loads(tmp_path, ["--urdf", PANDA, "--cutoff", "auto",
                                             "--write-kinematics", kinematics],
                                  header, np.column_stack([t, q, wrench]))
    # auto, as joint_loads' default, its wrench columns filtered alike
    value, rate, accel, cutoff = jle.smooth_zero_phase(t, q, forces={"wrench": (t, wrench)})
    printed = float(re.search(r"cutoff (\S+) Hz", stderr).group(1))
    assert cutoff == pytest.approx(printed, rel=1e-15)
    smoothed = read_csv(kinematics)
    for k, name in enumerate(model.coordinate_names):
        assert_same(value[:, k], smoothed[name + ".q"], name + ".q")
        assert_same(rate[:, k], smoothed[name + ".qd"], name + ".qd")
        assert_same(accel[:, k], smoothed[name + ".qdd"], name + ".qdd")
    # The wrench columns: the same filter, the positions' cutoff, no derivatives.
    filtered = jle.low_pass_zero_phase(t, wrench, cutoff)
    for c, name in enumerate(wrench_columns):
        assert_same(filtered[:, c], smoothed[name], name)
    compare_with_columns(jle.inverse_dynamics(model, value, rate, accel,
                                              wrenches={"panda_hand": filtered}), columns)
    fixed = jle.smooth_zero_phase(t, q, cutoff=cutoff)
    assert_same(fixed[2], accel, "a cutoff given")
    residual = jle.smooth_zero_phase(t, q, rule="residual")
    assert residual[3] != cutoff and residual[3] > 0
    with pytest.raises(ValueError, match="cutoff"):
        jle.smooth_zero_phase(t, q, cutoff=-1.0)


def test_zero_phase_rises_for_heel_strikes_as_joint_loads(tmp_path):
    """A contact force's heel strikes (8 ms rise into a 0.25 s half sine of 1500 N, 0.5 N
    of noise, 1 kHz) filtered alike raise the positions' own cutoff; joint_loads, given
    them as wrench columns, prints the same cutoff and says it was raised."""
    model = jle.Model(PANDA)
    n = 6000
    t = 0.001 * np.arange(n)
    rng = np.random.default_rng(8)
    q = 0.4 * np.sin(2 * np.pi * np.outer(t, rng.uniform(0.2, 1.0, model.nq))) + \
        rng.normal(0, 1e-3, (n, model.nq))
    wrench = rng.normal(0, 0.5, (n, 6))
    for start in (0.7, 1.9, 3.1, 4.3):
        s = t - start
        on = (s >= 0) & (s <= 0.25)
        wrench[on, 2] += 1500 * np.minimum(1, s[on] / 0.008) * np.sin(np.pi * s[on] / 0.25)
    own = jle.smooth_zero_phase(t, q)[3]
    raised = jle.smooth_zero_phase(t, q, forces={"contact": (t, wrench)})[3]
    assert raised > 1.5 * own
    header = ["t"] + [name + ".q" for name in model.coordinate_names] + \
        ["wrench@panda_hand." + c for c in ("fx", "fy", "fz", "mx", "my", "mz")]
    _, stderr = joint_loads(tmp_path, ["--urdf", PANDA, "--cutoff", "auto"], header,
                            np.column_stack([t, q, wrench]))
    assert float(re.search(r"cutoff (\S+) Hz", stderr).group(1)) == pytest.approx(raised,
                                                                                  rel=1e-15)
    assert "raised from the" in stderr, stderr


# --- process_bag on the same bag -----------------------------------------------------
@pytest.fixture(scope="module")
def example_bag(tmp_path_factory):
    bag = str(tmp_path_factory.mktemp("bag") / "example.bag")
    subprocess.run([tool("make_example_bag"), "--urdf", PANDA, "--output", bag, "--duration",
                    "1.5"], check=True, capture_output=True)
    return bag


def process_bag(tmp_path, bag, args):
    out = str(tmp_path / "loads.csv")
    run = subprocess.run([tool("process_bag"), "--bag", bag, "--urdf", PANDA, "--csv", out,
                          "--kinematics"] + args, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return read_csv(out)


@pytest.mark.parametrize("smoothing", [None, 4.0, "auto"])
def test_process_bag_is_the_tool(tmp_path, example_bag, smoothing):
    config = os.path.join(REPO, "config", "demo.yaml")
    args = ["--config", config]
    if smoothing is not None:
        args += ["--zero-phase", str(smoothing)]
    columns = process_bag(tmp_path, example_bag, args)
    loads = jle.process_bag(example_bag, PANDA, config, zero_phase=smoothing)
    assert len(loads) == len(columns["t"]) > 100
    assert_same(loads.t, columns["t"], "t")
    compare_with_columns(loads, columns)
    for j, joint in enumerate(loads.joints):
        for key, name in (("position", "q"), ("velocity", "qd"), ("acceleration", "qdd")):
            assert_same(getattr(loads, key)[:, j], columns[joint + "." + name], joint + "." + name)
    with pytest.raises(RuntimeError, match="no_such.bag"):
        jle.process_bag(str(tmp_path / "no_such.bag"), PANDA)



def test_external_outputs_are_the_tools(tmp_path):
    """The example bag's payload and push at panda_hand_tcp left out of the inputs
    (config/external_demo.yaml, docs/external_loads.md's worked example): Python's contact
    outputs are the process_bag tool's ~contact events and ~external_wrench/panda_hand_tcp
    messages, sample for sample, and the wrench is the bag's applied one (/ft_sensor/wrench, not
    given to the estimator) after the observer's first 0.5 s."""
    bag, out = str(tmp_path / "contact.bag"), str(tmp_path / "out.bag")
    subprocess.run([tool("make_example_bag"), "--urdf", PANDA, "--output", bag, "--effort",
                    "--sensor-frame", "panda_hand_tcp", "--duration", "2"], check=True,
                   capture_output=True)
    config = os.path.join(REPO, "config", "external_demo.yaml")
    run = subprocess.run([tool("process_bag"), "--bag", bag, "--urdf", PANDA, "--config", config,
                          "--output", out], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    loads = jle.process_bag(bag, PANDA, config)
    assert loads.contact_links == ["panda_hand_tcp"]
    assert loads.contact_active.shape == (len(loads), 1) and loads.contact_active.any()
    import rosbag
    with rosbag.Bag(out) as b:
        events = [m for _, m, _ in b.read_messages(["/joint_load_estimator/contact"])]
        wrenches = [m for _, m, _ in b.read_messages(
            ["/joint_load_estimator/external_wrench/panda_hand_tcp"])]
    with rosbag.Bag(bag) as b:
        applied = {m.header.stamp.to_nsec(): m.wrench for _, m, _ in
                   b.read_messages(["/ft_sensor/wrench"])}
    event = np.flatnonzero(loads.contact_started | loads.contact_changed | loads.contact_ended)
    assert len(events) == len(event) >= 1
    for m, i in zip(events, event):
        assert m.header.stamp.to_nsec() == loads.stamp_ns[i]
        assert m.in_contact == loads.in_contact[i]
        assert (m.joint, m.link) == (loads.contact_joint[i], loads.contact_link[i])
        active = [l for l, a in zip(loads.contact_links, loads.contact_active[i]) if a]
        assert list(m.contacts) == (active if m.in_contact else [])
    w = np.array([[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z, m.wrench.torque.x,
                   m.wrench.torque.y, m.wrench.torque.z] for m in wrenches])
    assert_same(w, loads.contact_wrench[:, 0, :], "panda_hand_tcp's wrench")
    late = [i for i, s in enumerate(loads.stamp_ns)
            if s - loads.stamp_ns[0] >= 5e8 and s in applied]
    assert len(late) > 1000
    truth = np.array([[applied[loads.stamp_ns[i]].force.x, applied[loads.stamp_ns[i]].force.y,
                       applied[loads.stamp_ns[i]].force.z] for i in late])
    error = np.sqrt(np.mean(np.sum((w[late, :3] - truth) ** 2, axis=1)))
    size = np.sqrt(np.mean(np.sum(truth ** 2, axis=1)))
    # docs/external_loads.md: 0.26 N of 20 N
    assert size > 10.0 and error < 0.05 * size, (error, size)

SENSOR_CONFIG = """wrenches:
  - topic: /ft_sensor/wrench
    link: panda_link8
"""


@pytest.mark.parametrize("lag", [0.0, 0.05])
def test_estimator_is_process_bag(tmp_path, example_bag, lag):
    """The online estimator with the node's defaults, fed the bag's samples in the bag's
    order, gives process_bag's loads (the node's message path around the same estimator).
    With a smoother (lag > 0) both give the last samples' loads at the end too (flush)."""
    import rosbag
    config = str(tmp_path / "sensor.yaml")
    with open(config, "w") as f:
        f.write(SENSOR_CONFIG)  # the sensor's own frame: no transform in the message path
        f.write("differentiator:\n  lag: %r\n" % lag)
    columns = process_bag(tmp_path, example_bag, ["--config", config])
    model = jle.Model(PANDA)
    joints, wrenches = [], []
    with rosbag.Bag(example_bag) as bag:
        for topic, msg, _ in bag.read_messages(["/joint_states", "/ft_sensor/wrench"]):
            stamp = msg.header.stamp.to_nsec()
            if topic == "/joint_states":
                position = dict(zip(msg.name, msg.position))
                joints.append([stamp] + [position[c] for c in model.coordinate_names])
            else:
                w = msg.wrench
                wrenches.append([stamp, w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y,
                                 w.torque.z])
    joints, wrenches = np.array(joints, dtype=object), np.array(wrenches, dtype=object)
    t0 = min(joints[0, 0], wrenches[0, 0])  # the message path's time origin: the first stamp
    seconds = lambda stamps: np.array([(s - t0) * 1e-9 for s in stamps])
    estimator = jle.Estimator(model, config)
    loads = jle.estimate(estimator, seconds(joints[:, 0]), joints[:, 1:].astype(float),
                         [(seconds(wrenches[:, 0]), wrenches[:, 1:].astype(float))])
    assert loads.joints == model.joint_names and len(loads) == len(columns["t"])
    assert np.abs(loads.t + t0 * 1e-9 - columns["t"]).max() < 1e-6
    compare_with_columns(loads, columns)
    # The sensor's readings matter: without them the efforts are others.
    bare = str(tmp_path / "bare.yaml")
    with open(bare, "w") as f:
        f.write("differentiator:\n  lag: %r\n" % lag)
    unloaded = jle.estimate(jle.Estimator(model, bare), seconds(joints[:, 0]),
                            joints[:, 1:].astype(float))
    assert np.abs(unloaded.effort - loads.effort).max() > 0.1
    # One sample at a time, from the start again: the same loads.
    estimator.reset()
    t, q = seconds(joints[:, 0]), joints[:, 1:].astype(float)
    w, k = wrenches[:, 1:].astype(float), 0
    tw = seconds(wrenches[:, 0])
    published = []
    for i in range(len(t)):
        while k < len(tw) and tw[k] <= t[i]:
            estimator.add_wrench(0, tw[k], w[k, :3], w[k, 3:])
            k += 1
        if estimator.add_joint_sample(t[i], q[i]) == "published":
            published.append(estimator.loads()["effort"])
    pending = estimator.delay_samples if lag > 0 else 0
    flushed = []
    while (status := estimator.flush()) is not None:
        flushed.append(status)
        if status == "published":
            published.append(estimator.loads()["effort"])
    assert len(flushed) == pending and (lag == 0 or pending > 10), flushed
    assert estimator.flush() is None
    assert_same(np.array(published), loads.effort, "sample by sample")


def pose_of(transform):
    t, r = transform.translation, transform.rotation
    return np.array([t.x, t.y, t.z, r.x, r.y, r.z, r.w])


def test_estimator_runs_the_gait_demo_with_plates(tmp_path):
    """The gait demo's configuration (floating base, two force plates, body_mass,
    decimation, a centred Savitzky-Golay filter) through Estimator, fed a walking bag's
    joint states (by name), plate samples and tf poses message by message, gives the
    records process_bag's code gives for the same bag: loads, efforts per kg, centres of
    pressure, plate contact and the base residual, both streams."""
    import rosbag
    bag = str(tmp_path / "gait.bag")
    subprocess.run([tool("make_gait_bag"), "--urdf", BODY, "--output", bag, "--strides", "1"],
                   check=True, capture_output=True)
    config = os.path.join(REPO, "config", "gait_demo.yaml")
    expected = jle.process_bag(bag, BODY, config)
    estimator = jle.Estimator(jle.Model(BODY), config)
    plates = {"/force_plate_1/wrench": 0, "/force_plate_2/wrench": 1}
    t0 = None
    records, smoothed = [], []

    def take():
        while estimator.take_drained():
            records.append(estimator.record())
        if estimator.smoothed_published():
            smoothed.append(estimator.record(smoothed=True))
        while estimator.take_drained_smoothed():
            smoothed.append(estimator.record(smoothed=True))

    with rosbag.Bag(bag) as b:
        for topic, msg, _ in b.read_messages():
            if topic in ("/tf", "/tf_static"):
                for tf in msg.transforms:
                    estimator.set_transform(tf.header.frame_id, tf.child_frame_id,
                                            pose_of(tf.transform))
                continue
            if topic not in plates and topic != "/joint_states":
                continue
            stamp = msg.header.stamp.to_nsec()
            t0 = stamp if t0 is None else t0
            t = (stamp - t0) * 1e-9
            if topic == "/joint_states":
                outcome = estimator.add_joint_state(t, names=list(msg.name),
                                                    q=np.array(msg.position))
                if outcome == "published":
                    records.append(estimator.record())
            else:
                w = msg.wrench
                outcome = estimator.add_plate(plates[topic], t, [w.force.x, w.force.y, w.force.z],
                                              [w.torque.x, w.torque.y, w.torque.z],
                                              msg.header.frame_id)
                assert outcome == "used", (outcome, estimator.problem)
            take()
    while estimator.flush():
        records.append(estimator.record())
    while estimator.flush_smoothed():
        smoothed.append(estimator.record(smoothed=True))
    assert len(records) == len(expected.t) >= 100  # 1 s at 100 Hz (decimation 2)
    assert len(smoothed) == len(expected.smoothed.t) >= 100
    joined = lambda key, rows: np.concatenate([getattr(r, key) for r in rows])
    for key in ("wrench", "effort", "effort_per_kg", "cop", "normal_force", "base_residual", "q",
                "qdd"):
        assert_same(joined(key, records), getattr(expected, key), key)
    assert (joined("plate_contact", records) == expected.plate_contact).all()
    assert expected.plate_contact.any() and (~expected.plate_contact).any()
    assert_same(joined("effort", smoothed), expected.smoothed.effort, "smoothed effort")
    # The plates matter: a moment of 1 N m/kg or more at the ankles in stance.
    assert np.abs(expected.effort_per_kg).max() > 1.0


def test_gait_demo_through_python_agrees_with_joint_loads(tmp_path):
    """The gait demo's configuration (floating base from tf, two force plates, body_mass,
    the centred Savitzky-Golay filter) through Python's process_bag against joint_loads on
    the same trial written as a CSV with exact derivatives (make_gait_bag --csv): a
    different front end and no filter. The efforts per kg agree to the filter's
    smoothing: RMS 0.036 N m/kg when written, peaks of 1.75 N m/kg."""
    bag, trial = str(tmp_path / "gait.bag"), str(tmp_path / "gait.csv")
    made = subprocess.run([tool("make_gait_bag"), "--urdf", BODY, "--output", bag, "--csv", trial,
                           "--strides", "2"], check=True, capture_output=True, text=True)
    plates = re.search(r"joint_loads: (--plate \S+ --plate \S+)", made.stdout + made.stderr)
    assert plates, made.stdout
    exact = str(tmp_path / "exact.csv")
    subprocess.run([tool("joint_loads"), "--urdf", BODY, "--input", trial, "--floating-base",
                    *plates.group(1).split(), "--per-kg", "--contact-threshold", "1", "--output",
                    exact], check=True, capture_output=True)
    with open(exact) as f:
        rows = list(csv.DictReader(f))
    t_exact = np.array([float(r["t"]) for r in rows])
    got = jle.process_bag(bag, BODY, os.path.join(REPO, "config", "gait_demo.yaml"))
    t = np.asarray(got.t) - 1000.0  # make_gait_bag stamps t0 + t, t0 = 1000 s
    inside = (t > 0.3) & (t < t_exact[-1] - 0.3)  # the filter's start and the trial's end
    assert inside.sum() >= 150
    error = np.array([
        np.asarray(got.effort_per_kg)[inside, j] -
        np.interp(t[inside], t_exact, [float(r[joint + ".effort_per_kg"]) for r in rows])
        for j, joint in enumerate(got.joints)])
    peak = max(abs(float(r[k])) for r in rows for k in r if k.endswith(".effort_per_kg"))
    assert peak > 1.0
    assert np.sqrt(np.mean(error ** 2)) < 0.05, np.sqrt(np.mean(error ** 2))
    assert np.abs(error).max() < 0.4 * peak, np.abs(error).max()  # 0.52 at heel strike
    # The smoothed stream (rviz's) no worse than the immediate one: 0.025 N m/kg when written.
    ts = np.asarray(got.smoothed.t) - 1000.0
    inside_s = (ts > 0.3) & (ts < t_exact[-1] - 0.3)
    smoothed = np.array([
        np.asarray(got.smoothed.effort_per_kg)[inside_s, j] -
        np.interp(ts[inside_s], t_exact, [float(r[joint + ".effort_per_kg"]) for r in rows])
        for j, joint in enumerate(got.smoothed.joints)])
    assert np.sqrt(np.mean(smoothed ** 2)) <= np.sqrt(np.mean(error ** 2)), \
        (np.sqrt(np.mean(smoothed ** 2)), np.sqrt(np.mean(error ** 2)))


def test_core_module_loads_without_ros():
    """joint_load_estimator (the model, inverse dynamics, the estimator, the zero-phase
    smoother) loads no ROS library: only process_bag's module (_bag) reads bags."""
    code = ("import joint_load_estimator as j; m = j.Model(%r); e = j.Estimator(m); "
            "print(open('/proc/self/maps').read())" % PANDA)
    maps = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                          text=True).stdout
    paths = [line.split()[-1] for line in maps.splitlines() if len(line.split()) >= 6]
    loaded = {os.path.basename(p) for p in paths if p.endswith(".so") or ".so." in p}
    ros = sorted(name for name in loaded
                 if re.match(r"lib(roscpp|rosbag|rosconsole|tf2|xmlrpcpp|cpp_common|rostime)",
                             name))
    assert any(name.startswith("_core") for name in loaded), sorted(loaded)
    assert not ros, ros


def test_estimator_defaults_are_the_nodes(tmp_path):
    """Estimator(model) and Estimator(model, default.yaml) are one configuration."""
    model = jle.Model(PANDA)
    default = jle.Estimator(model)
    from_file = jle.Estimator(model, os.path.join(REPO, "config", "default.yaml"))
    assert default.delay_samples == from_file.delay_samples
    t = 0.001 * np.arange(300)
    q = 0.3 * np.sin(np.outer(t, np.arange(1, model.nq + 1)))
    a, b = jle.estimate(default, t, q), jle.estimate(from_file, t, q)
    assert len(a) > 200
    assert_same(a.wrench, b.wrench, "default.yaml")
    with pytest.raises(ValueError, match="decimation"):
        bad = tmp_path / "bad.yaml"
        bad.write_text("decimation: 0\n")
        jle.Estimator(model, str(bad))


def test_estimate_refuses_an_absurd_position_and_says_what_to_trust():
    """Never silently wrong (docs/node.md): a joint state with a position of 1e300 or one joint
    3 rad off for one sample is refused (status "implausible") and changes no load (the
    loads equal those of the same samples without it, to the bit); each record's status
    bits (loads_status) say settling at the start, trusted after."""
    model = jle.Model(PANDA)
    t = 0.001 * np.arange(500)
    q = 0.3 * np.sin(np.outer(t, np.arange(1, model.nq + 1)))
    q[:, 3] -= 1.5  # panda_joint4 lies in [-3.07, -0.07]
    q[:, 5] += 1.5  # panda_joint6 in [-0.02, 3.75]
    q[:, 7] = 0.02  # the finger
    bad = q.copy()
    bad[200, 1] = 1e300
    bad[300, 2] += 3.0
    keep = [i for i in range(len(t)) if i not in (200, 300)]
    clean = jle.estimate(jle.Estimator(model), t[keep], q[keep])
    got = jle.estimate(jle.Estimator(model), t, bad)
    assert got.status[200] == "implausible" and got.status[300] == "implausible"
    assert sum(s == "implausible" for s in got.status) == 2
    assert len(got) == len(clean) > 400
    assert np.isfinite(got.effort).all()
    assert np.array_equal(got.effort, clean.effort)
    bits = np.asarray(got.loads_status)
    assert len(bits) == len(got)
    assert bits[0] & 1  # settling: the first records after the start
    assert (bits[-300:] == 0).all()  # trusted


def test_inverse_dynamics_releases_the_gil():
    """While a long batch runs in one thread, another keeps running Python: its longest
    pause is a fraction of the batch's time (with the GIL held it would be all of it)."""
    import threading
    import time
    model = jle.Model(PANDA)
    q, qd, qdd = random_states(model, 300000, 7)
    span = {}

    def batch():
        span["start"] = time.perf_counter()
        jle.inverse_dynamics(model, q, qd, qdd)
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=batch)
    worker.start()
    stamps = []
    while worker.is_alive():
        stamps.append(time.perf_counter())
    worker.join()
    inside = [s for s in stamps if span["start"] <= s <= span["end"]]
    duration = span["end"] - span["start"]
    edges = [span["start"]] + inside + [span["end"]]
    longest = max(b - a for a, b in zip(edges, edges[1:]))
    assert longest < 0.5 * duration, "longest pause %.3f s of a %.3f s batch" % (longest, duration)
