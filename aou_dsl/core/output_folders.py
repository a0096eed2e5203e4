"""The output folders aou writes (a ROS 2 bag, a sequence of DMPs), recognised so that
the next write may replace one of aou's own and nothing else."""

from __future__ import annotations

import os

__all__ = ["BAG_TOPIC", "is_aou_bag", "is_aou_dmp"]


#: The topic of the bags aou writes (a ROS 2 ``joint_trajectory_controller``'s).
BAG_TOPIC = "/joint_trajectory_controller/joint_trajectory"


def is_aou_bag(folder: str) -> bool:
    """Whether ``folder`` holds a bag aou wrote and nothing else: ``metadata.yaml`` and
    ``NAME.mcap`` (NAME: the folder's name) on aou's topic."""
    name = os.path.basename(folder)
    if sorted(os.listdir(folder)) != sorted(["metadata.yaml", f"{name}.mcap"]):
        return False
    try:
        with open(os.path.join(folder, "metadata.yaml"), "rb") as fh:
            return BAG_TOPIC.encode() in fh.read(1 << 16)
    except OSError:
        return False


def is_aou_dmp(folder: str) -> bool:
    """Whether ``folder`` holds DMPs aou wrote and nothing else: ``manifest.json`` (an
    ``aou-dmp/1`` sequence) and its ``parts`` folder."""
    if not set(os.listdir(folder)) <= {"manifest.json", "parts"} or \
            not os.path.isfile(os.path.join(folder, "manifest.json")):  # not a FIFO's wait
        return False
    try:
        with open(os.path.join(folder, "manifest.json"), "rb") as fh:
            return b'"aou-dmp/1"' in fh.read(1 << 16)
    except OSError:
        return False
