"""ROS 1 and ROS 2 bags, written here from a synthetic folder, map to the folder's trajectory:
through the Python API and through the CLI."""

import subprocess
import sys

import numpy as np
import pytest

import kartograf as kg
from bag_writer import write_bag
from test_odometry import read_tum


def test_a_ros2_and_a_ros1_bag_give_the_folders_trajectory(cpu, synthetic, tmp_path):
    sequence = kg.open_sequence(synthetic)
    folder_run = kg.run_odometry(cpu, sequence)
    for ros1, bag in ((False, tmp_path / "ros2_bag"), (True, tmp_path / "run.bag")):
        write_bag(sequence, synthetic, bag, ros1)
        assert kg.rosbag.is_bag(bag)
        converted = kg.rosbag.bag_to_folder(bag, tmp_path / f"frames_{ros1}")
        assert converted.topics.depth == "/camera/aligned_depth_to_color/image_raw"
        assert converted.topics.camera_info == "/camera/color/camera_info"
        assert converted.color_frames == converted.depth_frames == len(sequence)
        assert converted.camera == sequence.camera
        from_bag = kg.open_sequence(converted.folder)
        first = from_bag.frame(3)
        assert np.array_equal(first["depth"], sequence.frame(3)["depth"])
        assert np.array_equal(first["color"], sequence.frame(3)["color"])
        run = kg.run_odometry(cpu, from_bag)
        assert np.array_equal(run.poses, folder_run.poses), f"ros1={ros1}"


def test_the_cli_reads_a_bag(cpu, synthetic, tmp_path):
    sequence = kg.open_sequence(synthetic)
    bag = tmp_path / "cli_bag"
    write_bag(sequence, synthetic, bag, ros1=False)
    out = tmp_path / "trajectory.txt"
    done = subprocess.run([sys.executable, "-m", "kartograf._cli", "odometry", str(bag), "--out",
                           str(out), "--backend", "cpu", "--no-progress"],
                          check=True, capture_output=True, text=True)
    assert "bag:" in done.stderr
    from_folder = tmp_path / "folder_trajectory.txt"
    subprocess.run([sys.executable, "-m", "kartograf._cli", "odometry", str(synthetic), "--out",
                    str(from_folder), "--backend", "cpu", "--no-progress"], check=True,
                   capture_output=True)
    assert np.array_equal(read_tum(out), read_tum(from_folder))
    # The whole map (SLAM, views, grid, rooms) of the bag and of the folder: the same trajectory.
    for source, name in ((bag, "map_bag"), (synthetic, "map_folder")):
        subprocess.run([sys.executable, "-m", "kartograf._cli", "map", str(source), "--out",
                        str(tmp_path / name), "--backend", "cpu", "--no-progress"], check=True,
                       capture_output=True)
    assert np.array_equal(read_tum(tmp_path / "map_bag" / "trajectory.txt"),
                          read_tum(tmp_path / "map_folder" / "trajectory.txt"))


def test_a_bag_from_a_depth_camera_alone(cpu, synthetic, tmp_path):
    sequence = kg.open_sequence(synthetic)
    bag = tmp_path / "depth_bag"
    write_bag(sequence, synthetic, bag, ros1=False, colour=False)
    converted = kg.rosbag.bag_to_folder(bag, tmp_path / "frames")
    assert converted.topics.color is None and converted.color_frames == 0
    assert converted.depth_frames == len(sequence)
    assert not (converted.folder / "rgb").exists() and not (converted.folder / "rgb.txt").exists()
    from_bag = kg.open_sequence(converted.folder)
    assert not from_bag.has_color
    assert np.array_equal(from_bag.frame(3)["depth"], sequence.frame(3)["depth"])
    run = kg.run_odometry(cpu, from_bag)
    truth = [sequence.frame(i)["pose"] for i in range(len(sequence))]
    assert kg.ate(run.poses, truth).rmse_m < 0.05
    # A colour topic asked for by name must exist.
    with pytest.raises(kg.Error, match="no topic /camera/color/image_raw"):
        kg.rosbag.bag_to_folder(bag, tmp_path / "out", color_topic="/camera/color/image_raw")
    # The CLI maps it (without features, said) as it maps the folder.
    done = subprocess.run([sys.executable, "-m", "kartograf._cli", "map", str(bag), "--out",
                           str(tmp_path / "map"), "--backend", "cpu", "--no-progress"],
                          check=True, capture_output=True, text=True)
    assert "no colour topic (a depth camera alone)" in done.stderr
    assert "no local image features" in done.stderr
    assert (tmp_path / "map" / "mesh.ply").is_file()


def test_missing_topics_are_named(tmp_path, synthetic):

    sequence = kg.open_sequence(synthetic, frames=2)
    bag = tmp_path / "bag"
    write_bag(sequence, synthetic, bag, ros1=False)
    with pytest.raises(kg.Error, match="no topic /nothing"):
        kg.rosbag.bag_to_folder(bag, tmp_path / "out", depth_topic="/nothing")


