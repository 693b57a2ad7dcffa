"""The `kartograf` command the package installs: the C++ CLI carried inside the package. A ROS
bag given where a command takes a sequence folder is converted first (kartograf.rosbag), with
--color-topic, --depth-topic and --camera-info-topic to choose the topics, and --bag-poses (with
--odometry-topic or --tf-world) to take the camera's poses from the bag's odometry or /tf, or
--bag-prior to take them as the odometry's motion prior (`--motion-prior`: each step predicted
from them, the depth still registered); `kartograf batch` maps many sequences on Ray
(kartograf.batch)."""

import os
import sys
import tempfile
from pathlib import Path

SEQUENCE_COMMANDS = {"odometry", "slam", "map", "fuse", "planes"}
TOPIC_OPTIONS = {"--color-topic": "color_topic", "--depth-topic": "depth_topic",
                 "--camera-info-topic": "camera_info_topic", "--odometry-topic": "odometry_topic",
                 "--tf-world": "tf_world"}
# Use the bag's odometry or /tf as the camera's poses (`--poses` of the converted prior) or as the
# odometry's motion prior (`--motion-prior` of it): each flag and the option it becomes.
POSE_FLAGS = {"--bag-poses": "--poses", "--bag-prior": "--motion-prior"}


def _take_topic_options(args):
    """The arguments without the topic options, those options, and the option the bag's poses
    become (None: no pose flag)."""
    rest, topics, pose_option, i = [], {}, None, 0
    while i < len(args):
        name, _, value = args[i].partition("=")
        if name in POSE_FLAGS:
            if pose_option:
                sys.exit(f"kartograf: give {' or '.join(POSE_FLAGS)}, not both")
            pose_option = POSE_FLAGS[name]
        elif name in TOPIC_OPTIONS:
            if not value:
                i += 1
                value = args[i] if i < len(args) else ""
            topics[TOPIC_OPTIONS[name]] = value
        else:
            rest.append(args[i])
        i += 1
    return rest, topics, pose_option


def _convert_bags(args, scratch):
    """The arguments with the sequence argument, when it is a bag, replaced by its frames."""
    if not args or args[0] not in SEQUENCE_COMMANDS:
        return args
    from . import rosbag

    args, topics, pose_option = _take_topic_options(args)
    for i, arg in enumerate(args[1:], start=1):
        if not arg.startswith("-") and not args[i - 1].startswith("--") and rosbag.is_bag(arg):
            converted = rosbag.bag_to_folder(arg, Path(scratch) / "frames",
                                             pose_prior=pose_option is not None, **topics)
            colour = (f"{converted.color_frames} colour images from {converted.topics.color}"
                      if converted.topics.color else "no colour topic (a depth camera alone)")
            print(f"bag: {arg}: {converted.depth_frames} depth images from "
                  f"{converted.topics.depth}; {colour}", file=sys.stderr)
            poses = [pose_option, str(converted.prior)] if converted.prior else []
            return [*args[:i], str(converted.folder), *args[i + 1:], *poses]
    return args


def main() -> None:
    here = Path(__file__).parent
    executable = here / "bin" / "kartograf"
    if not executable.is_file():
        sys.exit(f"kartograf: the CLI is missing from the package ({executable})")
    environment = dict(os.environ)
    if (here / "models").is_dir():
        environment.setdefault("KARTOGRAF_MODELS_DIR", str(here / "models"))
    if sys.argv[1:2] == ["batch"]:  # many sequences on Ray (kartograf.batch)
        from .batch import main as batch_main

        os.environ.update(environment)
        sys.exit(batch_main(sys.argv[2:]))
    with tempfile.TemporaryDirectory(prefix="kartograf-bag-") as scratch:
        try:
            args = _convert_bags(sys.argv[1:], scratch)
        except Exception as error:  # a bag that cannot be read: say so as the CLI would
            sys.exit(f"kartograf: {error}")
        if args == sys.argv[1:]:
            os.execve(executable, [str(executable), *args], environment)
        import subprocess

        sys.exit(subprocess.run([str(executable), *args], env=environment).returncode)


if __name__ == "__main__":
    main()
