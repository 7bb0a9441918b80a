"""examples/crazyflie_flight.py (the steps of docs/crazyflie.md) on a dev flight re-encoded as a uSD-card log with
the event types of the shipped examples/usd/config.txt, and anchor positions saved as the Crazyflie client does
(PyYAML's dump of {id: {x, y, z}})."""
import os
import subprocess
import sys

import numpy as np
import pytest

import uwbtdoa as u
from conftest import REPO, pilot_flight, pilot_survey

CONFIG = REPO / "examples" / "usd" / "config.txt"


def config_events():
    """The `on:EVENT` names of the shipped config.txt (comments stripped as the deck's firmware does)."""
    events = []
    for line in CONFIG.read_text().splitlines():
        line = line.split("#", 1)[0].replace(" ", "").replace("\t", "")
        if line.startswith("on:"):
            events.append(line[3:])
    return events


def test_the_python_example_runs_the_guide_on_a_dev_flight(tmp_path):
    yaml = pytest.importorskip("yaml")
    # GIVEN a dev flight with only the streams the shipped config logs, written as the deck's event log
    original = u.read_flight_csv(str(pilot_flight("0425-traj2")))
    streams = {k: v for k, v in original.streams().items() if k in ("tdoa", "acc", "gyro", "tof", "pose")}
    log = tmp_path / "log00"
    u.write_usd_log(u.Flight(**streams), str(log))
    _, report = u.import_usd_log(str(log), with_report=True)
    assert {s["event"] for s in report["sources"]} <= set(config_events())
    assert not [n for n in report["notes"] if "ignored" in n or "lacks" in n], report["notes"]
    # AND the anchors as the Crazyflie client saves them
    survey = u.read_anchor_survey(str(pilot_survey("0425")))
    anchors = {int(i): {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])}
               for i, p in zip(survey.ids, survey.positions)}
    (tmp_path / "anchors.yaml").write_text(yaml.dump(anchors))
    # WHEN the example runs
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, str(REPO / "examples" / "crazyflie_flight.py"), str(log),
                           str(tmp_path / "anchors.yaml"), str(out)],
                          env=dict(os.environ), capture_output=True, text=True, timeout=600)
    # THEN it localizes the flight as the CLI does, writes the survey, CSV, TUM and the figure
    assert proc.returncode == 0, proc.stderr
    assert "airborne RMSE" in proc.stdout, proc.stdout
    rmse = float(proc.stdout.split("airborne RMSE ")[1].split()[0])
    assert 0.1 < rmse < 0.4
    assert u.read_anchor_survey(str(out / "survey.txt")).ids.tolist() == survey.ids.tolist()
    traj = u.read_trajectory_csv(str(out / "traj.csv"))
    tum = np.loadtxt(out / "traj.tum")  # as evo reads it: '#' comments, 8 columns
    assert tum.shape == (len(traj["t"]), 8)
    assert np.max(np.abs(tum[:, 1:4] - traj["p"])) <= 1e-9
    assert (out / "traj.png").stat().st_size > 10_000
