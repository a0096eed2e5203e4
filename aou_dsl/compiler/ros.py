"""ROS 2 output: the trajectory as one ``trajectory_msgs/msg/JointTrajectory``.

Two forms of the same message (docs/ros2.md shows how to send them):

- ``mcap``: a ROS 2 bag (rosbag2 format 9, MCAP storage) holding that one message on
  :data:`TOPIC`, the topic a ros2_control ``joint_trajectory_controller`` named
  ``joint_trajectory_controller`` subscribes to. A bag is a folder (``metadata.yaml``
  and ``NAME.mcap``); written with rosbags (pure Python, no ROS install needed).
- ``yaml``: the message as YAML, for ``ros2 topic pub`` or a ``FollowJointTrajectory``
  action goal.

The message: one point per sample, positions, velocities and accelerations of every
joint (the controller then interpolates with quintic splines), no effort;
``time_from_start`` is the sample's time, so the first point (t = 0) is the start state
and the last one the end, at rest. The header's stamp is zero ("start now"). Both forms
are deterministic: the same document gives the same bytes.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Sequence

import numpy as np

from ..core.codes import I502, R401
from ..core.diagnostics import AouError, Span, diag
from ..core.output_folders import BAG_TOPIC
from ..version import __version__

__all__ = ["MSGTYPE", "TOPIC", "encode_yaml", "is_bag", "message", "read_bag", "write_bag"]

#: The topic of a ros2_control ``joint_trajectory_controller`` named
#: ``joint_trajectory_controller`` (``<controller>/joint_trajectory``).
TOPIC = BAG_TOPIC
MSGTYPE = "trajectory_msgs/msg/JointTrajectory"


def _duration(t: float) -> dict[str, int]:
    """``builtin_interfaces/Duration`` of ``t`` [s], rounded to the nanosecond."""
    ns = int(round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def message(doc: dict) -> dict:
    """The ``JointTrajectory`` of a trajectory document, as plain data (lists, ints)."""
    q = np.asarray(doc["q"], dtype=float)
    qd = np.asarray(doc["qd"], dtype=float)
    qdd = np.asarray(doc["qdd"], dtype=float)
    points = [{"positions": q[i].tolist(), "velocities": qd[i].tolist(),
               "accelerations": qdd[i].tolist(), "effort": [],
               "time_from_start": _duration(float(t))}
              for i, t in enumerate(doc["t"])]
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
            "joint_names": list(doc["joint_names"]), "points": points}


def _num(x: float) -> str:
    """A float as YAML 1.1 (PyYAML, which ROS 2's command line uses) reads a float: it
    needs a dot before an exponent (``1e-05`` would be a string)."""
    s = repr(float(x))
    if "e" in s and "." not in s.split("e")[0]:
        mant, exp = s.split("e")
        s = f"{mant}.0e{exp}"
    return s


def _flow(values: Sequence[float]) -> str:
    return "[" + ", ".join(_num(v) for v in values) + "]"


def encode_yaml(doc: dict) -> bytes:
    """The message as block YAML (arrays inline), as ``ros2 topic echo`` prints it."""
    m = message(doc)
    names = ", ".join("'" + n.replace("'", "''") + "'" for n in m["joint_names"])
    lines = [f"# {MSGTYPE} for {TOPIC}",
             f"# behaviour {doc.get('behaviour')!r}, robot {doc.get('robot')!r}, "
             f"aouc {__version__}",
             "header:", "  stamp:", "    sec: 0", "    nanosec: 0", "  frame_id: ''",
             f"joint_names: [{names}]", "points:"]
    for p in m["points"]:
        d = p["time_from_start"]
        lines += [f"- positions: {_flow(p['positions'])}",
                  f"  velocities: {_flow(p['velocities'])}",
                  f"  accelerations: {_flow(p['accelerations'])}",
                  "  effort: []",
                  "  time_from_start:", f"    sec: {d['sec']}", f"    nanosec: {d['nanosec']}"]
    return ("\n".join(lines) + "\n").encode()


def is_bag(path: str) -> bool:
    """Whether ``path`` is a ROS 2 bag folder (it holds a ``metadata.yaml``)."""
    return os.path.isfile(os.path.join(path, "metadata.yaml"))


def _typestore():
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _serialized(doc: dict) -> bytes:
    ts = _typestore()
    t = ts.types
    m = message(doc)
    points = [t["trajectory_msgs/msg/JointTrajectoryPoint"](
        positions=np.asarray(p["positions"], dtype=np.float64),
        velocities=np.asarray(p["velocities"], dtype=np.float64),
        accelerations=np.asarray(p["accelerations"], dtype=np.float64),
        effort=np.zeros(0, dtype=np.float64),
        time_from_start=t["builtin_interfaces/msg/Duration"](**p["time_from_start"]))
        for p in m["points"]]
    header = t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0),
                                      frame_id="")
    msg = t[MSGTYPE](header=header, joint_names=m["joint_names"], points=points)
    return bytes(ts.serialize_cdr(msg, MSGTYPE))


def write_bag(doc: dict, path: str, *, topic: str = TOPIC, inputs: Sequence[str] = ()
              ) -> None:
    """Write the message as a ROS 2 bag (MCAP storage) in the folder ``path``.

    The bag is made in a temporary folder beside ``path`` and renamed onto it when
    complete; the folders missing on the way are made. ``path`` must be new, an empty
    folder or a bag aou wrote (:func:`aou_dsl.core.files.guard_output`), which is replaced.

    Raises:
        AouError: I502 when it cannot be written, or ``path`` is, holds or links to an
            input, is a special file, or holds files other than a bag aou wrote.
    """
    from rosbags.rosbag2 import StoragePlugin, Writer

    from ..core.files import guard_output, make_folders, sweep_stale, temp_prefix

    where = Span.whole_file(path)
    final = os.path.abspath(path.rstrip(os.sep) or path)
    guard_output(final, inputs, bag=True)
    final = os.path.realpath(final)
    data = _serialized(doc)
    parent = os.path.dirname(final)
    made = make_folders(parent, where)
    sweep_stale(parent)
    try:
        tmp = tempfile.mkdtemp(prefix=temp_prefix(), dir=parent)
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}", where)) from None
    done = False
    try:
        bag = os.path.join(tmp, os.path.basename(final))
        ts = _typestore()
        with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
            conn = writer.add_connection(topic, MSGTYPE, typestore=ts)
            writer.write(conn, 0, data)
        old = os.path.join(tmp, ".replaced")
        if os.path.lexists(final):
            os.rename(final, old)
        try:
            os.rename(bag, final)
        except OSError:
            if os.path.lexists(old):
                os.rename(old, final)
            raise
        done = True
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}", where)) from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        for f in () if done else made:
            with contextlib.suppress(OSError):
                os.rmdir(f)


def read_bag(path: str) -> tuple[str, str, dict]:
    """The first message of a bag: its topic, its type and the message as plain data
    (the form :func:`message` gives).

    Raises:
        AouError: R401 when ``path`` is not a readable bag or holds no message.
    """
    from rosbags.rosbag2 import Reader

    try:
        with Reader(path) as reader:
            for conn, _, raw in reader.messages():
                msg = _typestore().deserialize_cdr(raw, conn.msgtype)
                return conn.topic, conn.msgtype, _plain(msg)
    except AouError:
        raise
    except Exception as exc:  # rosbags raises its own errors for any unreadable bag
        raise AouError(diag(R401, f"cannot read the bag `{path}`: {exc}",
                            Span.whole_file(path))) from None
    raise AouError(diag(R401, f"the bag `{path}` holds no message", Span.whole_file(path)))


def _plain(msg) -> dict:
    """A deserialised ``JointTrajectory`` as plain data."""
    def dur(d) -> dict[str, int]:
        return {"sec": int(d.sec), "nanosec": int(d.nanosec)}

    return {"header": {"stamp": dur(msg.header.stamp), "frame_id": msg.header.frame_id},
            "joint_names": list(msg.joint_names),
            "points": [{"positions": p.positions.tolist(), "velocities": p.velocities.tolist(),
                        "accelerations": p.accelerations.tolist(),
                        "effort": p.effort.tolist(), "time_from_start": dur(p.time_from_start)}
                       for p in msg.points]}
