"""Contexts, backends, intrinsics and errors."""

import pickle

import pytest

import kartograf as kg


def test_the_cpu_backend_is_always_there(cpu):
    statuses = {b["backend"]: b for b in kg.backends()}
    assert set(statuses) == {"cpu", "vulkan", "opencl"}
    assert statuses["cpu"]["available"]
    assert cpu.backend == "cpu"
    assert cpu.device["backend"] == "cpu"


def test_every_backend_ci_has_makes_a_context():
    for status in kg.backends():
        if status["available"]:
            assert kg.Context(status["backend"]).backend == status["backend"]


def test_a_wrong_backend_is_an_error_with_the_librarys_message():
    with pytest.raises(kg.Error, match="nope"):
        kg.Context("nope")
    assert issubclass(kg.Error, RuntimeError)


def test_intrinsics_check_their_values_and_pickle():
    camera = kg.PinholeIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5)
    assert pickle.loads(pickle.dumps(camera)) == camera
    assert kg.PinholeIntrinsics.kinect_7scenes().fx == 585.0
    with pytest.raises(kg.Error, match="focal"):
        kg.PinholeIntrinsics(640, 480, -1.0, 525.0, 319.5, 239.5)
