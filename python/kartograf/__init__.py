"""Kartograf: maps for mobile robots from RGB-D sequences, on the CPU, Vulkan or OpenCL.

The C++ library's main APIs with NumPy arrays: images and grids in, poses as 4 x 4 arrays out,
results as plain dataclasses (picklable: hand them to multiprocessing, joblib or Ray).

    import kartograf as kg
    context = kg.Context("auto")            # or "cpu", "vulkan", "opencl"
    sequence = kg.open_sequence("path/to/folder")
    run = kg.run_odometry(context, sequence)
    print(run.poses.shape, run.ate().rmse_m)

Every error of the library is a kartograf.Error with the library's message.
"""

import os as _os
from pathlib import Path as _Path

# The trained models travel inside the package: the library and the CLI look there.
_models = _Path(__file__).parent / "models"
if _models.is_dir():
    _os.environ.setdefault("KARTOGRAF_MODELS_DIR", str(_models))

from . import _kartograf  # noqa: E402
from ._kartograf import (  # noqa: E402
    Context,
    Error,
    PinholeIntrinsics,
    Sequence,
    backends,
    open_sequence,
)
from .mapping import Mapper, run_slam  # noqa: E402
from .odometry import Odometry, run_odometry  # noqa: E402
from .results import (  # noqa: E402
    Ate,
    ClockOffset,
    Cloud,
    DistanceField,
    FrameReport,
    Grid,
    MapResult,
    Mesh,
    OdometryRun,
    SEMANTIC_CLASSES,
    SemanticGrid,
    SlamRun,
    StepError,
    WorstSteps,
    ate,
    clock_offset,
    worst_steps,
)
from .scene import (  # noqa: E402
    Plane,
    PlaneSet,
    Room,
    RoomScores,
    RoomSegmentation,
    ViewLabels,
    backproject,
    evaluate_rooms,
    extract_planes,
    label_points,
    label_view,
    read_map,
    read_room_ground_truth,
    read_semantic_png,
    room_methods,
    segment_rooms,
)
from .synthetic import synthesize  # noqa: E402
from . import rosbag  # noqa: E402  (needs rosbags only when a bag is read)

__version__ = "0.1.0"

__all__ = [
    "Ate",
    "Cloud",
    "Context",
    "DistanceField",
    "Error",
    "FrameReport",
    "Grid",
    "MapResult",
    "Mapper",
    "Mesh",
    "Odometry",
    "OdometryRun",
    "PinholeIntrinsics",
    "Plane",
    "PlaneSet",
    "Room",
    "RoomScores",
    "RoomSegmentation",
    "SEMANTIC_CLASSES",
    "SemanticGrid",
    "Sequence",
    "SlamRun",
    "StepError",
    "ViewLabels",
    "WorstSteps",
    "ate",
    "ClockOffset",
    "clock_offset",
    "backends",
    "evaluate_rooms",
    "extract_planes",
    "backproject",
    "label_points",
    "label_view",
    "open_sequence",
    "read_map",
    "read_room_ground_truth",
    "read_semantic_png",
    "room_methods",
    "run_odometry",
    "rosbag",
    "run_slam",
    "segment_rooms",
    "worst_steps",
    "synthesize",
]
