"""Message types for ROS bags that carry no definitions of their own (ROS 2 sqlite3 bags
recorded before Iron): rosbags' ROS 2 Humble standard types plus the lab types shipped as
``ingest/ros_msgs/<package>/msg/<Name>.msg`` (``rokubimini_msgs/msg/Reading``, the force/torque
sensor of the CMU rig). ROS 1 bags and newer ROS 2 bags carry their definitions; rosbags
decodes those from the bag itself."""

from __future__ import annotations

from functools import lru_cache
from importlib import resources


def lab_types() -> dict:
    """rosbags type definitions of the shipped ``.msg`` files, keyed ``<package>/msg/<Name>``."""
    from rosbags.typesys import get_types_from_msg

    types: dict = {}
    for package in (resources.files("ingest") / "ros_msgs").iterdir():
        folder = package / "msg"
        if not folder.is_dir():
            continue
        for msg in folder.iterdir():
            if msg.name.endswith(".msg"):
                name = f"{package.name}/msg/{msg.name[:-4]}"
                types.update(get_types_from_msg(msg.read_text(encoding="utf-8"), name))
    return types


@lru_cache(maxsize=1)
def default_typestore():
    """The types used for a bag without definitions (read only: AnyReader copies them)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(lab_types())
    return store
