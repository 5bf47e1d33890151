# Copyright 2026 iemd_ros authors
# SPDX-License-Identifier: BSD-3-Clause
#
# Redistribution and use in source and binary forms, with or without
# modification, are permitted provided that the following conditions are met:
#
#    * Redistributions of source code must retain the above copyright
#      notice, this list of conditions and the following disclaimer.
#
#    * Redistributions in binary form must reproduce the above copyright
#      notice, this list of conditions and the following disclaimer in the
#      documentation and/or other materials provided with the distribution.
#
#    * Neither the name of the iemd_ros authors nor the names of its
#      contributors may be used to endorse or promote products derived from
#      this software without specific prior written permission.
#
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"
# AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE
# IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE
# ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE
# LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR
# CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF
# SUBSTITUTE GOODS OR SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS
# INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN
# CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE)
# ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE
# POSSIBILITY OF SUCH DAMAGE.

"""
Bag I/O shared by ``iemd-make-bag``, ``iemd-replay`` and ``iemd-play`` (rosbags, no rclpy).

* Typestores: ROS 2 Jazzy (+ vision_msgs, :mod:`iemd_ros.bags.types`) and ROS 1 Noetic.
* :class:`BagWriter`: one writer for rosbag2 (mcap or sqlite3) and ROS 1 ``.bag`` files; messages
  are built with the writer's typestore classes (:meth:`BagWriter.msg`), so ROS 1/2 field
  differences (``Header.seq``, ``CameraInfo.K`` vs ``k``) are handled by :func:`header` /
  :func:`camera_info_fields`.
* :func:`open_bag`: AnyReader over a rosbag2 folder (sqlite3 or mcap, also given as its
  ``metadata.yaml`` / storage file), a bare ``.mcap`` file or a ROS 1 ``.bag``; an mcap cut short
  (a killed recorder) is read up to its last intact chunk (:func:`salvage_mcap`), with a warning;
  every other failure becomes a :class:`BagError` (a ``ValueError``) with a readable message,
  including truncation found while reading (:func:`iter_messages`).
* :func:`select_topics`: the image / IMU / camera-info topics, auto-detected when a bag has exactly
  one topic of a type, else named (wrong type or ambiguity -> BagError).  The image topic is a
  ``sensor_msgs/Image`` or a ``sensor_msgs/CompressedImage`` (image_transport's
  ``<image>/compressed``); auto-detection takes the one image topic that holds messages, where a
  compressed topic whose raw twin ``<image>`` holds messages too does not count (the twins carry
  the same frames, raw is lossless).  Any other mix (e.g. a depth Image beside a colour stream's
  ``/compressed``) -> BagError naming the candidates.
"""
from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
import shutil

from iemd_ros.common.cli import one_line
from iemd_ros.messages.conversions import ns_to_stamp, raw_twin
import numpy as np

__all__ = [
    'IMAGE_TYPE',
    'COMPRESSED_IMAGE_TYPE',
    'IMAGE_TYPES',
    'IMU_TYPE',
    'CAMERA_INFO_TYPE',
    'FORMATS',
    'BagError',
    'BagMessages',
    'BagWriter',
    'Topics',
    'bag_path',
    'camera_info_fields',
    'custom_data',
    'deserialize',
    'header',
    'iter_messages',
    'open_bag',
    'resolve_bag_path',
    'ros1_typestore',
    'ros2_typestore',
    'salvage_mcap',
    'Salvage',
    'select_topics',
]

IMAGE_TYPE = 'sensor_msgs/msg/Image'
COMPRESSED_IMAGE_TYPE = 'sensor_msgs/msg/CompressedImage'
#: types an image topic may have
IMAGE_TYPES = (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE)
IMU_TYPE = 'sensor_msgs/msg/Imu'
CAMERA_INFO_TYPE = 'sensor_msgs/msg/CameraInfo'
#: rosbag2 custom_data keys written by iemd-make-bag (documentation of the bag's provenance).
META_PREFIX = 'iemd_ros.'


