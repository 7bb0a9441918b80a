"""examples/paper_experiment.py runs on the real util-pilot flight pair and writes its figures."""
import os
import subprocess
import sys

from conftest import REPO, data_dir, pilot_flight


def test_paper_experiment_example_runs(tmp_path):
    pilot_flight("0425-traj6"), pilot_flight("0425-traj2")  # skip when the real data are absent
    env = dict(os.environ, UWBTDOA_DATA=str(data_dir()))
    proc = subprocess.run([sys.executable, str(REPO / "examples" / "paper_experiment.py"), "0425-traj6",
                           "0425-traj2", str(tmp_path)], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "airborne RMSE uncorrected" in proc.stdout and "improvement" in proc.stdout
    for name in ("fig6_error_distribution.png", "fig7_bias_vs_angles.png", "trajectory.png"):
        assert (tmp_path / name).stat().st_size > 10_000, name
