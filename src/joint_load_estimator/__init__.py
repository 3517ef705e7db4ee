"""joint_load_estimator: joint loads by per-segment 6x6 inverse dynamics, from Python.

The C++ core of the ROS package, over numpy arrays (docs/python.md):

    import numpy as np
    import joint_load_estimator as jle

    model = jle.Model("panda.urdf")                # or jle.Model.from_string(xml)
    loads = jle.inverse_dynamics(model, q, qd, qdd)  # N x nq each, model.coordinate_names
    loads.wrench                                   # N x joints x 6 (fx fy fz mx my mz)
    loads.effort                                   # N x joints
    loads["panda_joint2"].effort                   # one joint's column

Conventions are the package's (docs/how_it_works.md, "What it computes, and the conventions"): the
wrench the parent link exerts on the child link through the joint, moment about the
joint origin, in the child link frame by default; SI units. The generated messages stay
where ROS puts them: ``from joint_load_estimator.msg import JointLoads``.
"""

from ._core import Estimator, Model, default_gravity
from . import _core

__all__ = ["Model", "Estimator", "Loads", "inverse_dynamics", "estimate", "smooth_zero_phase",
           "low_pass_zero_phase", "process_bag", "default_gravity"]


class Loads:
    """Named arrays of joint loads over N samples.

    Attributes: ``joints`` (names, length m), ``links`` (each joint's child link),
    ``frame`` (the frame of the wrenches), ``wrench`` (N x m x 6: force [N], moment
    [N m] about the joint origin), ``effort`` (N x m, [N m] or [N]), ``force`` and
    ``moment`` (N x m x 3 views of ``wrench``), and whatever else the producer gives
    (``t``, ``base_residual``, ``position``, ...). ``loads["joint"]`` selects one joint.
    """

    def __init__(self, arrays):
        self.__dict__.update(arrays)

    @property
    def force(self):
        return self.wrench[..., :3]

    @property
    def moment(self):
        return self.wrench[..., 3:]

    def index(self, joint):
        """Column of ``joint`` in the arrays; KeyError naming it if it has none."""
        try:
            return self.joints.index(joint)
        except ValueError:
            raise KeyError("no loads for joint '%s' (joints: %s)" % (joint, ", ".join(self.joints)))

    # The arrays with one column per joint (the others, t or base_residual, are kept whole).
    PER_JOINT = ("wrench", "effort", "effort_stddev", "effort_per_kg", "position", "velocity",
                 "acceleration", "motor_effort", "measured_effort", "external_effort",
                 "external_effort_stddev", "covariance")

    def __getitem__(self, joint):
        i = self.index(joint)
        picked = dict(self.__dict__)
        for key in self.PER_JOINT:
            value = picked.get(key)
            if value is not None and value.ndim >= 2 and value.shape[1] == len(self.joints):
                picked[key] = value[:, i]
        picked["joints"], picked["links"] = [joint], [self.links[i]]
        return Loads(picked)

    def __len__(self):
        return len(self.effort)

    def __repr__(self):
        return "Loads(%d samples x %d joints, frame %s)" % (len(self), len(self.joints), self.frame)


def _record(estimator, smoothed=False):
    """The last published record (of the smoothed stream with smoothed=True) as Loads of
    one sample: every output of the node's record, as process_bag returns them."""
    return Loads(estimator._record(smoothed))


Estimator.record = _record


def inverse_dynamics(model, q, qd, qdd, wrenches=None, frame="child", gravity=None,
                     base_pose=None, base_twist=None, base_acceleration=None):
    """Joint loads of every moving joint for N samples at once (the GIL is released).

    model: a Model. q, qd, qdd: N x model.nq arrays [rad or m, /s, /s^2] in
    model.coordinate_names order. wrenches: optional {link: N x 6 array}, the wrench
    applied TO the robot at the origin of URDF link ``link``, in that link's frame
    (force [N], moment [N m]), as joint_loads' wrench@LINK columns. frame: 'child'
    (default), 'parent' or 'world'. gravity: [m/s^2] in the world (root) frame, default
    ``default_gravity`` (the estimator's). A floating-base model needs base_pose (N x 7:
    x y z qx qy qz qw, world), base_twist (N x 6: v, omega, world) and base_acceleration
    (N x 6: a, alpha, world); then ``base_residual`` (N x 6, world frame, moment about
    the root origin) is what the world must apply to the root.
    Returns Loads (joints = model.joint_names). The numbers are those of the
    ``joint_loads`` command-line tool for the same samples.
    """
    base = {}
    for key, value in (("base_pose", base_pose), ("base_twist", base_twist),
                       ("base_acceleration", base_acceleration)):
        if value is not None:
            base[key] = value
    return Loads(_core._inverse_dynamics(model, q, qd, qdd, wrenches, frame, gravity, base))