class BagError(ValueError):
    """A bag that cannot be read, written or used (missing, truncated, wrong topics, ...)."""


def ros2_typestore():
    """
    ROS 2 Jazzy typestore with the vision_msgs and foxglove_msgs definitions registered.

    Returns
    -------
    rosbags.typesys.store.Typestore
        The typestore.

    """
    from iemd_ros.bags.types import interface_types, VENDORED
    from rosbags.typesys import get_typestore, Stores

    ts = get_typestore(Stores.ROS2_JAZZY)
    for package in VENDORED:
        ts.register(interface_types(package))
    return ts


def ros1_typestore():
    """
    Return the ROS 1 Noetic typestore.

    It has Image, Imu, CameraInfo with ``D``/``K``/``R``/``P`` and ``Header.seq``.

    Returns
    -------
    rosbags.typesys.store.Typestore
        The typestore.

    """
    from rosbags.typesys import get_typestore, Stores

    return get_typestore(Stores.ROS1_NOETIC)


# ----------------------------------------------------------------------------------------------
# writing
FORMATS = ('mcap', 'sqlite3', 'ros1')


class BagWriter:
    """
    Write one bag.

    Use as a context manager; on an exception the partial bag is removed.

    Parameters
    ----------
    path : str or path-like
        The new bag: a rosbag2 folder, or a ``.bag`` file for ``ros1``.
    fmt : {"mcap", "sqlite3", "ros1"}, optional
        ``mcap`` / ``sqlite3`` (rosbag2 version 9 folder) or ``ros1`` (.bag file).
    custom_data : dict, optional
        Goes into ``metadata.yaml`` (rosbag2 only).

    Raises
    ------
    BagError
        For an unknown format, an output that exists already, or a ROS 1 path not ending in
        ``.bag``.

    """

    def __init__(self, path, fmt: str = 'mcap', custom_data: dict | None = None):
        if fmt not in FORMATS:
            raise BagError(f'unknown bag format {fmt!r} (choose from {", ".join(FORMATS)})')
        self.path = Path(path)
        self.fmt = fmt
        if self.path.exists():
            raise BagError(f'output {self.path} exists already; choose a new path')
        if fmt == 'ros1':
            from rosbags.rosbag1 import Writer

            if self.path.suffix != '.bag':
                raise BagError(f'a ROS 1 bag must be a file ending in .bag, got {self.path}')
            self.typestore = ros1_typestore()
            self._writer = Writer(self.path)
        else:
            from rosbags.rosbag2 import StoragePlugin, Writer

            plugin = StoragePlugin.MCAP if fmt == 'mcap' else StoragePlugin.SQLITE3
            self.typestore = ros2_typestore()
            self._writer = Writer(self.path, version=9, storage_plugin=plugin)
            for k, v in (custom_data or {}).items():
                self._writer.set_custom_data(str(k), str(v))
        self._seq: dict[str, int] = {}
        self.counts: dict[str, int] = {}

    @property
    def ros1(self) -> bool:
        """Whether the bag is a ROS 1 ``.bag``."""
        return self.fmt == 'ros1'

    def __enter__(self) -> BagWriter:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._writer.open()
        self._conns: dict[str, object] = {}
        return self

    def __exit__(self, exc_type, exc, tb):
        result = self._writer.__exit__(exc_type, exc, tb)
        if exc_type is not None:  # do not leave a half-written bag behind
            if self.path.is_dir():
                shutil.rmtree(self.path, ignore_errors=True)
            elif self.path.exists():
                self.path.unlink()
        return result

    def msg(self, msgtype: str):
        """
        Message class of ``msgtype`` in this bag's typestore.

        Parameters
        ----------
        msgtype : str
            Full type name (``sensor_msgs/msg/Image``).

        Returns
        -------
        type
            The message class.

        """
        return self.typestore.types[msgtype]

    def add_topic(self, topic: str, msgtype: str) -> None:
        """
        Add a topic of ``msgtype`` to the bag.

        Parameters
        ----------
        topic : str
            The topic's name.
        msgtype : str
            Full type name of its messages.

        """
        self._conns[topic] = self._writer.add_connection(topic, msgtype, typestore=self.typestore)
        self.counts[topic] = 0

    def next_seq(self, topic: str) -> int:
        """
        ROS 1 ``Header.seq`` of the next message on ``topic``.

        Parameters
        ----------
        topic : str
            The topic's name.

        Returns
        -------
        int
            The sequence number, counting from 0.

        """
        s = self._seq.get(topic, 0)
        self._seq[topic] = s + 1
        return s

    def write(self, topic: str, log_time_ns: int, message) -> None:
        """
        Serialize ``message`` and write it on ``topic`` at a log time.

        Parameters
        ----------
        topic : str
            A topic added by :meth:`add_topic`.
        log_time_ns : int
            The log (receive) time, ns.
        message : object
            A message of this bag's typestore (:meth:`msg`).

        """
        conn = self._conns[topic]
        ser = self.typestore.serialize_ros1 if self.ros1 else self.typestore.serialize_cdr
        self._writer.write(conn, int(log_time_ns), ser(message, conn.msgtype))
        self.counts[topic] += 1


