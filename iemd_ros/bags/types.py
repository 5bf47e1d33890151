"""Message definitions for rosbags typestores (bag I/O, no rclpy).

rosbags ships the core ROS 2 message types but not vision_msgs. ``vision_msgs_types()`` parses the
vision_msgs 4.x ``.msg`` definitions into the dict that ``Typestore.register`` takes, so bags with
``vision_msgs/msg/Detection2DArray`` (the tracker's output) can be written and read without ROS:

    from rosbags.typesys import Stores, get_typestore
    from iemd_ros.bags.types import vision_msgs_types
    typestore = get_typestore(Stores.ROS2_JAZZY)
    typestore.register(vision_msgs_types())

The definitions are read, in this order, from an explicit folder, from ``share/vision_msgs/msg`` of
an installed vision_msgs (the prefixes in AMENT_PREFIX_PATH, then this interpreter's prefix, where
scripts/build_vision_msgs.sh installs it), or from the repository's ``interfaces/vision_msgs/msg``.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

PACKAGE = "vision_msgs"
REPO_MSG_DIR = Path(__file__).resolve().parents[1] / "interfaces" / PACKAGE / "msg"


def vision_msgs_msg_dirs() -> list[Path]:
    """Candidate folders of vision_msgs ``.msg`` files, most authoritative first.

    Returns
    -------
    list of Path
        ``share/vision_msgs/msg`` of each prefix in AMENT_PREFIX_PATH and of this interpreter's prefix, then the
        repository's ``interfaces/vision_msgs/msg``.
    """
    prefixes = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes.append(Path(sys.prefix))
    dirs = [prefix / "share" / PACKAGE / "msg" for prefix in prefixes]
    dirs.append(REPO_MSG_DIR)
    return dirs


def find_vision_msgs_msg_dir() -> Path:
    """First folder of ``vision_msgs_msg_dirs()`` that holds ``.msg`` files.

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    FileNotFoundError
        When none holds them.
    """
    searched = vision_msgs_msg_dirs()
    for folder in searched:
        if folder.is_dir() and any(folder.glob("*.msg")):
            return folder
    raise FileNotFoundError(
        "no vision_msgs .msg definitions found; searched: " + ", ".join(map(str, searched)))


def vision_msgs_types(msg_dir: str | os.PathLike | None = None) -> dict:
    """Parse every ``vision_msgs/msg/*.msg`` into ``{type name: definition}`` for rosbags.

    Parameters
    ----------
    msg_dir : str or path-like, optional
        Folder of the ``.msg`` files; default ``find_vision_msgs_msg_dir()``.

    Returns
    -------
    dict
        Type name -> definition, as ``Typestore.register`` takes it.

    Raises
    ------
    ValueError
        When an explicit ``msg_dir`` is not a folder or holds no ``.msg`` file.
    FileNotFoundError
        When no ``msg_dir`` is given and no folder holds the definitions.
    """
    from rosbags.typesys import get_types_from_msg

    if msg_dir is None:
        folder = find_vision_msgs_msg_dir()
    else:
        folder = Path(msg_dir)
        if not folder.is_dir():
            raise ValueError(f"vision_msgs msg folder {folder} is not a directory")
    files = sorted(folder.glob("*.msg"))
    if not files:
        raise ValueError(f"vision_msgs msg folder {folder} holds no .msg file")
    types: dict = {}
    for path in files:
        types.update(get_types_from_msg(path.read_text(encoding="utf-8"),
                                        f"{PACKAGE}/msg/{path.stem}"))
    return types
