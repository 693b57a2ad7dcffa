"""Small ROS bags made from a sequence folder, with rosbags' writers (as a robot would record):
ROS 2 with raw rgb8 colour, ROS 1 with PNG-compressed colour; depth 32FC1 in metres (exact for
TUM's 1/5000 m steps); one camera_info."""

from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore


def _header(types, ros1, t):
    stamp = types["builtin_interfaces/msg/Time"](sec=int(t), nanosec=int(round((t % 1) * 1e9)))
    fields = {"stamp": stamp, "frame_id": "camera"}
    if ros1:
        fields["seq"] = 0
    return types["std_msgs/msg/Header"](**fields)


def _depth(types, ros1, t, depth):
    metres = (depth.astype(np.float64) / 5000.0).astype("<f4")
    h, w = depth.shape
    return types["sensor_msgs/msg/Image"](
        header=_header(types, ros1, t), height=h, width=w, encoding="32FC1", is_bigendian=0,
        step=w * 4, data=np.frombuffer(metres.tobytes(), np.uint8))


def _color(types, ros1, t, color, png):
    if png is not None:
        return types["sensor_msgs/msg/CompressedImage"](
            header=_header(types, ros1, t), format="png",
            data=np.frombuffer(Path(png).read_bytes(), np.uint8))
    h, w, _ = color.shape
    return types["sensor_msgs/msg/Image"](
        header=_header(types, ros1, t), height=h, width=w, encoding="rgb8", is_bigendian=0,
        step=w * 3, data=np.frombuffer(color.tobytes(), np.uint8))


def _camera_info(types, ros1, camera):
    k = np.array([camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1], np.float64)
    matrices = {"D": np.zeros(5), "K": k, "R": np.eye(3).ravel(),
                "P": np.array([camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0],
                              np.float64)}
    if not ros1:
        matrices = {name.lower(): value for name, value in matrices.items()}
    roi = types["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                     do_rectify=False)
    return types["sensor_msgs/msg/CameraInfo"](
        header=_header(types, ros1, 0.0), height=camera.height, width=camera.width,
        distortion_model="plumb_bob", binning_x=0, binning_y=0, roi=roi, **matrices)


def write_bag(sequence, folder, path, ros1):
    """The sequence's frames into a bag at path; colour from the folder's PNGs for ROS 1."""
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    types = store.types
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    writer = Writer1(path) if ros1 else Writer2(path, version=9)
    with writer:
        add = (lambda topic, msgtype: writer.add_connection(topic, msgtype, typestore=store))
        info = add("/camera/color/camera_info", "sensor_msgs/msg/CameraInfo")
        depth_topic = add("/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image")
        color_type = "sensor_msgs/msg/CompressedImage" if ros1 else "sensor_msgs/msg/Image"
        color_topic = add("/camera/color/image_raw" + ("/compressed" if ros1 else ""), color_type)
        rgb_files = sorted((Path(folder) / "rgb").glob("*.png"))
        writer.write(info, 1, serialize(_camera_info(types, ros1, sequence.camera),
                                        "sensor_msgs/msg/CameraInfo"))
        for i in range(len(sequence)):
            frame = sequence.frame(i)
            t = frame["timestamp"]
            ns = int(round(t * 1e9))
            writer.write(depth_topic, ns, serialize(_depth(types, ros1, t, frame["depth"]),
                                                    "sensor_msgs/msg/Image"))
            color = _color(types, ros1, t, frame["color"], rgb_files[i] if ros1 else None)
            writer.write(color_topic, ns, serialize(color, color_type))