class BagMessages:
    """
    A :class:`~iemd_ros.messages.outputs.MessageFactory` of a rosbag2 writer's typestore.

    Parameters
    ----------
    bag : BagWriter
        The writer whose typestore builds the messages.

    """

    def __init__(self, bag: BagWriter):
        self._types = bag.typestore.types

    def __call__(self, msgtype: str, **fields):
        return self._types[msgtype](**fields)

    @staticmethod
    def byte(value: int) -> int:
        """
        Return the value of a ``byte`` field: an int for rosbags.

        Parameters
        ----------
        value : int
            The byte's value.

        Returns
        -------
        int
            ``value``.

        """
        return int(value)


def header(bag: BagWriter, topic: str, stamp_ns: int, frame_id: str):
    """
    ``std_msgs/Header`` with ``stamp_ns`` (ROS 1: plus the per-topic ``seq``).

    Parameters
    ----------
    bag : BagWriter
        The bag whose typestore builds the header.
    topic : str
        The topic it is for (ROS 1 ``seq``).
    stamp_ns : int
        The stamp, ns.
    frame_id : str
        The header's frame.

    Returns
    -------
    std_msgs/Header
        The header.

    """
    sec, nsec = ns_to_stamp(stamp_ns)
    stamp = bag.msg('builtin_interfaces/msg/Time')(sec=sec, nanosec=nsec)
    if bag.ros1:
        return bag.msg('std_msgs/msg/Header')(
            seq=bag.next_seq(topic), stamp=stamp, frame_id=frame_id
        )
    return bag.msg('std_msgs/msg/Header')(stamp=stamp, frame_id=frame_id)


def camera_info_fields(ros1: bool, d, k, r, p) -> dict:
    """
    Return the CameraInfo matrix fields under their ROS 1 (``D K R P``) or ROS 2 names.

    The ROS 2 names are ``d k r p``.

    Parameters
    ----------
    ros1 : bool
        Use the ROS 1 names.
    d, k, r, p : array_like
        Distortion coefficients, camera, rectification and projection matrices.

    Returns
    -------
    dict
        Field name -> flat float64 array.

    """
    names = ('D', 'K', 'R', 'P') if ros1 else ('d', 'k', 'r', 'p')
    return dict(zip(names, (np.asarray(v, dtype=np.float64).ravel() for v in (d, k, r, p))))


