"""Small ROS bags made from a sequence folder, with rosbags' writers (as a robot would record):
ROS 2 with raw rgb8 colour, ROS 1 with PNG-compressed colour; depth 32FC1 in metres (exact for
TUM's 1/5000 m steps); one camera_info."""

from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore


def _header(types, ros1, t):
    stamp = types["builtin_interfaces/msg/Time"](sec=int(t), nanosec=int(round((t % 1) * 1e9)))
    fields = {"stamp": stamp, "frame_id": "camera_optical"}
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


def _quaternion_msg(types, q):
    return types["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])


def _vector(types, name, v):
    return types[name](x=float(v[0]), y=float(v[1]), z=float(v[2]))


# base_link -> camera_link -> camera_optical: a camera 30 cm up and 10 cm ahead, turned 10 degrees
# about z, then the optical frame's axes (x right, y down, z ahead).
EXTRINSICS = (("base_link", "camera_link", (0.1, 0.0, 0.3), (0.0, 0.0, 0.0871557, 0.9961947)),
              ("camera_link", "camera_optical", (0.0, 0.0, 0.0), (-0.5, 0.5, -0.5, 0.5)))


def base_T_camera():
    from kartograf.bag_poses import matrix_of

    pose = np.eye(4)
    for _, _, t, q in EXTRINSICS:
        pose = pose @ matrix_of(t, q)
    return pose


def _stamped(types, ros1, t, parent, child, translation, q):
    header = _header(types, ros1, t)
    header.frame_id = parent
    return types["geometry_msgs/msg/TransformStamped"](
        header=header, child_frame_id=child,
        transform=types["geometry_msgs/msg/Transform"](
            translation=_vector(types, "geometry_msgs/msg/Vector3", translation),
            rotation=_quaternion_msg(types, q)))


def _tf_static(types, ros1):
    return types["tf2_msgs/msg/TFMessage"](transforms=[
        _stamped(types, ros1, 0.0, parent, child, t, q) for parent, child, t, q in EXTRINSICS])


def _base_pose(camera_pose):
    return camera_pose @ np.linalg.inv(base_T_camera())


def _tf_base(types, ros1, t, camera_pose):
    """/tf's odom -> base_link at t, as a robot's base controller publishes it."""
    from kartograf.bag_poses import quaternion

    base = _base_pose(camera_pose)
    return types["tf2_msgs/msg/TFMessage"](transforms=[
        _stamped(types, ros1, t, "odom", "base_link", base[:3, 3], quaternion(base[:3, :3]))])


def _odometry(types, ros1, t, camera_pose):
    from kartograf.bag_poses import quaternion

    base = _base_pose(camera_pose)
    zeros = np.zeros(36)
    pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=base[0, 3], y=base[1, 3], z=base[2, 3]),
        orientation=_quaternion_msg(types, quaternion(base[:3, :3])))
    twist = types["geometry_msgs/msg/Twist"](
        linear=_vector(types, "geometry_msgs/msg/Vector3", (0, 0, 0)),
        angular=_vector(types, "geometry_msgs/msg/Vector3", (0, 0, 0)))
    header = _header(types, ros1, t)
    header.frame_id = "odom"
    return types["nav_msgs/msg/Odometry"](
        header=header, child_frame_id="base_link",
        pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=zeros),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=zeros))


def write_bag(sequence, folder, path, ros1, odometry=False, tf_every=0, colour=True):
    """The sequence's frames into a bag at path; colour from the folder's PNGs for ROS 1 (none
    without colour: a depth camera alone). With
    odometry: /odom (the base's ground-truth pose) and /tf_static (base to camera). With tf_every
    k: /tf's odom -> base_link (the true pose) at every k-th frame and the last, and /tf_static."""
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if ros1 and "tf2_msgs/msg/TFMessage" not in store.types:  # noetic's store lacks tf2_msgs
        store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms",
                                          "tf2_msgs/msg/TFMessage"))
    types = store.types
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    writer = Writer1(path) if ros1 else Writer2(path, version=9)
    with writer:
        add = (lambda topic, msgtype: writer.add_connection(topic, msgtype, typestore=store))
        info = add("/camera/color/camera_info", "sensor_msgs/msg/CameraInfo")
        depth_topic = add("/camera/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image")
        color_type = "sensor_msgs/msg/CompressedImage" if ros1 else "sensor_msgs/msg/Image"
        if colour:
            color_topic = add("/camera/color/image_raw" + ("/compressed" if ros1 else ""),
                              color_type)
        rgb_files = sorted((Path(folder) / "rgb").glob("*.png"))
        if odometry:
            odom = add("/odom", "nav_msgs/msg/Odometry")
        if tf_every:
            tf = add("/tf", "tf2_msgs/msg/TFMessage")
        if odometry or tf_every:
            static = add("/tf_static", "tf2_msgs/msg/TFMessage")
            writer.write(static, 1, serialize(_tf_static(types, ros1), "tf2_msgs/msg/TFMessage"))
        writer.write(info, 1, serialize(_camera_info(types, ros1, sequence.camera),
                                        "sensor_msgs/msg/CameraInfo"))
        for i in range(len(sequence)):
            frame = sequence.frame(i)
            t = frame["timestamp"]
            ns = int(round(t * 1e9))
            writer.write(depth_topic, ns, serialize(_depth(types, ros1, t, frame["depth"]),
                                                    "sensor_msgs/msg/Image"))
            if colour:
                color = _color(types, ros1, t, frame["color"], rgb_files[i] if ros1 else None)
                writer.write(color_topic, ns, serialize(color, color_type))
            if odometry:
                writer.write(odom, ns, serialize(_odometry(types, ros1, t, frame["pose"]),
                                                 "nav_msgs/msg/Odometry"))
            if tf_every and (i % tf_every == 0 or i == len(sequence) - 1):
                writer.write(tf, ns, serialize(_tf_base(types, ros1, t, frame["pose"]),
                                               "tf2_msgs/msg/TFMessage"))
