"""Shared fixtures: a small synthetic sequence made once, the CPU context, the real data."""

import os
from pathlib import Path

import pytest

import kartograf as kg

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cpu():
    return kg.Context("cpu")


@pytest.fixture(scope="session")
def synthetic(tmp_path_factory):
    """30 hand-held frames of synthetic world 3 at 320 x 240 with the Kinect noise model."""
    folder = tmp_path_factory.mktemp("synthetic") / "handheld"
    kg.synthesize(folder, seed=3, frames=30, trajectory="handheld", width=320, height=240)
    return folder


@pytest.fixture(scope="session")
def data_dir():
    """../shared/data (KARTOGRAF_DATA_DIR overrides): the real sequences, never copied here."""
    folder = Path(os.environ.get("KARTOGRAF_DATA_DIR", REPO.parent / "shared" / "data"))
    if not (folder / "7scenes_redkitchen").is_dir():
        pytest.fail(f"the real data is missing: {folder} (KARTOGRAF_DATA_DIR)")
    return folder