# ----------------------------------------------------------------------------------------------
# reading
def resolve_bag_path(path) -> Path:
    """
    Return the path AnyReader takes.

    A ``.bag`` file or a rosbag2 folder (also from its metadata/storage file).

    Parameters
    ----------
    path : str or path-like
        A ``.bag`` file, a rosbag2 folder, or its ``metadata.yaml``, ``.mcap`` or ``.db3`` file.

    Returns
    -------
    Path
        The ``.bag`` file or the rosbag2 folder.

    Raises
    ------
    BagError
        For a path that does not exist or is neither.

    """
    p = Path(path)
    if not p.exists():
        raise BagError(f'bag {p} does not exist')
    if p.is_file() and p.suffix != '.bag':
        if p.name == 'metadata.yaml' or p.suffix in ('.mcap', '.db3'):
            p = p.parent
        else:
            raise BagError(f'{p} is neither a ROS 1 .bag file nor a rosbag2 folder')
    if p.is_dir() and not (p / 'metadata.yaml').is_file():
        raise BagError(f'{p} is not a rosbag2 folder: it has no metadata.yaml')
    return p


def bag_path(path) -> Path:
    """
    Return the bag a path names, as :func:`open_bag` reads it.

    A lone mcap (a bare ``.mcap`` file, or a folder holding one without ``metadata.yaml``) as
    given, else :func:`resolve_bag_path`'s path.

    Parameters
    ----------
    path : str or path-like
        What :func:`open_bag` takes.

    Returns
    -------
    Path
        The bag.

    Raises
    ------
    BagError
        As :func:`resolve_bag_path`.

    """
    p = Path(path)
    return p if p.exists() and _lone_mcap(p) is not None else resolve_bag_path(p)


def _lone_mcap(path: Path) -> Path | None:
    """
    Return the mcap file a bag path names without a ``metadata.yaml`` beside it.

    (a bare ``.mcap`` file, or a folder holding one, as a killed recorder leaves it), else None.
    """
    if path.is_file() and path.suffix == '.mcap' and not (path.parent / 'metadata.yaml').is_file():
        return path
    if path.is_dir() and not (path / 'metadata.yaml').is_file():
        files = sorted(path.glob('*.mcap'))
        return files[0] if len(files) == 1 else None
    return None


def _reader_errors() -> tuple:
    import sqlite3
    import struct
    import zlib

    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as Reader1Error
    from rosbags.rosbag2 import ReaderError as Reader2Error
    from rosbags.serde import SerdeError
    from rosbags.typesys import TypesysError

    return (
        AnyReaderError,
        Reader1Error,
        Reader2Error,
        SerdeError,
        TypesysError,
        sqlite3.Error,
        struct.error,
        zlib.error,
        EOFError,
        OSError,
        KeyError,
        IndexError,
        ValueError,
        AssertionError,
    )


def open_bag(path, warn=None):
    """
    Open a bag with rosbags' AnyReader.

    An mcap file that cannot be opened as it is (a recorder killed before it wrote the summary, a
    file cut short) and a bare ``.mcap`` file without its ``metadata.yaml`` are read record by
    record up to the last intact chunk (:func:`salvage_mcap`); ``warn`` is told where a truncated
    one stopped.

    Parameters
    ----------
    path : str or path-like
        As :func:`resolve_bag_path` takes it, or a bare ``.mcap`` file.
    warn : callable, optional
        Receives a warning (one line) when only a part of the bag can be read.

    Returns
    -------
    rosbags.highlevel.AnyReader
        The open reader (close it, or use ``with``).

    Raises
    ------
    BagError
        For a bag that is missing, truncated with nothing intact, or corrupt.

    """
    from rosbags.highlevel import AnyReader

    p = Path(path)
    lone = _lone_mcap(p) if p.exists() else None
    if lone is not None:
        return _salvaged_reader(lone, warn)
    p = resolve_bag_path(path)
    try:
        reader = AnyReader([p], default_typestore=ros2_typestore())
        reader.open()
    except _reader_errors() as exc:
        storage = sorted(p.glob('*.mcap')) if p.is_dir() else []
        if len(storage) == 1:
            return _salvaged_reader(storage[0], warn)
        raise BagError(
            f'cannot read bag {p} (missing, truncated or corrupt?): {one_line(exc)}'
        ) from None
    return reader


