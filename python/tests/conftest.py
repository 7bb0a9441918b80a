"""Shared pytest fixtures: real-data paths (skip with a clear message when the data are absent)."""
import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def data_dir() -> pathlib.Path:
    """$UWBTDOA_DATA, else ../shared/data next to the repository (as the CLI)."""
    return pathlib.Path(os.environ.get("UWBTDOA_DATA", REPO.parent / "shared" / "data"))


def pilot_flight(name: str) -> pathlib.Path:
    """util-pilot flight CSV by name, e.g. '0425-traj2'; skips the test when absent."""
    path = data_dir() / "real" / "util-pilot" / name.split("-")[0] / f"{name}.csv"
    if not path.is_file():
        pytest.skip(f"real data absent: {path} (set UWBTDOA_DATA to the shared data directory)")
    return path


def pilot_survey(day: str) -> pathlib.Path:
    path = data_dir() / "real" / "util-pilot" / "survey" / f"anchor_{day}_survey.txt"
    if not path.is_file():
        pytest.skip(f"real data absent: {path} (set UWBTDOA_DATA to the shared data directory)")
    return path
