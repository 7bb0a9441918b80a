"""uwbtdoa.plots: every figure renders from synthetic data files written to the documented contract."""
import csv
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from uwbtdoa import plots

KERNELS = ("z1", "z2", "tdoa")
INDUCING = (10, 30, 50, 100, 170)


def _write_report_dir(out, rng):
    """Writes DIR/results.json and DIR/figdata/* exactly as `uwbtdoa evaluate --out DIR` does."""
    fig = out / "figdata"
    fig.mkdir(parents=True)
    results = []
    for k, kernel in enumerate(KERNELS):
        for m in INDUCING:
            change = -(5.0 + 4.0 * k + 8.0 * math.log10(m))
            results.append({"kernel": kernel, "inducing": m, "rmse_uncorrected_m": 0.226,
                            "rmse_corrected_m": 0.226 * (1 + change / 100), "change_pct": change,
                            "change_pct_min": change - 1.0, "change_pct_max": change + 1.5})
    (out / "results.json").write_text(json.dumps(results, indent=1))

    with open(fig / "errors.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["kernel", "inducing", "flight", "corrected", "t", "error_m"])
        for flight in ("0425-traj2", "0425-traj3"):
            t = np.arange(0, 30, 0.05)
            for ti, e in zip(t, np.abs(rng.normal(0.2, 0.08, t.size))):
                w.writerow(["none", 0, flight, 0, f"{ti:.3f}", f"{e:.5f}"])
            for kernel, m in (("tdoa", 30), ("z1", 30), ("tdoa", 170)):
                for ti, e in zip(t, np.abs(rng.normal(0.16, 0.06, t.size))):
                    w.writerow([kernel, m, flight, 1, f"{ti:.3f}", f"{e:.5f}"])

    n = 3000
    ai, aj = rng.uniform(-math.pi, 0.5, n), rng.uniform(-0.5, math.pi, n)
    err = 0.1 * np.sin(ai) + 0.05 * np.cos(aj) + rng.normal(0, 0.03, n)
    gi, gj = np.linspace(-math.pi, math.pi, 61), np.linspace(-math.pi, math.pi, 41)
    gm = 0.1 * np.sin(gi)[None, :] + 0.05 * np.cos(gj)[:, None]
    gm_list = gm.tolist()
    gm_list[0][0] = None  # a blank cell (NaN) must be accepted
    (fig / "fig7.json").write_text(json.dumps({
        "kernel": "z1", "inducing": 30, "id_a": 0, "id_b": 1,
        "alpha_i_rad": ai.tolist(), "alpha_j_rad": aj.tolist(), "error_m": err.tolist(),
        "grid_alpha_i_rad": gi.tolist(), "grid_alpha_j_rad": gj.tolist(), "grid_mean_m": gm_list,
        "inducing_alpha_i_rad": rng.uniform(-3, 0.5, 30).tolist(),
        "inducing_alpha_j_rad": rng.uniform(-0.5, 3, 30).tolist()}))

    with open(fig / "trajectories.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["flight", "variant", "t", "x", "y", "z"])
        t = np.arange(0, 30, 0.1)
        for variant, noise in (("ground_truth", 0.0), ("uncorrected", 0.15), ("corrected tdoa M=30", 0.08)):
            x = 1.5 * np.cos(0.4 * t) + rng.normal(0, noise, t.size)
            y = 1.5 * np.sin(0.4 * t) + rng.normal(0, noise, t.size)
            for row in zip(t, x, y, np.full(t.size, 1.5)):
                w.writerow(["0425-traj2", variant] + [f"{v:.4f}" for v in row])
    with open(fig / "anchors.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "x", "y", "z"])
        for i, (x, y) in enumerate([(-4, -4), (4, -4), (4, 4), (-4, 4)] * 2):
            w.writerow([i, x, y, 0.2 if i < 4 else 2.6])
    return results


def _is_png(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_report_renders_every_figure_from_the_data_files(tmp_path):
    # GIVEN a report directory following the contract of docs/python.md
    _write_report_dir(tmp_path, np.random.default_rng(7))
    # WHEN the report command runs as the CLI calls it
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, "-m", "uwbtdoa.plots", "report", str(tmp_path)], env=env,
                          capture_output=True, text=True, timeout=120)
    # THEN it succeeds and writes every PNG, listing each on stdout
    assert proc.returncode == 0, proc.stderr
    expected = ["fig5_improvement.png", "fig6_error_distribution.png", "fig6_error_distribution_tdoa.png",
                "fig6_error_distribution_z1.png", "fig7_bias_vs_angles.png", "trajectory_0425-traj2.png"]
    listed = [os.path.basename(p) for p in proc.stdout.split()]
    for name in expected:
        assert name in listed
        assert _is_png(tmp_path / name), name
        assert (tmp_path / name).stat().st_size > 10_000, name


def test_report_without_optional_files_draws_fig5_only(tmp_path):
    (tmp_path / "results.json").write_text(json.dumps(
        [{"kernel": "tdoa", "inducing": 30, "change_pct": -15.2, "change_pct_min": -16.0, "change_pct_max": -14.0}]))
    written = plots.render_report(str(tmp_path))
    assert [os.path.basename(p) for p in written] == ["fig5_improvement.png"]


def test_change_is_read_with_one_sign_from_new_and_old_results():
    new = {"kernel": "tdoa", "inducing": 30, "change_pct": -15.2, "change_pct_min": -16.0, "change_pct_max": -14.0}
    old = {"kernel": "tdoa", "inducing": 30, "improvement_pct": 15.2, "improvement_pct_min": 14.0,
           "improvement_pct_max": 16.0}
    for r in (new, old):
        assert plots._change(r) == pytest.approx(-15.2)
        assert plots._change(r, "min") == pytest.approx(-16.0)
        assert plots._change(r, "max") == pytest.approx(-14.0)


def test_calibration_and_per_flight_figures_are_drawn_from_the_report_files(tmp_path):
    # GIVEN results.json, runs.csv and figdata/calibration.csv as `uwbtdoa evaluate` writes them
    (tmp_path / "figdata").mkdir()
    (tmp_path / "results.json").write_text(json.dumps(
        [{"kernel": "tdoa", "inducing": 30, "change_pct": -10.0}, {"kernel": "z1", "inducing": 10, "change_pct": 2.0}]))
    runs = ["kernel,inducing,repeat,flight,rmse_uncorrected_m,rmse_corrected_m,bias_rmse_before_m,bias_rmse_after_m,"
            "train_seconds,coverage_1sigma,coverage_2sigma,nlpd"]
    cal = ["kernel,inducing,repeat,flight,level,coverage"]
    levels = [0.05 * i for i in range(1, 20)] + [0.99]
    for kernel, m in (("tdoa", 30), ("z1", 10)):
        for flight in ("f1", "f2"):
            runs.append(f"{kernel},{m},0,{flight},0.25,0.22,0.27,0.23,1.0,0.70,0.93,0.1")
            cal += [f"{kernel},{m},0,{flight},{lv:.2f},{min(1.0, 0.9 * lv):.4f}" for lv in levels]
    (tmp_path / "runs.csv").write_text("\n".join(runs) + "\n")
    (tmp_path / "figdata" / "calibration.csv").write_text("\n".join(cal) + "\n")
    # WHEN the report is rendered
    written = [os.path.basename(p) for p in plots.render_report(str(tmp_path))]
    # THEN the calibration curve and the per-flight bars are PNGs
    for name in ("calibration.png", "per_flight.png"):
        assert name in written
        assert _is_png(tmp_path / name)


def test_calibration_curve_rejects_mismatched_lengths():
    with pytest.raises(ValueError, match="2 values for 3 levels"):
        plots.calibration_curve([0.1, 0.5, 0.9], {"a": [0.1, 0.5]})


def test_report_errors_name_the_file_and_line(tmp_path):
    _write_report_dir(tmp_path, np.random.default_rng(1))
    with open(tmp_path / "figdata" / "errors.csv", "a") as f:
        f.write("tdoa,30,0425-traj2,1,99.0,abc\n")
    with pytest.raises(plots.ReportDataError, match=r"errors\.csv:\d+ \(error_m\): not a number"):
        plots.render_report(str(tmp_path))
    rc = plots.main(["report", str(tmp_path)])
    assert rc == 2


def test_missing_results_json_is_an_error(tmp_path):
    with pytest.raises(plots.ReportDataError, match="results.json: not found"):
        plots.render_report(str(tmp_path))


def test_figure_functions_return_figures_and_save(tmp_path):
    rng = np.random.default_rng(3)
    f = plots.fig6_error_distribution(np.abs(rng.normal(0.2, 0.1, 500)), np.abs(rng.normal(0.15, 0.05, 500)),
                                      path=str(tmp_path / "f6.png"))
    assert len(f.axes) == 2 and _is_png(tmp_path / "f6.png")
    f = plots.trajectory_top_view(rng.normal(size=(50, 3)), rng.normal(size=(50, 2)), None,
                                  np.array([[0, 0], [1, 1]]), path=str(tmp_path / "tv.png"))
    assert _is_png(tmp_path / "tv.png")
    with pytest.raises(ValueError, match="grid_mean has shape"):
        plots.fig7_bias_vs_angles([0.0], [0.0], [0.1], [0, 1, 2], [0, 1], np.zeros((3, 2)), np.zeros((0, 2)))
