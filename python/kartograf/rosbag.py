"""ROS recordings as input: ROS 1 .bag and ROS 2 bags (.db3, .mcap), read with the pure-Python
`rosbags` package (pip install rosbags), no ROS installation.

A bag becomes a TUM RGB-D folder (rgb/, depth/, rgb.txt, depth.txt, camera_intrinsics.json),
which every Kartograf reader, pipeline and CLI command takes; colour and depth are paired by their
header stamps as TUM's tools pair them (within 0.02 s). A bag with no image topic but the depth's
(a depth camera alone) becomes depth/ and depth.txt only: what needs no colour runs on it
(odometry, slam without features, map, semantic, fuse, planes in the cells mode).

    folder = kg.rosbag.bag_to_folder("run.bag", "run_frames")   # topics chosen automatically
    run = kg.run_odometry(context, kg.open_sequence(folder))

Images: sensor_msgs/Image (depth 16UC1 in millimetres or 32FC1 in metres; colour rgb8, bgr8,
rgba8, bgra8, mono8) and sensor_msgs/CompressedImage (colour png or jpeg; depth
"compressedDepth png", millimetres). Depth is written in TUM's 5000 units per metre. Intrinsics:
the camera_info topic's K (sensor_msgs/CameraInfo).

A pose prior (pose_prior=True; the CLI's --bag-poses): the camera's pose at every depth image's
stamp, written as prior.txt (TUM) for `--poses`. It is the chain of transforms from a world frame
to the images' frame (kartograf.bag_poses): a nav_msgs/Odometry topic (the bag's only one, or
odometry_topic) gives its child frame's pose in its header's frame, which is then the world;
without one, /tf's changing transforms do (odom -> base_link, ...) from the images' topmost frame
or from tf_world. /tf_static adds the fixed links (base to camera); changing ones are interpolated
at each image's stamp.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from . import _kartograf, bag_poses

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED = "sensor_msgs/msg/CompressedImage"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
ODOMETRY = "nav_msgs/msg/Odometry"
TF = "tf2_msgs/msg/TFMessage"
TUM_UNITS = 5000.0  # depth units per metre in the folder


@dataclass
class BagTopics:
    color: Optional[str]  # None: a depth camera alone (the folder then has no rgb/)
    depth: str
    camera_info: Optional[str]
    odometry: Optional[str] = None  # the pose prior's (nav_msgs/Odometry), when asked for
    world: Optional[str] = None  # the pose prior's world frame (the odometry's, or /tf's root)


@dataclass
class BagConversion:
    folder: Path
    topics: BagTopics
    color_frames: int
    depth_frames: int
    camera: _kartograf.PinholeIntrinsics
    prior: Optional[Path] = None  # prior.txt: camera poses from the odometry topic (TUM)


def is_bag(path: str | os.PathLike) -> bool:
    """A ROS 1 .bag, a ROS 2 storage file (.db3, .mcap) or a ROS 2 bag folder (metadata.yaml)."""
    p = Path(path)
    return p.suffix in (".bag", ".db3", ".mcap") or (p / "metadata.yaml").is_file()


def _reader(path: Path):
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError as error:
        raise ImportError("reading ROS bags needs rosbags (pip install rosbags)") from error
    # A ROS 2 storage file is read through its folder (metadata.yaml beside it).
    bag = path.parent if path.suffix in (".db3", ".mcap") and (
        path.parent / "metadata.yaml").is_file() else path
    return AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE))


def _image_topics(topics: dict) -> list:
    return [t for t, info in topics.items() if info.msgtype in (IMAGE, COMPRESSED)]


def choose_topics(topics: dict, color: Optional[str] = None, depth: Optional[str] = None,
                  camera_info: Optional[str] = None) -> BagTopics:
    """The colour, depth and camera_info topics: given, else by name ('depth' for depth; 'color',
    'rgb' or 'image' for colour, None when the bag has no other image topic: a depth camera
    alone; the camera_info in the depth topic's namespace, else any)."""
    images = _image_topics(topics)
    listing = ", ".join(f"{t} ({i.msgtype})" for t, i in sorted(topics.items()))
    if depth is None:
        candidates = [t for t in images if "depth" in t.lower()]
        if not candidates:
            raise _kartograf.Error(f"bag: no depth image topic (name with 'depth'); topics: {listing}")
        depth = min(candidates, key=lambda t: ("aligned" not in t and "registered" not in t, t))
    if color is None:
        candidates = [t for t in images if t != depth and "depth" not in t.lower()]
        ranked = sorted(candidates, key=lambda t: (not any(k in t.lower() for k in ("color", "rgb")), t))
        color = ranked[0] if ranked else None
    for topic in (color, depth):
        if topic is not None and topic not in topics:
            raise _kartograf.Error(f"bag: no topic {topic}; topics: {listing}")
    if camera_info is None:
        infos = [t for t, i in topics.items() if i.msgtype == CAMERA_INFO]
        namespace = depth.rsplit("/", 1)[0]
        near = [t for t in infos if t.startswith(namespace)]
        camera_info = (near or infos or [None])[0]
    return BagTopics(color=color, depth=depth, camera_info=camera_info)


def choose_odometry_topic(topics: dict, odometry: Optional[str] = None) -> Optional[str]:
    """The nav_msgs/Odometry topic: given, else the bag's only one, else None (the prior then
    comes from /tf); an Error naming them when there are several."""
    found = sorted(t for t, i in topics.items() if i.msgtype == ODOMETRY)
    if odometry is None and len(found) > 1:
        raise _kartograf.Error(f"bag: {len(found)} odometry topics ({', '.join(found)}); name one")
    if odometry is None and not found:
        return None
    odometry = odometry or found[0]
    if odometry not in topics or topics[odometry].msgtype != ODOMETRY:
        raise _kartograf.Error(f"bag: {odometry} is not a nav_msgs/Odometry topic")
    return odometry


def _stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def _tum_depth(millimetres: np.ndarray) -> np.ndarray:
    """Depth in millimetres as the folder's TUM units (5000 per metre)."""
    scaled = millimetres.astype(np.float64) * TUM_UNITS / 1000.0
    return np.clip(scaled, 0, 65535).round().astype(np.uint16)


def _raw_image(msg) -> np.ndarray:
    """A sensor_msgs/Image as uint16 depth (TUM units), or H x W x 3 uint8 RGB."""
    data = np.frombuffer(bytes(msg.data), dtype=np.uint8)
    rows = data.reshape(msg.height, msg.step)
    encoding = msg.encoding.lower()
    if encoding in ("16uc1", "mono16"):
        return _tum_depth(rows[:, : msg.width * 2].copy().view(">u2" if msg.is_bigendian else "<u2"))
    if encoding == "32fc1":
        metres = rows[:, : msg.width * 4].copy().view(">f4" if msg.is_bigendian else "<f4")
        metres = np.nan_to_num(metres.astype(np.float64), nan=0.0, posinf=0.0, neginf=0.0)
        return np.clip(np.round(metres * TUM_UNITS), 0, 65535).astype(np.uint16)
    channels = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "bgra8": 4, "mono8": 1}.get(encoding)
    if channels is None:
        raise _kartograf.Error(f"bag: image encoding '{msg.encoding}' is not supported")
    pixels = rows[:, : msg.width * channels].reshape(msg.height, msg.width, channels)
    if channels == 1:
        pixels = np.repeat(pixels, 3, axis=2)
    if encoding.startswith("bgr"):
        pixels = pixels[:, :, 2::-1]
    return np.ascontiguousarray(pixels[:, :, :3])