def _salvaged_reader(mcap: Path, warn):
    """
    Return an AnyReader over the intact part of ``mcap``.

    Copied into a temporary rosbag2 folder removed on close.
    """
    import tempfile

    from rosbags.highlevel import AnyReader

    class SalvagedReader(AnyReader):
        def close(self) -> None:
            try:
                super().close()
            finally:
                shutil.rmtree(tmp, ignore_errors=True)

    tmp = Path(tempfile.mkdtemp(prefix='iemd-mcap-'))
    try:
        salvage = salvage_mcap(mcap, tmp / 'bag')
        if salvage.stop:
            if not salvage.messages:
                raise BagError(
                    f'bag {mcap} is truncated or corrupt with no intact chunk: {salvage.stop}'
                )
            if warn is not None:
                warn(
                    f'bag {mcap} is truncated: {salvage.stop}; reading its {salvage.messages} '
                    'messages before '
                    f'byte {salvage.intact_bytes}'
                )
        reader = SalvagedReader([tmp / 'bag'], default_typestore=ros2_typestore())
        reader.open()
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return reader


@dataclass(frozen=True)
class Salvage:
    """
    What :func:`salvage_mcap` could read.

    Parameters
    ----------
    messages : int
        Messages copied.
    intact_bytes : int
        Bytes of the file before the first record that could not be read (its size when all could).
    stop : str
        Why the reading stopped early ("" when the whole file was read).
    skipped_topics : tuple of str
        Topics of types the typestore does not know, not copied.

    """

    messages: int
    intact_bytes: int
    stop: str
    skipped_topics: tuple[str, ...] = ()


_MCAP_MAGIC = b'\x89MCAP0\r\n'


