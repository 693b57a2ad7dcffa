"""To and from Open3D geometry (needs open3d: pip install open3d)."""

from __future__ import annotations

import numpy as np

from .results import Cloud, Mesh


def _open3d():
    try:
        import open3d
    except ImportError as error:  # say what to install
        raise ImportError("Open3D interop needs open3d (pip install open3d)") from error
    return open3d


def cloud_to_open3d(cloud: Cloud):
    o3d = _open3d()
    out = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(cloud.points.astype(np.float64)))
    if len(cloud.colors):
        out.colors = o3d.utility.Vector3dVector(cloud.colors.astype(np.float64) / 255.0)
    return out


def cloud_from_open3d(cloud) -> Cloud:
    points = np.asarray(cloud.points, dtype=np.float32).reshape(-1, 3)
    colors = (np.round(np.asarray(cloud.colors) * 255).astype(np.uint8).reshape(-1, 3)
              if cloud.has_colors() else np.zeros((0, 3), np.uint8))
    return Cloud(points=points, colors=colors)


def mesh_to_open3d(mesh: Mesh):
    o3d = _open3d()
    out = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(mesh.vertices.astype(np.float64)),
                                    o3d.utility.Vector3iVector(mesh.triangles.astype(np.int32)))
    if len(mesh.colors):
        out.vertex_colors = o3d.utility.Vector3dVector(mesh.colors.astype(np.float64) / 255.0)
    return out


def mesh_from_open3d(mesh) -> Mesh:
    vertices = np.asarray(mesh.vertices, dtype=np.float32).reshape(-1, 3)
    triangles = np.asarray(mesh.triangles, dtype=np.int32).reshape(-1, 3)
    colors = (np.round(np.asarray(mesh.vertex_colors) * 255).astype(np.uint8).reshape(-1, 3)
              if mesh.has_vertex_colors() else np.zeros((0, 3), np.uint8))
    return Mesh(vertices=vertices, triangles=triangles, colors=colors)