def _compressed_image(msg, depth: bool, scratch: Path) -> np.ndarray:
    data = bytes(msg.data)
    if depth:
        # compressedDepth: a 12-byte header (format, quantisation) before the PNG of millimetres.
        if "compresseddepth" in msg.format.lower():
            data = data[12:]
        scratch.write_bytes(data)
        return _tum_depth(_kartograf.read_depth_png(scratch))
    scratch.write_bytes(data)
    return _kartograf.read_color_image(scratch)


def _camera(msg) -> _kartograf.PinholeIntrinsics:
    k = np.asarray(msg.k if hasattr(msg, "k") else msg.K, dtype=np.float64)  # ROS 2, ROS 1
    return _kartograf.PinholeIntrinsics(int(msg.width), int(msg.height), k[0], k[4], k[2], k[5])


def _transform_matrix(stamped) -> np.ndarray:
    """parent_T_child of a geometry_msgs/TransformStamped."""
    transform = stamped.transform
    return bag_poses.message_matrix(transform.translation, transform.rotation)


class _PoseRecords:
    """What the pose prior is made of, gathered while the bag is read."""

    def __init__(self, topics: dict, odometry_topic: Optional[str]):
        self.odometry_topic = choose_odometry_topic(topics, odometry_topic)
        self.tf_topics = {t for t, i in topics.items() if i.msgtype == TF}
        self.fixed, self.changing, self.odometry = [], [], []

    def take(self, topic: str, msg) -> None:
        if topic == self.odometry_topic:
            self.odometry.append(msg)
            return
        static = topic.rstrip("/").endswith("tf_static")
        for stamped in msg.transforms:
            (self.fixed if static else self.changing).append(stamped)

    def tree(self) -> bag_poses.FrameTree:
        """The odometry's poses win over /tf's samples of the same link."""
        tree = bag_poses.FrameTree()
        for msg in self.odometry:
            pose = bag_poses.message_matrix(msg.pose.pose.position, msg.pose.pose.orientation)
            tree.add_sample(msg.header.frame_id, msg.child_frame_id, _stamp(msg), pose)
        for stamped in self.changing:
            parent, child = stamped.header.frame_id, stamped.child_frame_id
            if not (self.odometry and tree.has_edge(parent, child)):
                tree.add_sample(parent, child, _stamp(stamped), _transform_matrix(stamped))
        for stamped in self.fixed:
            tree.add_fixed(stamped.header.frame_id, stamped.child_frame_id,
                           _transform_matrix(stamped))
        tree.finish()
        return tree

    def write(self, path: Path, camera_frame: str, stamps: list, world: Optional[str]) -> str:
        """prior.txt at the depth images' stamps; returns the world frame."""
        if self.odometry_topic and not self.odometry:
            raise _kartograf.Error(f"bag: {self.odometry_topic} holds no message")
        if not self.odometry_topic and not self.changing:
            raise _kartograf.Error("bag: no nav_msgs/Odometry topic and no /tf transform to take "
                                   "the camera's poses from")
        tree = self.tree()
        world = world or (self.odometry[0].header.frame_id.lstrip("/") if self.odometry
                          else tree.root(camera_frame))
        source = self.odometry_topic or f"/tf from '{world}'"
        bag_poses.write_tum(path, bag_poses.camera_poses(tree, world, camera_frame, stamps),
                            f"{source} to '{camera_frame}'")
        return world