def salvage_mcap(mcap, out) -> Salvage:
    """
    Copy the messages of an mcap file, record by record, into a new rosbag2 (mcap) folder ``out``.

    The file is read from its start, without the summary at its end (a killed recorder never writes
    one): schemas, channels and messages, in and out of chunks, until the end or the first record
    that is cut short or whose chunk does not decompress; a chunk is copied only whole.

    Parameters
    ----------
    mcap : str or path-like
        The mcap file.
    out : str or path-like
        The new rosbag2 folder (must not exist).

    Returns
    -------
    Salvage
        How much was copied and why it stopped.

    Raises
    ------
    BagError
        For a file that is not an mcap file.

    """
    import struct

    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.rosbag2.storage_mcap import decompress

    data = Path(mcap).read_bytes()
    if not data.startswith(_MCAP_MAGIC):
        raise BagError(f'{mcap} is not an mcap file (no MCAP magic)')
    typestore = ros2_typestore()
    schemas: dict[int, str] = {}
    channels: dict[int, object] = {}
    skipped: set[str] = set()
    count = 0

    def records(buf: bytes, pos: int, end: int):
        """
        (opcode, body, offset after it) of each whole record in buf[pos:end].

        Stops at a record cut short.
        """
        while pos + 9 <= end:
            op, size = buf[pos], struct.unpack_from('<Q', buf, pos + 1)[0]
            if pos + 9 + size > end:
                return
            yield op, memoryview(buf)[pos + 9: pos + 9 + size], pos + 9 + size
            pos += 9 + size

    def text(body, at: int) -> tuple[str, int]:
        n = struct.unpack_from('<I', body, at)[0]
        return bytes(body[at + 4: at + 4 + n]).decode(), at + 4 + n

    def take(op: int, body, writer) -> None:
        nonlocal count
        if op == 0x03:  # Schema: id, name, encoding, data
            schemas[struct.unpack_from('<H', body, 0)[0]] = text(body, 2)[0]
        # Channel: id, schema id, topic, message encoding, metadata
        elif op == 0x04:
            cid, sid = struct.unpack_from('<HH', body, 0)
            topic, _ = text(body, 4)
            msgtype = schemas.get(sid, '')
            if cid in channels or topic in skipped:
                # a repeat (the summary section repeats the channels)
                pass
            elif msgtype in typestore.types:
                channels[cid] = writer.add_connection(topic, msgtype, typestore=typestore)
            else:
                skipped.add(topic)
        # Message: channel, sequence, log time, publish time, data
        elif op == 0x05:
            cid, _, log_time = struct.unpack_from('<HIQ', body, 0)
            if cid in channels:
                writer.write(channels[cid], log_time, bytes(body[22:]))
                count += 1

    stop, complete = '', False
    with Writer(Path(out), version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        pos = len(_MCAP_MAGIC)
        for op, body, after in records(data, pos, len(data)):
            # DataEnd (the summary follows) or Footer: the messages are all read
            if op in (0x0F, 0x02):
                complete = True
                break
            # Chunk: start, end, uncompressed size, crc, compression, records
            if op == 0x06:
                try:
                    _, _, size, crc = struct.unpack_from('<QQQI', body, 0)
                    compression, at = text(body, 28)
                    n = struct.unpack_from('<Q', body, at)[0]
                    inner = decompress(bytes(body[at + 8: at + 8 + n]), compression, size, crc)
                except Exception as exc:  # any damage ends the intact part
                    stop = f'the chunk at byte {pos} does not decompress ({one_line(exc)})'
                    break
                for inner_op, inner_body, _ in records(inner, 0, len(inner)):
                    take(inner_op, inner_body, writer)
            else:
                take(op, body, writer)
            pos = after
        if complete:
            pos = len(data)
        elif not stop:
            stop = (
                f'the record at byte {pos} of {len(data)} is cut short'
                if pos < len(data)
                else 'the file ends without its data-end and footer records'
            )
    return Salvage(count, pos, stop, tuple(sorted(skipped)))


def iter_messages(reader, connections, path='bag') -> Iterator[tuple[object, int, bytes]]:
    """
    ``reader.messages(connections)``; a read error (truncated/corrupt storage) becomes a BagError.

    Parameters
    ----------
    reader : rosbags.highlevel.AnyReader
        An open reader.
    connections : list
        The connections to read.
    path : str or path-like, optional
        The bag's name in the error message.

    Yields
    ------
    tuple
        (connection, log time ns, raw message bytes), in log-time order.

    Raises
    ------
    BagError
        For truncated or corrupt storage.

    """
    it = reader.messages(connections=connections)
    while True:
        try:
            item = next(it)
        except StopIteration:
            return
        except _reader_errors() as exc:
            raise BagError(f'bag {path} is truncated or corrupt: {one_line(exc)}') from None
        yield item


def deserialize(reader, raw: bytes, msgtype: str, path='bag'):
    """
    Decode a raw message.

    Parameters
    ----------
    reader : rosbags.highlevel.AnyReader
        The open reader it was read with.
    raw : bytes
        The serialized message.
    msgtype : str
        Its full type name.
    path : str or path-like, optional
        The bag's name in the error message.

    Returns
    -------
    object
        The message.

    Raises
    ------
    BagError
        For a message that cannot be decoded.

    """
    try:
        return reader.deserialize(raw, msgtype)
    except _reader_errors() as exc:
        raise BagError(f'bag {path}: cannot decode a {msgtype} message: {one_line(exc)}') from None


@dataclass(frozen=True)
class Topics:
    """
    Topics chosen for replay; ``imu``/``camera_info`` are None when the bag has none.

    Parameters
    ----------
    image : str
        The image topic (``sensor_msgs/Image`` or ``sensor_msgs/CompressedImage``).
    imu : str or None
        The IMU topic.
    camera_info : str or None
        The camera-info topic.

    """

    image: str
    imu: str | None
    camera_info: str | None


def _listing(topics: dict, names) -> str:
    return ', '.join(f'{t} [{topics[t].msgtype}]' for t in sorted(names)) or 'none'


def _pick(
    topics: dict,
    msgtypes: tuple[str, ...],
    wanted: str | None,
    role: str,
    required: bool,
    narrow=lambda topics, names: names,
) -> str | None:
    """
    Return the ``role`` topic.

    ``wanted`` if given (of one of ``msgtypes``), else the one topic of those types that
    ``narrow(topics, names)`` keeps; None (or BagError if ``required``) when the bag has none.
    """
    expected = ' or '.join(msgtypes)
    if wanted is not None:
        if wanted not in topics:
            raise BagError(
                f'{role} topic {wanted!r} is not in the bag (topics: '
                f'{", ".join(sorted(topics)) or "none"})'
            )
        if topics[wanted].msgtype not in msgtypes:
            raise BagError(
                f'{role} topic {wanted!r} has type {topics[wanted].msgtype}, expected {expected}'
            )
        return wanted
    of_type = [t for t, info in topics.items() if info.msgtype in msgtypes]
    if not of_type:
        if required:
            raise BagError(f'the bag has no {expected} topic (topics: {_listing(topics, topics)})')
        return None
    candidates = narrow(topics, of_type)
    if len(candidates) > 1:
        flag = {
            'image': '--image-topic',
            'IMU': '--imu-topic',
            'camera-info': '--camera-info-topic',
        }[role]
        raise BagError(
            f'the bag has {len(candidates)} {role} topics ({_listing(topics, candidates)}); '
            f'choose one with {flag}'
        )
    return candidates[0]


def _image_candidates(topics: dict, images: list[str]) -> list[str]:
    """
    Return the image topics auto-detection may take.

    Those holding messages (all of them if none does), without a compressed topic whose raw twin
    holds messages (module docstring).
    """
    filled = [t for t in images if topics[t].msgcount > 0] or images
    raw = {t for t in filled if topics[t].msgtype == IMAGE_TYPE}
    return [
        t
        for t in filled
        if not (topics[t].msgtype == COMPRESSED_IMAGE_TYPE and raw_twin(t) in raw)
    ]


def select_topics(
    reader, image: str | None = None, imu: str | None = None, camera_info: str | None = None
) -> Topics:
    """
    Choose the image, IMU and camera-info topics of an open reader (see module docstring).

    Parameters
    ----------
    reader : rosbags.highlevel.AnyReader
        An open reader.
    image, imu, camera_info : str, optional
        The topics to use (default: auto-detected).

    Returns
    -------
    Topics
        The topics chosen.

    Raises
    ------
    BagError
        For a named topic missing or of the wrong type, an ambiguous choice, no image topic, or an
        image topic with no message.

    """
    topics = reader.topics
    img = _pick(topics, IMAGE_TYPES, image, 'image', True, narrow=_image_candidates)
    if topics[img].msgcount == 0:
        raise BagError(f'image topic {img!r} holds no message')
    return Topics(
        img,
        _pick(topics, (IMU_TYPE,), imu, 'IMU', False),
        _pick(topics, (CAMERA_INFO_TYPE,), camera_info, 'camera-info', False),
    )


def custom_data(reader) -> dict:
    """
    rosbag2 ``custom_data`` of an open reader.

    Parameters
    ----------
    reader : rosbags.highlevel.AnyReader
        An open reader.

    Returns
    -------
    dict
        Key -> value; {} for ROS 1 bags.

    """
    out: dict = {}
    for r in getattr(reader, 'readers', []):
        md = getattr(getattr(r, 'storage', None), 'metadata', None)
        out.update(getattr(md, 'custom', None) or {})
    return out
