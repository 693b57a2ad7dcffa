"""SLAM and the online mapper from Python; Open3D interop."""

import pickle
from pathlib import Path

import numpy as np
import pytest

import kartograf as kg


def test_slam_runs_and_pickles(cpu, synthetic):
    slam = kg.run_slam(cpu, kg.open_sequence(synthetic), build_map=True)
    assert slam.poses.shape == (30, 4, 4)
    assert slam.ate().rmse_m < 0.05
    assert slam.odometry.poses.shape == (30, 4, 4)
    assert slam.map.points.shape[1] == 3 and len(slam.map.points) > 1000
    copy = pickle.loads(pickle.dumps(slam))
    assert np.array_equal(copy.poses, slam.poses)
    assert copy.map.points.shape == slam.map.points.shape


def mapped(cpu, synthetic, colour=True):
    sequence = kg.open_sequence(synthetic)
    mapper = kg.Mapper(cpu, sequence.camera, sequence.depth_units_per_metre, features=False)
    for i in range(len(sequence)):
        frame = sequence.frame(i)
        step = mapper.add_frame(frame["depth"], frame["color"] if colour else None, frame["pose"])
        assert step["status"] == "given"
    return mapper


def test_the_mappers_mesh_and_distance_field_agree(cpu, synthetic):
    mapper = mapped(cpu, synthetic)
    mesh = mapper.mesh()
    assert len(mesh.triangles) > 1000 and mesh.colors.shape == mesh.vertices.shape
    field = mapper.distance_field()
    assert field.distances.shape == field.occupied.shape
    assert field.occupied.any()
    # The mesh's vertices are surface: within a cell's diagonal of an occupied cell.
    diagonal = np.sqrt(3) * field.resolution
    near = [field.distance(v) <= diagonal for v in mesh.vertices[::50]]
    assert np.mean(near) > 0.97
    assert field.distance((1e3, 1e3, 1e3)) == field.max_distance
    copy = pickle.loads(pickle.dumps(field))
    assert np.array_equal(copy.distances, field.distances)


def test_a_depth_camera_alone_gives_the_same_surface_without_colours(cpu, synthetic):
    coloured, depth_alone = mapped(cpu, synthetic).mesh(), mapped(cpu, synthetic, False).mesh()
    assert coloured.colors.shape == coloured.vertices.shape
    assert depth_alone.colors.shape == (0, 3)
    assert np.allclose(depth_alone.vertices, coloured.vertices, atol=1e-6)


def test_the_mappers_finished_map_has_rooms_and_a_semantic_grid(cpu, synthetic):
    result = mapped(cpu, synthetic).finish()
    assert result.poses.shape == (30, 4, 4)
    assert len(result.mesh.triangles) > 1000
    assert result.semantic.classes.shape == result.semantic.weight.shape
    assert result.semantic.share("floor") > 0.05 and result.semantic.share("wall") > 0.01
    assert result.room_count >= 1 and result.rooms.max() == result.room_count
    assert result.occupancy.cells.shape == result.rooms.shape
    assert pickle.loads(pickle.dumps(result)).semantic.classes.tobytes() == \
        result.semantic.classes.tobytes()


def test_the_mapper_refuses_a_pose_that_is_not_rigid(cpu, synthetic):
    sequence = kg.open_sequence(synthetic, frames=2)
    mapper = kg.Mapper(cpu, sequence.camera, sequence.depth_units_per_metre, features=False)
    frame = sequence.frame(0)
    with pytest.raises(kg.Error, match="rigid"):
        mapper.add_frame(frame["depth"], frame["color"], np.eye(4) * 2)


def test_open3d_round_trip(cpu, synthetic):
    o3d = pytest.importorskip("open3d")
    mesh = mapped(cpu, synthetic).mesh()
    back = kg.Mesh.from_open3d(mesh.to_open3d())
    assert isinstance(mesh.to_open3d(), o3d.geometry.TriangleMesh)
    assert np.allclose(back.vertices, mesh.vertices)
    assert np.array_equal(back.triangles, mesh.triangles)
    assert np.array_equal(back.colors, mesh.colors)
    cloud = kg.Cloud(points=mesh.vertices, colors=mesh.colors)
    assert np.allclose(kg.Cloud.from_open3d(cloud.to_open3d()).points, cloud.points)


def cli(*args):
    import subprocess
    import sys

    subprocess.run([sys.executable, "-m", "kartograf._cli", *map(str, args)], check=True,
                   capture_output=True)


def read_mesh_ply(path):
    """Kartograf's binary mesh.ply: float x y z and uchar r g b per vertex, triangles."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    counts = {line.split()[1]: int(line.split()[2]) for line in header.splitlines()
              if line.startswith("element")}
    vertex = np.dtype([("xyz", "<f4", 3), ("rgb", "u1", 3)])
    face = np.dtype([("n", "u1"), ("v", "<i4", 3)])
    vertices = np.frombuffer(data, vertex, counts["vertex"], end)
    faces = np.frombuffer(data, face, counts["face"], end + vertex.itemsize * counts["vertex"])
    assert (faces["n"] == 3).all()
    return vertices["xyz"], vertices["rgb"], faces["v"]


def test_slam_and_the_mapper_give_the_clis_results(cpu, synthetic, tmp_path):
    from test_odometry import pose_rows, read_tum

    sequence = kg.open_sequence(synthetic)
    cli("slam", synthetic, "--out", tmp_path / "slam", "--no-map", "--backend", "cpu",
        "--no-progress")
    slam = kg.run_slam(cpu, sequence)
    assert np.allclose(read_tum(tmp_path / "slam" / "trajectory.txt"), pose_rows(slam.poses),
                       atol=2e-6)
    # The online mapper fed frame by frame (features on, as `kartograf map`'s default) against
    # the CLI's map of the whole sequence: the same SLAM, the same map frame.
    cli("map", synthetic, "--out", tmp_path / "map", "--backend", "cpu", "--no-progress")
    mapper = kg.Mapper(cpu, sequence.camera, sequence.depth_units_per_metre)
    for i in range(len(sequence)):
        frame = sequence.frame(i)
        mapper.add_frame(frame["depth"], frame["color"])
    result = mapper.finish()
    assert np.allclose(read_tum(tmp_path / "map" / "trajectory.txt"), pose_rows(result.poses),
                       atol=2e-6)
    # The mesh, the occupancy grid and the rooms `kartograf map` wrote.
    vertices, colors, triangles = read_mesh_ply(tmp_path / "map" / "mesh.ply")
    assert len(triangles) > 1000 and np.array_equal(triangles, result.mesh.triangles)
    assert np.allclose(vertices, result.mesh.vertices, atol=1e-5)
    assert np.array_equal(colors, result.mesh.colors)
    grid = kg.read_map(tmp_path / "map" / "occupancy.yaml")
    assert np.array_equal(grid.cells, result.occupancy.cells)
    assert np.allclose(grid.origin[:2], result.occupancy.origin[:2], atol=1e-6)
    rooms = kg.read_room_ground_truth(tmp_path / "map" / "rooms_labels.png")
    assert result.room_count >= 1 and np.array_equal(rooms, result.rooms)