def test_the_bags_odometry_and_tf_give_the_cameras_poses(cpu, synthetic, tmp_path):
    from test_odometry import pose_rows

    sequence = kg.open_sequence(synthetic)
    truth = np.array([sequence.frame(i)["pose"] for i in range(len(sequence))])
    for ros1, bag in ((False, tmp_path / "ros2_odom"), (True, tmp_path / "odom.bag")):
        write_bag(sequence, synthetic, bag, ros1, odometry=True)
        converted = kg.rosbag.bag_to_folder(bag, tmp_path / f"prior_{ros1}", pose_prior=True)
        assert converted.topics.odometry == "/odom"
        assert np.allclose(read_tum(converted.prior), pose_rows(truth), atol=1e-6), f"ros1={ros1}"
    # The CLI: --bag-poses maps at those poses, as --poses groundtruth does on the folder.
    run = [sys.executable, "-m", "kartograf._cli", "map"]
    common = ["--backend", "cpu", "--no-progress"]
    subprocess.run([*run, str(tmp_path / "ros2_odom"), "--bag-poses", "--out", str(tmp_path / "a"),
                    *common], check=True, capture_output=True)
    subprocess.run([*run, str(synthetic), "--poses", "groundtruth", "--out", str(tmp_path / "b"),
                    *common], check=True, capture_output=True)
    assert np.allclose(read_tum(tmp_path / "a" / "trajectory.txt"),
                       read_tum(tmp_path / "b" / "trajectory.txt"), atol=1e-5)
    # --bag-prior: the same poses as the odometry's motion prior (every step after the first).
    done = subprocess.run([sys.executable, "-m", "kartograf._cli", "odometry",
                           str(tmp_path / "ros2_odom"), "--bag-prior", "--out",
                           str(tmp_path / "prior.txt"), *common], check=True, capture_output=True,
                          text=True)
    assert f"predicted by the motion prior {len(sequence) - 1}" in done.stdout
    both = subprocess.run([*run, str(tmp_path / "ros2_odom"), "--bag-poses", "--bag-prior",
                           "--out", str(tmp_path / "c"), *common], capture_output=True, text=True)
    assert both.returncode != 0 and "not both" in both.stderr


def test_tf_alone_gives_the_cameras_poses_between_its_samples(cpu, synthetic, tmp_path):
    """No odometry topic: /tf's odom -> base_link at every 2nd frame, interpolated at the others,
    chained with /tf_static's base -> camera."""
    from kartograf.bag_poses import matrix_of
    from test_odometry import pose_rows

    sequence = kg.open_sequence(synthetic)
    truth = pose_rows([sequence.frame(i)["pose"] for i in range(len(sequence))])
    sampled = np.array([i % 2 == 0 or i == len(sequence) - 1 for i in range(len(sequence))])
    for ros1, bag in ((False, tmp_path / "ros2_tf"), (True, tmp_path / "tf.bag")):
        write_bag(sequence, synthetic, bag, ros1, tf_every=2)
        converted = kg.rosbag.bag_to_folder(bag, tmp_path / f"tf_{ros1}", pose_prior=True)
        assert converted.topics.odometry is None and converted.topics.world == "odom"
        prior = read_tum(converted.prior)
        error = np.linalg.norm(prior[:, :3] - truth[:, :3], axis=1)
        assert error[sampled].max() < 1e-6 and np.allclose(prior[sampled], truth[sampled],
                                                           atol=1e-6), f"ros1={ros1}"
        # Between samples: far closer to the true pose than the neighbouring samples are.
        step = np.linalg.norm(np.diff(truth[:, :3], axis=0), axis=1)
        between = np.flatnonzero(~sampled)
        neighbour = np.minimum(step[between - 1], step[between])
        assert (error[between] < 0.25 * neighbour).all(), (error[between], neighbour)
        assert error[between].max() < 0.003, error[between].max()
    with pytest.raises(kg.Error, match="no transform from 'map' to 'camera_optical'"):
        kg.rosbag.bag_to_folder(tmp_path / "ros2_tf", tmp_path / "no_map", pose_prior=True,
                                tf_world="map")
    # The CLI's --bag-poses --tf-world: the map is made at the prior's poses (its trajectory is
    # in the map's frame: one rigid motion away from the prior).
    subprocess.run([sys.executable, "-m", "kartograf._cli", "map", str(tmp_path / "ros2_tf"),
                    "--bag-poses", "--tf-world", "odom", "--out", str(tmp_path / "map"),
                    "--backend", "cpu", "--no-progress"], check=True, capture_output=True)
    mapped = [matrix_of(r[:3], r[3:]) for r in read_tum(tmp_path / "map" / "trajectory.txt")]
    given = [matrix_of(r[:3], r[3:]) for r in read_tum(tmp_path / "tf_False" / "prior.txt")]
    offsets = np.array([m @ np.linalg.inv(g) for m, g in zip(mapped, given)])
    assert len(mapped) == len(given) and np.allclose(offsets, offsets[0], atol=1e-5)