def bag_to_folder(bag: str | os.PathLike, folder: str | os.PathLike,
                  color_topic: Optional[str] = None, depth_topic: Optional[str] = None,
                  camera_info_topic: Optional[str] = None,
                  camera: Optional[_kartograf.PinholeIntrinsics] = None,
                  pose_prior: bool = False, odometry_topic: Optional[str] = None,
                  tf_world: Optional[str] = None) -> BagConversion:
    """Writes the bag's colour and depth frames as a TUM folder (depth alone when the bag has no
    colour topic: every command that needs no colour takes it); returns what it used. With
    pose_prior: also prior.txt, the camera's pose at each depth image (a TUM trajectory for
    `--poses`) from the odometry topic or /tf (from tf_world, default the topmost frame)."""
    bag, folder = Path(bag), Path(folder)
    if folder.exists() and any(folder.iterdir()):
        raise _kartograf.Error(f"bag: {folder} exists and is not empty")
    camera_frame, records = None, None
    with _reader(bag) as reader, tempfile.TemporaryDirectory() as scratch:
        topics = choose_topics(reader.topics, color_topic, depth_topic, camera_info_topic)
        lists = {"rgb": [], "depth": []} if topics.color else {"depth": []}
        for name in lists:
            (folder / name).mkdir(parents=True, exist_ok=True)
        if pose_prior:
            records = _PoseRecords(reader.topics, odometry_topic)
            topics.odometry = records.odometry_topic
        pose_topics = {records.odometry_topic, *records.tf_topics} if records else set()
        wanted = {topics.color, topics.depth, topics.camera_info, *pose_topics} - {None}
        for connection, _, raw in reader.messages(
                connections=[c for c in reader.connections if c.topic in wanted]):
            msg = reader.deserialize(raw, connection.msgtype)
            if connection.topic == topics.camera_info:
                camera = camera or _camera(msg)
            elif connection.topic in pose_topics:
                records.take(connection.topic, msg)
            else:
                if connection.topic == topics.depth and camera_frame is None:
                    camera_frame = msg.header.frame_id
                _write_frame(folder, msg, connection, topics, lists, Path(scratch) / "image")
    if camera is None:
        raise _kartograf.Error(f"bag: {bag} has no camera_info topic; give the camera")
    _kartograf.write_camera_intrinsics_json(folder / "camera_intrinsics.json", camera)
    for name, entries in lists.items():
        lines = [f"# {name} images of {bag.name}", "# timestamp filename"]
        lines += [f"{t:.6f} {name}/{t:.6f}.png" for t in entries]
        (folder / f"{name}.txt").write_text("\n".join(lines) + "\n")
    for name, entries in lists.items():
        if not entries:
            raise _kartograf.Error(f"bag: {bag} holds no {'colour' if name == 'rgb' else 'depth'} "
                                   "images on the chosen topics")
    prior = folder / "prior.txt" if records else None
    if records:
        topics.world = records.write(prior, camera_frame, lists["depth"], tf_world)
    return BagConversion(folder=folder, topics=topics, color_frames=len(lists.get("rgb", [])),
                         depth_frames=len(lists["depth"]), camera=camera, prior=prior)


def _write_frame(folder: Path, msg, connection, topics: BagTopics, lists: dict,
                 scratch: Path) -> None:
    depth = connection.topic == topics.depth
    compressed = connection.msgtype == COMPRESSED
    image = _compressed_image(msg, depth, scratch) if compressed else _raw_image(msg)
    stamp = _stamp(msg)
    name = "depth" if depth else "rgb"
    path = folder / name / f"{stamp:.6f}.png"
    if depth:
        if image.ndim != 2:
            raise _kartograf.Error(f"bag: {connection.topic} is not a depth image")
        _kartograf.write_depth_png(path, np.ascontiguousarray(image))
    else:
        _kartograf.write_color_png(path, np.ascontiguousarray(image))
    lists[name].append(stamp)