def smooth_zero_phase(t, x, cutoff=None, rule="auto", order=4, padding=0, forces=None):
    """Zero-phase Butterworth smoothing and differentiation of a whole record
    (docs/studies/zero_phase.md; joint_loads' positions-only path).

    t: N stamps [s], increasing; x: N x channels. cutoff [Hz], or None to choose it by
    ``rule`` ('auto': the noise spectrum of the positions, 'spectrum', 'gcv' or
    'residual'); order of each pass; padding (0: 3 (order + 1)). forces: None, or
    {name: (t, x)} of the force, wrench and plate channels to be filtered alike
    (low_pass_zero_phase with the returned cutoff), each at its own stamps: a chosen
    cutoff rises where their own spectrum shows content far above it (jle::FilteredAlike),
    as joint_loads' does for its wrench and plate columns.
    Returns (value, rate, accel, cutoff): N x channels arrays and the cutoff used [Hz].
    """
    r = _core._smooth_zero_phase(t, x, cutoff, rule, order, padding, forces or {})
    return r["value"], r["rate"], r["accel"], r["cutoff"]


def low_pass_zero_phase(t, x, cutoff, order=4, padding=0):
    """The same filter without derivatives (for force, wrench and plate columns)."""
    return _core._low_pass_zero_phase(t, x, cutoff, order, padding)


def process_bag(bag, urdf, config="", zero_phase=None, cutoff_rule="auto", summary=False):
    """The node's estimate over a bag, through process_bag's own code (jle::processBag).

    bag, urdf: paths; config: the node's parameters as a YAML file ('' : defaults);
    zero_phase: None, a cutoff [Hz] or 'auto' (process_bag --zero-phase; cutoff_rule
    with 'auto'); summary: print process_bag's summary on standard error.
    Returns Loads with ``t`` (stamp [s], as process_bag --csv writes it), ``stamp_ns``,
    ``wrench`` (child frame), ``effort``, ``position``, ``velocity``, ``acceleration``
    (the filter's estimate), ``measured_effort``, and, when the config enables them,
    ``effort_stddev`` and ``motor_effort`` (else N x 0): the immediate stream. Its
    ``smoothed`` is the smoothed stream's Loads (the config's smoothed/...; docs/how_it_works.md "Two
    streams"), None when it is off or with zero_phase.
    """
    from . import _bag  # the one part that needs ROS (rosbag, tf2)
    arrays = _bag._process_bag(bag, urdf, config, zero_phase, cutoff_rule, summary)
    smoothed = arrays.pop("smoothed")
    loads = Loads(arrays)
    loads.smoothed = Loads(smoothed) if smoothed is not None else None
    return loads


def estimate(estimator, t, q, wrenches=(), qd=None, base_pose=None):
    """Feeds N joint states (t [s], N; q, N x nq in coordinate_names order; qd, N x nq
    measured velocities, optional; base_pose, N x 7 for a floating base) and the readings
    of the config's wrench inputs (a list of (t_k, N_k x 6) per input, in the input's frame,
    as the sensor reports them) to ``estimator`` in time order, through the node's message
    path; returns Loads of the immediate stream's published samples (``t`` = the stamp each
    describes; every output of the record, see Estimator.record) with ``status`` per joint
    state, and its ``smoothed`` stream's Loads (None when smoothed/enabled is false)."""
    r = estimator.run(t, q, list(wrenches), qd, base_pose)
    smoothed = r.pop("smoothed")
    loads = Loads(r)
    loads.smoothed = Loads(smoothed) if smoothed is not None else None
    return loads
