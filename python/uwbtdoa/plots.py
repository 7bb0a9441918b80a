"""Figures of the uwbtdoa evaluation report (paper Fig. 5, 6, 7 and a trajectory top view).

One function per figure. Each takes numpy arrays or plain dicts, returns the matplotlib ``Figure`` and,
when ``path`` is given, saves it as a PNG (dpi 130). Uses only numpy and matplotlib (Agg backend), so this
file also works without the compiled ``_uwbtdoa`` extension and can be run as a plain script.

Command line (called by ``uwbtdoa evaluate --out DIR``)::

    python3 -m uwbtdoa.plots report DIR          # with PYTHONPATH=build/python
    python3 build/python/uwbtdoa/plots.py report DIR

renders every figure whose data files exist into ``DIR/*.png`` and prints the path of each PNG written,
one per line, on stdout (notes on stderr). Exit status 0 on success, 2 on a missing/invalid results.json or
a malformed data file (the message names the file and, for CSV, the line).

Data-file contract (written by ``uwbtdoa evaluate``; everything in SI units, angles in radians)
-----------------------------------------------------------------------------------------------

``DIR/results.json`` (required) -- JSON array, one object per (kernel, number of inducing points)::

    {"kernel": "tdoa",              # kernel name (z1, z2, tdoa, or any other string)
     "inducing": 30,                # number of inducing points M (integer)
     "rmse_uncorrected_m": 0.226,   # airborne RMSE without correction: per test flight, then the mean over
                                    #   repeats and test flights (not pooled over samples)
     "rmse_corrected_m": 0.192,     # airborne RMSE with correction, same averaging
     "change_pct": -15.0,           # 100 * (rmse_corrected / rmse_uncorrected - 1) from the means above;
                                    #   NEGATIVE = the correction reduces the error (paper: -15.25 %)
     "change_pct_min": -17.0,       # minimum over repeats (of the per-repeat mean over test flights): best repeat
     "change_pct_max": -13.0}       # maximum over repeats
    Only kernel, inducing, change_pct, change_pct_min and change_pct_max are needed by Fig. 5; other keys
    are ignored. Files with the older "improvement_pct" (= -change_pct) keys are read as well.

``DIR/figdata/errors.csv`` (optional; Fig. 6) -- header line, then one row per evaluated sample::

    kernel,inducing,flight,corrected,t,error_m
    none,0,0425-traj2,0,12.34,0.231
    tdoa,30,0425-traj2,1,12.34,0.187

    kernel, inducing: the configuration of a corrected row; uncorrected rows use kernel "none", inducing 0
    flight: test-flight name; corrected: 0 (uncorrected filter) or 1 (with bias correction);
    t: time [s]; error_m: Euclidean position error |p_est - p_gt| [m].
    Rows are the samples that the RMSE is computed over (airborne only). Any number of configurations and
    repeats may be present (all rows of a configuration are pooled); decimate to <= ~50 Hz to keep the file
    small. Fig. 6 pools the samples of all test flights (its RMSE is not the table's per-flight mean); it is
    drawn for the configuration with the most negative change_pct in results.json that has
    corrected rows (``fig6_error_distribution.png``) and, per kernel, for that kernel's best M
    (``fig6_error_distribution_<kernel>.png``).

``DIR/figdata/fig7.json`` (optional; Fig. 7) -- one anchor pair (A, B) = (id_a, id_b)::

    {"kernel": "z1", "inducing": 30, "id_a": 0, "id_b": 1,
     "alpha_i_rad": [...],          # yaw angle of anchor A in the body frame per training sample (N)
     "alpha_j_rad": [...],          # yaw angle of anchor B in the body frame per training sample (N)
     "error_m": [...],              # measured TDoA error (paper eq. 6) per training sample [m] (N)
     "grid_alpha_i_rad": [...],     # grid axis for anchor A's yaw (n_i values, increasing)
     "grid_alpha_j_rad": [...],     # grid axis for anchor B's yaw (n_j values, increasing)
     "grid_mean_m": [[...], ...],   # n_j rows of n_i values: the model's mean averaged over the training
                                    #   samples in the cell centred at (grid_alpha_i[c], grid_alpha_j[r]) is
                                    #   grid_mean_m[r][c] (row = alpha_j, column = alpha_i) [m]; null = no data
     "inducing_alpha_i_rad": [...], # inducing points' yaw of anchor A (M)
     "inducing_alpha_j_rad": [...]} # inducing points' yaw of anchor B (M)
    kernel, inducing, id_a, id_b are used in titles only. NaN cells in grid_mean_m (JSON null) are blank.

``DIR/figdata/trajectories.csv`` (optional; top view) -- header, then one row per sample::

    flight,variant,t,x,y,z
    0425-traj2,ground_truth,0.00,1.50,0.00,0.01

    variant: "ground_truth", "uncorrected", or "corrected" (one corrected configuration, the writer's
    choice; a label such as "corrected tdoa M=30" is allowed: every variant starting with "corrected" is
    drawn as the corrected estimate). World frame [m]. One PNG per flight: ``trajectory_<flight>.png``.

``DIR/figdata/anchors.csv`` (optional; drawn in the top view) -- ``id,x,y,z`` with a header line [m].

``DIR/figdata/calibration.csv`` (optional; calibration figure) -- header, then one row per run and level::

    kernel,inducing,repeat,flight,level,coverage
    tdoa,30,0,0425-traj2,0.68,0.71

    level: nominal probability p of the central interval µ ± z_p σ of the predicted bias; coverage: observed
    fraction of TDoA errors inside it on that test flight (docs/math/gp.md P43).

``DIR/runs.csv`` (optional; per-flight bars) -- one row per configuration, repeat and test flight with at least
``kernel,inducing,repeat,flight,rmse_uncorrected_m,rmse_corrected_m`` and optionally ``coverage_1sigma,
coverage_2sigma,nlpd``; drawn for the best configuration, repeats averaged.

PNGs written: ``fig5_improvement.png``, ``fig6_error_distribution.png`` (+ per kernel),
``fig7_bias_vs_angles.png``, ``calibration.png``, ``per_flight.png``, ``trajectory_<flight>.png``.
"""
from __future__ import annotations

import csv
import json
import math
import os
import sys
from typing import Iterable, Mapping, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DPI = 130

_KERNEL_LABELS = {
    "z1": r"$k_{\mathrm{TDoA}_{z1}}$ (periodic, yaw angles)",
    "z2": r"$k_{\mathrm{TDoA}_{z2}}$ (Matérn 5/2, yaw angles)",
    "tdoa": r"$k_{\mathrm{TDoA}}$ (anchor positions in body frame)",
}


class ReportDataError(ValueError):
    """A report data file is missing a field or malformed; the message names the file (and line)."""


def kernel_label(name: str) -> str:
    """Display label for a kernel name (the paper's symbols for z1, z2, tdoa; the name otherwise)."""
    return _KERNEL_LABELS.get(str(name), str(name))


def _finish(fig, path: str | None):
    fig.tight_layout()
    if path:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        fig.savefig(path, dpi=DPI)
    return fig


def _change(r: Mapping, bound: str = "") -> float:
    """change_pct (negative = error reduced) of a results.json entry, or its min/max over repeats; entries of
    older files carry improvement_pct = −change_pct (their min/max swap)."""
    suffix = f"_{bound}" if bound else ""
    if "change_pct" in r:
        return float(r.get("change_pct" + suffix, r["change_pct"]))
    old = {"": "", "min": "_max", "max": "_min"}[bound]
    return -float(r.get("improvement_pct" + old, r["improvement_pct"]))


def _rmse(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else float("nan")


# --------------------------------------------------------------------------------------------- Fig. 5
def fig5_improvement(results: Sequence[Mapping], path: str | None = None, title: str | None = None):
    """Change of the airborne RMSE [%] against the number of inducing points, one line per kernel.

    ``results``: list of dicts with keys kernel, inducing, change_pct, change_pct_min, change_pct_max (the schema
    of results.json; older files with improvement_pct = −change_pct are accepted). The min/max spread over
    repeats is drawn as error bars and a light band. change_pct = 100 (corrected/uncorrected − 1): negative =
    the correction reduces the error.
    """
    if not results:
        raise ValueError("fig5_improvement: no results")
    by_kernel: dict[str, list[Mapping]] = {}
    for r in results:
        by_kernel.setdefault(str(r["kernel"]), []).append(r)
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    markers = "osD^vP*X"
    for k, (kernel, rows) in enumerate(by_kernel.items()):
        rows = sorted(rows, key=lambda r: int(r["inducing"]))
        m = np.array([int(r["inducing"]) for r in rows], dtype=float)
        y = np.array([_change(r) for r in rows])
        lo = np.array([_change(r, "min") for r in rows])
        hi = np.array([_change(r, "max") for r in rows])
        lo, hi = np.minimum(lo, y), np.maximum(hi, y)
        line = ax.errorbar(m, y, yerr=[y - lo, hi - y], marker=markers[k % len(markers)], capsize=4,
                           linewidth=1.8, markersize=6, label=kernel_label(kernel))
        ax.fill_between(m, lo, hi, color=line[0].get_color(), alpha=0.15, linewidth=0)
    ax.axhline(0.0, color="0.4", linewidth=0.8, linestyle="--")
    ax.set_xlabel("number of inducing points M")
    ax.set_ylabel("change of airborne RMSE [%] (negative = reduced)\n100·(RMSE_corrected / RMSE_uncorrected − 1)")
    ax.set_title(title or "Fig. 5: RMSE change vs. number of inducing points\n(mean over repeats and test flights; "
                 "bars and band: min/max over repeats)", fontsize=10.5)
    all_m = sorted({int(r["inducing"]) for r in results})
    ax.set_xticks(all_m)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=9)
    return _finish(fig, path)


# --------------------------------------------------------------------------------------------- Fig. 6
def fig6_error_distribution(err_uncorrected, err_corrected, path: str | None = None, title: str | None = None,
                            bins: int = 60):
    """Distribution of the localization error without and with correction: density histogram and CDF.

    ``err_uncorrected``, ``err_corrected``: 1-D arrays of Euclidean position errors [m]. Medians (dashed) and
    RMSEs (dotted) are marked and given in the legend.
    """
    eu = np.asarray(err_uncorrected, dtype=float).ravel()
    ec = np.asarray(err_corrected, dtype=float).ravel()
    eu, ec = eu[np.isfinite(eu)], ec[np.isfinite(ec)]
    if eu.size == 0 or ec.size == 0:
        raise ValueError("fig6_error_distribution: empty error array")
    fig, (ax_h, ax_c) = plt.subplots(1, 2, figsize=(11.0, 4.3))
    upper = float(np.percentile(np.concatenate([eu, ec]), 99.5))
    edges = np.linspace(0.0, upper * 1.02 if upper > 0 else 1.0, bins + 1)
    styles = [("uncorrected", eu, "tab:blue"), ("corrected", ec, "tab:orange")]
    bin_width = edges[1] - edges[0]
    for name, e, color in styles:
        med, rmse = float(np.median(e)), _rmse(e)
        beyond = int(np.sum(e > edges[-1]))  # the axis ends at the 99.5th percentile; those are counted, not drawn
        label = f"{name}: median {med:.3f} m, RMSE {rmse:.3f} m" + (f" ({beyond} beyond axis)" if beyond else "")
        w = np.full(e.size, 1.0 / (e.size * bin_width))  # density over ALL samples, not only those drawn
        ax_h.hist(e, bins=edges, weights=w, histtype="stepfilled", alpha=0.35, color=color, label=label)
        ax_h.hist(e, bins=edges, weights=w, histtype="step", color=color, linewidth=1.2)
        ax_h.axvline(med, color=color, linestyle="--", linewidth=1.4)
        ax_h.axvline(rmse, color=color, linestyle=":", linewidth=1.6)
        xs = np.sort(e)
        cdf = np.arange(1, xs.size + 1) / xs.size
        ax_c.plot(xs, cdf, color=color, linewidth=1.8, label=f"{name} (n={e.size})")
        ax_c.plot([med], [0.5], "o", color=color)
        ax_c.axvline(rmse, color=color, linestyle=":", linewidth=1.4)
    ax_h.set_ylim(0.0, ax_h.get_ylim()[1] * 1.3)  # head room for the legend
    ax_h.set_xlabel("localization error |p_est − p_gt| [m]")
    ax_h.set_ylabel("density [1/m]")
    ax_h.set_title("error density (dashed: median, dotted: RMSE)")
    ax_h.legend(fontsize=8.5, loc="upper right")
    ax_h.grid(True, alpha=0.3)
    ax_c.axhline(0.5, color="0.5", linewidth=0.8, linestyle="--")
    ax_c.set_xlim(0.0, edges[-1])
    ax_c.set_ylim(0.0, 1.0)
    ax_c.set_xlabel("localization error |p_est − p_gt| [m]")
    ax_c.set_ylabel("cumulative fraction of samples")
    ax_c.set_title("empirical CDF (dots: medians, dotted: RMSE)")
    ax_c.legend(fontsize=8.5, loc="lower right")
    ax_c.grid(True, alpha=0.3)
    fig.suptitle(title or "Fig. 6: localization error without / with bias correction")
    return _finish(fig, path)


# --------------------------------------------------------------------------------------------- Fig. 7
def fig7_bias_vs_angles(alpha_i, alpha_j, error, grid_alpha_i, grid_alpha_j, grid_mean, inducing_alpha,
                        path: str | None = None, title: str | None = None, pair: tuple[int, int] | None = None):
    """Measured TDoA error over the two anchor yaw angles (left) next to the model mean per grid cell (right;
    NaN cells, where there is no data, are blank).

    ``alpha_i``, ``alpha_j``, ``error``: per-sample yaw angles of anchors A and B in the body frame [rad] and
    the measured TDoA error [m]. ``grid_alpha_i`` (n_i), ``grid_alpha_j`` (n_j): grid axes [rad];
    ``grid_mean``: (n_j, n_i) GP mean [m] (row = alpha_j). ``inducing_alpha``: (M, 2) inducing points
    (alpha_i, alpha_j) [rad], drawn in red; the sample locations are shaded light grey on the right. Both panels
    share one colour scale; angles are shown in degrees.
    """
    ai, aj, err = (np.asarray(a, dtype=float).ravel() for a in (alpha_i, alpha_j, error))
    if not (ai.size == aj.size == err.size):
        raise ValueError(f"fig7_bias_vs_angles: alpha_i, alpha_j, error differ in length "
                         f"({ai.size}, {aj.size}, {err.size})")
    gi, gj = np.asarray(grid_alpha_i, dtype=float).ravel(), np.asarray(grid_alpha_j, dtype=float).ravel()
    gm = np.asarray(grid_mean, dtype=float)
    if gm.shape != (gj.size, gi.size):
        raise ValueError(f"fig7_bias_vs_angles: grid_mean has shape {gm.shape}, expected "
                         f"(len(grid_alpha_j), len(grid_alpha_i)) = ({gj.size}, {gi.size})")
    z = np.asarray(inducing_alpha, dtype=float).reshape(-1, 2) if np.size(inducing_alpha) else np.zeros((0, 2))
    vals = np.concatenate([err[np.isfinite(err)], gm[np.isfinite(gm)]])
    lim = float(np.percentile(np.abs(vals), 98)) if vals.size else 1.0
    lim = lim if lim > 0 else 1.0
    deg = 180.0 / math.pi
    fig, (ax_l, ax_r) = plt.subplots(1, 2, figsize=(11.5, 5.0), sharex=True, sharey=True, layout="constrained")
    order = np.argsort(np.abs(err))  # draw large errors on top
    ax_l.scatter(ai[order] * deg, aj[order] * deg, c=err[order], cmap="viridis", vmin=-lim, vmax=lim, s=6,
                 linewidths=0, rasterized=True)
    mesh = ax_r.pcolormesh(gi * deg, gj * deg, np.ma.masked_invalid(gm), cmap="viridis", vmin=-lim, vmax=lim,
                           shading="auto")
    if ai.size and np.isfinite(gm).all():  # a full grid: shade where the samples lie (elsewhere: extrapolation)
        ax_r.scatter(ai * deg, aj * deg, s=1.5, c="k", alpha=0.25, linewidths=0, rasterized=True, zorder=2)
        ax_r.plot([], [], "o", color="k", alpha=0.5, markersize=4, label="sample locations")  # legend entry
    if z.shape[0]:
        ax_r.scatter(z[:, 0] * deg, z[:, 1] * deg, s=28, c="red", edgecolors="white", linewidths=0.6,
                     label=f"inducing points (M={z.shape[0]})", zorder=3)
    if (ai.size and np.isfinite(gm).all()) or z.shape[0]:
        ax_r.legend(loc="upper right", fontsize=8.5, framealpha=0.85)
    a_name, b_name = ("A", "B") if pair is None else (str(pair[0]), str(pair[1]))
    for ax in (ax_l, ax_r):
        ax.set_xlabel(f"α_i: yaw of anchor {a_name} in body frame [deg]")
        ax.set_xlim(-180, 180)
        ax.set_ylim(-180, 180)
        ax.set_xticks(np.arange(-180, 181, 90))
        ax.set_yticks(np.arange(-180, 181, 90))
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.25)
    ax_l.set_ylabel(f"α_j: yaw of anchor {b_name} in body frame [deg]")
    ax_l.set_title(f"measured TDoA error (n={err.size})")
    ax_r.set_title("model mean at the samples, per cell (blank: no data)")
    cbar = fig.colorbar(mesh, ax=[ax_l, ax_r], shrink=0.95, pad=0.02)
    cbar.set_label("TDoA error / GP mean [m]")
    fig.suptitle(title or "Fig. 7: TDoA bias against the anchor yaw angles")
    if path:  # constrained layout (a colorbar spanning both panels); no tight_layout here
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        fig.savefig(path, dpi=DPI)
    return fig


# ------------------------------------------------------------------------------------- trajectory view
def trajectory_top_view(gt_xy, est_uncorrected_xy, est_corrected_xy=None, anchors_xy=None,
                        path: str | None = None, title: str | None = None, anchor_ids: Iterable | None = None):
    """Top view (x-y) of ground truth and the estimates without/with correction, anchors as triangles.

    Each trajectory: (N, 2) or (N, >=2) array in the world frame [m] (only x, y are used); None to omit.
    """
    fig, ax = plt.subplots(figsize=(6.8, 6.2))
    series = [("ground truth", gt_xy, "k", "-", 2.0), ("uncorrected", est_uncorrected_xy, "tab:blue", "-", 1.1),
              ("corrected", est_corrected_xy, "tab:orange", "-", 1.1)]
    for name, xy, color, ls, lw in series:
        if xy is None:
            continue
        xy = np.asarray(xy, dtype=float)
        if xy.size == 0:
            continue
        xy = xy.reshape(len(xy), -1)
        ax.plot(xy[:, 0], xy[:, 1], color=color, linestyle=ls, linewidth=lw, label=name,
                alpha=1.0 if name == "ground truth" else 0.85)
    if anchors_xy is not None and np.size(anchors_xy):
        an = np.asarray(anchors_xy, dtype=float).reshape(len(anchors_xy), -1)
        ax.plot(an[:, 0], an[:, 1], "^", color="tab:green", markersize=10, markeredgecolor="k", label="anchors")
        ids = list(anchor_ids) if anchor_ids is not None else list(range(len(an)))
        labels: dict[tuple[float, float], list[str]] = {}  # anchors stacked vertically share one label
        for (x, y), i in zip(an[:, :2], ids):
            labels.setdefault((round(float(x), 1), round(float(y), 1)), []).append(str(i))
        for (x, y), names in labels.items():
            ax.annotate("/".join(names), (x, y), textcoords="offset points", xytext=(7, 7), fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (world)")
    ax.set_ylabel("y [m] (world)")
    ax.set_title(title or "Trajectory, top view")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=9)
    return _finish(fig, path)


# ------------------------------------------------------------------------------------------ calibration
def calibration_curve(levels, coverage_by_label: Mapping[str, Sequence[float]], path: str | None = None,
                      title: str | None = None):
    """Coverage of the predicted bias intervals against their nominal probability (docs/math/gp.md P43).

    ``levels``: nominal probabilities p of the central intervals µ ± z_p σ (1-D, in (0, 1)).
    ``coverage_by_label``: {label: observed fractions at ``levels``}. The diagonal is perfect calibration;
    below it the predicted σ is too small (over-confident), above it too large. 1σ and 2σ are marked.
    """
    lv = np.asarray(levels, dtype=float).ravel()
    if lv.size == 0 or not coverage_by_label:
        raise ValueError("calibration_curve: no levels or no coverage")
    fig, ax = plt.subplots(figsize=(5.8, 5.4))
    ax.plot([0, 1], [0, 1], color="0.4", linestyle="--", linewidth=1.0, label="calibrated")
    for p, name in ((0.6827, "1σ"), (0.9545, "2σ")):
        ax.axvline(p, color="0.75", linewidth=0.8)
        ax.text(p, 0.02, f" {name}", color="0.4", fontsize=8.5)
    for label, cov in coverage_by_label.items():
        c = np.asarray(cov, dtype=float).ravel()
        if c.size != lv.size:
            raise ValueError(f"calibration_curve: '{label}' has {c.size} values for {lv.size} levels")
        ax.plot(lv, c, marker="o", markersize=3.5, linewidth=1.5, label=str(label))
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect("equal")
    ax.set_xlabel("nominal probability of the interval µ ± z·σ")
    ax.set_ylabel("observed fraction of TDoA errors inside")
    ax.set_title(title or "Calibration of the predicted bias on the test flights", fontsize=10.5)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8.5)
    return _finish(fig, path)


def per_flight_bars(flights: Sequence[str], rmse_uncorrected, rmse_corrected, coverage_1sigma=None,
                    coverage_2sigma=None, path: str | None = None, title: str | None = None):
    """Per test flight: airborne RMSE without / with correction (left) and, when given, the 1σ / 2σ coverage of
    the predicted bias (right, nominal 68.3 / 95.4 % as lines). Changes are labelled as 100 (corr/unc − 1) %:
    negative = the correction reduced the error."""
    names = [str(f) for f in flights]
    unc = np.asarray(rmse_uncorrected, dtype=float).ravel()
    cor = np.asarray(rmse_corrected, dtype=float).ravel()
    if not names or unc.size != len(names) or cor.size != len(names):
        raise ValueError("per_flight_bars: flights, rmse_uncorrected, rmse_corrected must have the same length > 0")
    with_cov = coverage_1sigma is not None and coverage_2sigma is not None
    fig, axes = plt.subplots(1, 2 if with_cov else 1, figsize=(11.0 if with_cov else 6.5, 4.3), squeeze=False)
    x = np.arange(len(names))
    ax = axes[0][0]
    ax.bar(x - 0.2, unc, 0.4, label="uncorrected", color="tab:blue")
    ax.bar(x + 0.2, cor, 0.4, label="corrected", color="tab:orange")
    for i in range(len(names)):
        change = 100.0 * (cor[i] / unc[i] - 1.0) if unc[i] > 0 else float("nan")
        ax.annotate(f"{change:+.1f} %", (x[i] + 0.2, cor[i]), textcoords="offset points", xytext=(0, 3),
                    ha="center", fontsize=8)
    ax.set_xticks(x, names, rotation=20, ha="right")
    ax.set_ylabel("airborne RMSE [m]")
    ax.set_title("localization error per flight (label: change, − = reduced)", fontsize=10)
    ax.legend(fontsize=8.5)
    ax.grid(True, axis="y", alpha=0.3)
    if with_cov:
        c1 = 100.0 * np.asarray(coverage_1sigma, dtype=float).ravel()
        c2 = 100.0 * np.asarray(coverage_2sigma, dtype=float).ravel()
        ax = axes[0][1]
        ax.bar(x - 0.2, c1, 0.4, label="within 1σ", color="tab:green")
        ax.bar(x + 0.2, c2, 0.4, label="within 2σ", color="tab:olive")
        ax.axhline(68.27, color="tab:green", linestyle="--", linewidth=1.0)
        ax.axhline(95.45, color="tab:olive", linestyle="--", linewidth=1.0)
        ax.set_ylim(0, 100)
        ax.set_xticks(x, names, rotation=20, ha="right")
        ax.set_ylabel("TDoA errors inside the predicted interval [%]")
        ax.set_title("coverage of the predicted bias (dashed: nominal)", fontsize=10)
        ax.legend(fontsize=8.5, loc="lower right")
        ax.grid(True, axis="y", alpha=0.3)
    fig.suptitle(title or "Per test flight")
    return _finish(fig, path)


# ------------------------------------------------------------------------------------ report data files
def position_vs_time(t, est_xyz, sigma_xyz, gt_t=None, gt_xyz=None, path: str | None = None,
                     title: str | None = None):
    """x, y, z of the estimate against time with its ±2σ band (the reported σ, docs/math/filter.md F23) and the
    ground truth when given: the figure to look at first."""
    t = np.asarray(t, float)
    est = np.asarray(est_xyz, float).reshape(-1, 3)
    sig = np.asarray(sigma_xyz, float).reshape(-1, 3)
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for k, (ax, name) in enumerate(zip(axes, "xyz")):
        ax.fill_between(t, est[:, k] - 2 * sig[:, k], est[:, k] + 2 * sig[:, k], color="tab:blue", alpha=0.2,
                        linewidth=0, label="±2σ")
        ax.plot(t, est[:, k], color="tab:blue", linewidth=1.0, label="estimate")
        if gt_t is not None and gt_xyz is not None and len(gt_t):
            g = np.asarray(gt_xyz, float).reshape(-1, 3)
            ax.plot(np.asarray(gt_t, float), g[:, k], color="black", linewidth=0.8, label="ground truth")
        ax.set_ylabel(f"{name} [m]")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", ncol=3, fontsize=8)
    axes[-1].set_xlabel("t [s]")
    if title:
        axes[0].set_title(title)
    return _finish(fig, path)


def load_trajectory_csv(path: str) -> dict[str, np.ndarray]:
    """A trajectory CSV written by `uwbtdoa localize --out` (t, x, y, z, …, std_x, std_y, std_z, …)."""
    cols = _read_csv(path, ["t", "x", "y", "z", "std_x", "std_y", "std_z"])
    return {k: _floats(path, cols, k) for k in ["t", "x", "y", "z", "std_x", "std_y", "std_z"]}


def load_flight_truth(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Ground-truth position (t_pose, pose_x/y/z) of a UTIL flight CSV (column-stacked streams: empty cells are
    skipped); empty arrays when the flight has no pose columns."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, [])
        if not {"t_pose", "pose_x", "pose_y", "pose_z"} <= set(header):
            return np.zeros(0), np.zeros((0, 3))
        i = [header.index(c) for c in ("t_pose", "pose_x", "pose_y", "pose_z")]
        rows = []
        for line_no, row in enumerate(reader, start=2):
            if len(row) <= max(i) or row[i[0]] == "":
                continue
            try:
                rows.append([float(row[j]) for j in i])
            except ValueError:
                raise ReportDataError(f"{path}:{line_no}: pose columns are not numbers") from None
    a = np.asarray(rows, float).reshape(-1, 4)
    return a[:, 0], a[:, 1:]


def _read_csv(path: str, required: Sequence[str]) -> dict[str, list[str]]:
    """Reads a CSV with a header into columns of strings; errors name file and line."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = [h.strip() for h in next(reader)]
        except StopIteration:
            raise ReportDataError(f"{path}:1: empty file, expected header {','.join(required)}") from None
        missing = [c for c in required if c not in header]
        if missing:
            raise ReportDataError(f"{path}:1: missing column(s) {', '.join(missing)} in header {','.join(header)}")
        cols: dict[str, list[str]] = {h: [] for h in header}
        for line_no, row in enumerate(reader, start=2):
            if not row or all(not c.strip() for c in row):
                continue
            if len(row) != len(header):
                raise ReportDataError(f"{path}:{line_no}: {len(row)} fields, header has {len(header)}")
            for h, v in zip(header, row):
                cols[h].append(v.strip())
    return cols


def _floats(path: str, cols: dict[str, list[str]], name: str) -> np.ndarray:
    try:
        return np.array(cols[name], dtype=float)
    except ValueError:
        for i, v in enumerate(cols[name]):
            try:
                float(v)
            except ValueError:
                raise ReportDataError(f"{path}:{i + 2} ({name}): not a number: '{v}'") from None
        raise


def load_results(path: str) -> list[dict]:
    """Reads and checks results.json (see the module docstring)."""
    try:
        with open(path) as f:
            data = json.load(f)
    except json.JSONDecodeError as e:
        raise ReportDataError(f"{path}:{e.lineno}:{e.colno}: invalid JSON: {e.msg}") from None
    if not isinstance(data, list):
        raise ReportDataError(f"{path}: expected a JSON array of result objects")
    for i, r in enumerate(data):
        for key in ("kernel", "inducing"):
            if not isinstance(r, dict) or key not in r:
                raise ReportDataError(f"{path}: entry {i} lacks key '{key}'")
        if "change_pct" not in r and "improvement_pct" not in r:
            raise ReportDataError(f"{path}: entry {i} lacks key 'change_pct'")
    return data


def load_errors(path: str) -> dict[str, np.ndarray]:
    """Reads figdata/errors.csv into arrays: kernel, flight (str), inducing, corrected (int), t, error_m."""
    cols = _read_csv(path, ["kernel", "inducing", "flight", "corrected", "t", "error_m"])
    return {"kernel": np.array(cols["kernel"], dtype=str), "flight": np.array(cols["flight"], dtype=str),
            "inducing": _floats(path, cols, "inducing").astype(int),
            "corrected": _floats(path, cols, "corrected").astype(int),
            "t": _floats(path, cols, "t"), "error_m": _floats(path, cols, "error_m")}


def load_trajectories(path: str) -> dict[str, dict[str, np.ndarray]]:
    """Reads figdata/trajectories.csv into {flight: {variant: (N, 4) array of t, x, y, z}}."""
    cols = _read_csv(path, ["flight", "variant", "t", "x", "y", "z"])
    data = np.column_stack([_floats(path, cols, c) for c in ("t", "x", "y", "z")]) if cols["t"] else np.zeros((0, 4))
    flights = np.array(cols["flight"], dtype=str)
    variants = np.array(cols["variant"], dtype=str)
    out: dict[str, dict[str, np.ndarray]] = {}
    for fl in dict.fromkeys(flights.tolist()):
        for va in dict.fromkeys(variants[flights == fl].tolist()):
            out.setdefault(fl, {})[va] = data[(flights == fl) & (variants == va)]
    return out


def load_anchors(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Reads figdata/anchors.csv: returns (ids, (N, 3) positions)."""
    cols = _read_csv(path, ["id", "x", "y", "z"])
    ids = _floats(path, cols, "id").astype(int)
    return ids, np.column_stack([_floats(path, cols, c) for c in ("x", "y", "z")]) if ids.size else np.zeros((0, 3))


def load_fig7(path: str) -> dict:
    """Reads figdata/fig7.json and checks its keys and shapes."""
    try:
        with open(path) as f:
            d = json.load(f)
    except json.JSONDecodeError as e:
        raise ReportDataError(f"{path}:{e.lineno}:{e.colno}: invalid JSON: {e.msg}") from None
    keys = ["alpha_i_rad", "alpha_j_rad", "error_m", "grid_alpha_i_rad", "grid_alpha_j_rad", "grid_mean_m",
            "inducing_alpha_i_rad", "inducing_alpha_j_rad"]
    missing = [k for k in keys if k not in d]
    if missing:
        raise ReportDataError(f"{path}: missing key(s) {', '.join(missing)}")

    def arr(k):
        return np.array([np.nan if v is None else v for v in d[k]], dtype=float)

    gm = np.array([[np.nan if v is None else v for v in row] for row in d["grid_mean_m"]], dtype=float)
    out = {k: arr(k) for k in keys if k != "grid_mean_m"}
    out["grid_mean_m"] = gm
    if gm.shape != (out["grid_alpha_j_rad"].size, out["grid_alpha_i_rad"].size):
        raise ReportDataError(f"{path}: grid_mean_m has shape {gm.shape}, expected (len(grid_alpha_j_rad), "
                              f"len(grid_alpha_i_rad)) = ({out['grid_alpha_j_rad'].size}, "
                              f"{out['grid_alpha_i_rad'].size})")
    for k in ("kernel", "inducing", "id_a", "id_b"):
        out[k] = d.get(k)
    return out


def load_calibration(path: str) -> dict[str, np.ndarray]:
    """Reads figdata/calibration.csv: kernel, flight (str), inducing, repeat (int), level, coverage."""
    cols = _read_csv(path, ["kernel", "inducing", "repeat", "flight", "level", "coverage"])
    return {"kernel": np.array(cols["kernel"], dtype=str), "flight": np.array(cols["flight"], dtype=str),
            "inducing": _floats(path, cols, "inducing").astype(int), "repeat": _floats(path, cols, "repeat").astype(int),
            "level": _floats(path, cols, "level"), "coverage": _floats(path, cols, "coverage")}


def load_runs(path: str) -> dict[str, np.ndarray]:
    """Reads runs.csv (one row per configuration, repeat and test flight)."""
    cols = _read_csv(path, ["kernel", "inducing", "repeat", "flight", "rmse_uncorrected_m", "rmse_corrected_m"])
    out = {"kernel": np.array(cols["kernel"], dtype=str), "flight": np.array(cols["flight"], dtype=str),
           "inducing": _floats(path, cols, "inducing").astype(int), "repeat": _floats(path, cols, "repeat").astype(int)}
    for c in ("rmse_uncorrected_m", "rmse_corrected_m", "coverage_1sigma", "coverage_2sigma", "nlpd"):
        if c in cols:
            out[c] = _floats(path, cols, c)
    return out


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in str(name))


def render_report(out_dir: str, log=sys.stderr) -> list[str]:
    """Renders every figure whose data files exist in ``out_dir`` (contract: module docstring).

    Returns the list of PNG paths written. Raises ReportDataError / OSError on missing or malformed input.
    """
    written: list[str] = []
    fig_dir = os.path.join(out_dir, "figdata")
    results_path = os.path.join(out_dir, "results.json")
    if not os.path.isfile(results_path):
        raise ReportDataError(f"{results_path}: not found (written by `uwbtdoa evaluate --out {out_dir}`)")
    results = load_results(results_path)

    def save(fig, name):
        p = os.path.join(out_dir, name)
        fig.savefig(p, dpi=DPI)
        plt.close(fig)
        written.append(p)

    if results:
        save(fig5_improvement(results), "fig5_improvement.png")

    errors_path = os.path.join(fig_dir, "errors.csv")
    if os.path.isfile(errors_path):
        e = load_errors(errors_path)
        unc = e["error_m"][e["corrected"] == 0]
        configs = {(k, m) for k, m, c in zip(e["kernel"], e["inducing"], e["corrected"]) if c == 1}
        ranked = sorted((_change(r), str(r["kernel"]), int(r["inducing"])) for r in results
                        if (str(r["kernel"]), int(r["inducing"])) in configs)
        if not ranked:  # no results entry matches: take the configurations in file order
            ranked = [(0.0, k, m) for k, m in sorted(configs)]
        if unc.size == 0 or not ranked:
            print(f"[plots] {errors_path}: needs both uncorrected (corrected=0) and corrected rows; "
                  "Fig. 6 skipped", file=log)
        else:
            best_per_kernel: dict[str, tuple[float, str, int]] = {}
            for item in ranked:
                best_per_kernel.setdefault(item[1], item)
            jobs = [("fig6_error_distribution.png", ranked[0])]
            if len(best_per_kernel) > 1:
                jobs += [(f"fig6_error_distribution_{_safe(k)}.png", v) for k, v in best_per_kernel.items()]
            for name, (_, kern, m) in jobs:
                sel = (e["corrected"] == 1) & (e["kernel"] == kern) & (e["inducing"] == m)
                t = (f"Fig. 6: localization error without / with correction ({kernel_label(kern)}, M={m}, "
                     f"{len(set(e['flight'][sel]))} test flight(s))")
                save(fig6_error_distribution(unc, e["error_m"][sel], title=t), name)
    else:
        print(f"[plots] {errors_path} absent: Fig. 6 skipped", file=log)

    fig7_path = os.path.join(fig_dir, "fig7.json")
    if os.path.isfile(fig7_path):
        d = load_fig7(fig7_path)
        pair = (d["id_a"], d["id_b"]) if d.get("id_a") is not None else None
        t = "Fig. 7: TDoA bias against the anchor yaw angles"
        if pair is not None:
            t += f", anchor pair ({pair[0]}, {pair[1]})"
        if d.get("kernel") is not None:
            t += f"; GP {kernel_label(d['kernel'])}"
            if d.get("inducing") is not None:
                t += f", M={d['inducing']}"
        z = np.column_stack([d["inducing_alpha_i_rad"], d["inducing_alpha_j_rad"]])
        save(fig7_bias_vs_angles(d["alpha_i_rad"], d["alpha_j_rad"], d["error_m"], d["grid_alpha_i_rad"],
                                 d["grid_alpha_j_rad"], d["grid_mean_m"], z, title=t, pair=pair),
             "fig7_bias_vs_angles.png")
    else:
        print(f"[plots] {fig7_path} absent: Fig. 7 skipped", file=log)

    best = None  # the best configuration of results.json: lowest corrected RMSE relative to uncorrected
    if results:
        r0 = min(results, key=_change)
        best = (str(r0["kernel"]), int(r0["inducing"]))

    cal_path = os.path.join(fig_dir, "calibration.csv")
    if os.path.isfile(cal_path):
        c = load_calibration(cal_path)
        levels = np.unique(c["level"])
        curves: dict[str, np.ndarray] = {}
        for kern, m in dict.fromkeys(zip(c["kernel"].tolist(), c["inducing"].tolist())):
            sel = (c["kernel"] == kern) & (c["inducing"] == m)
            curves[f"{kern} M={m}"] = np.array([np.mean(c["coverage"][sel & (c["level"] == lv)]) for lv in levels])
        if curves:
            save(calibration_curve(levels, curves, title="Calibration of the predicted bias on the test flights\n"
                                   "(mean over repeats and flights)"), "calibration.png")
    else:
        print(f"[plots] {cal_path} absent: calibration figure skipped", file=log)

    runs_path = os.path.join(out_dir, "runs.csv")
    if os.path.isfile(runs_path) and best is not None:
        r = load_runs(runs_path)
        sel = (r["kernel"] == best[0]) & (r["inducing"] == best[1])
        flights = list(dict.fromkeys(r["flight"][sel].tolist()))
        if flights:
            def mean_of(key):
                if key not in r:
                    return None
                return [float(np.mean(r[key][sel & (r["flight"] == f)])) for f in flights]
            save(per_flight_bars(flights, mean_of("rmse_uncorrected_m"), mean_of("rmse_corrected_m"),
                                 mean_of("coverage_1sigma"), mean_of("coverage_2sigma"),
                                 title=f"Per test flight, {best[0]} M={best[1]} (repeats averaged)"),
                 "per_flight.png")

    traj_path = os.path.join(fig_dir, "trajectories.csv")
    if os.path.isfile(traj_path):
        anchors_path = os.path.join(fig_dir, "anchors.csv")
        ids, anchors = load_anchors(anchors_path) if os.path.isfile(anchors_path) else (None, None)
        for flight, variants in load_trajectories(traj_path).items():
            gt = variants.get("ground_truth")
            unc = variants.get("uncorrected")
            cor_name = next((v for v in variants if v.startswith("corrected")), None)
            cor = variants.get(cor_name) if cor_name else None
            fig = trajectory_top_view(None if gt is None else gt[:, 1:3], None if unc is None else unc[:, 1:3],
                                      None if cor is None else cor[:, 1:3],
                                      None if anchors is None else anchors[:, :2],
                                      title=f"Top view, {flight}" + (f" ({cor_name})" if cor_name else ""),
                                      anchor_ids=ids)
            save(fig, f"trajectory_{_safe(flight)}.png")
    else:
        print(f"[plots] {traj_path} absent: trajectory view skipped", file=log)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: ``report DIR`` renders every figure of an evaluation report; ``position TRAJECTORY.csv
    FLIGHT.csv OUT.png`` draws position_vs_time (what ``uwbtdoa localize --plot`` runs). Returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) == 4 and argv[0] == "position":
        # python3 -m uwbtdoa.plots position TRAJECTORY.csv FLIGHT.csv OUT.png
        try:
            tr = load_trajectory_csv(argv[1])
            gt_t, gt = load_flight_truth(argv[2])
            position_vs_time(tr["t"], np.column_stack([tr["x"], tr["y"], tr["z"]]),
                             np.column_stack([tr["std_x"], tr["std_y"], tr["std_z"]]), gt_t, gt, path=argv[3],
                             title=os.path.basename(argv[2]))
        except (ReportDataError, OSError, KeyError, ValueError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
        print(argv[3])
        return 0
    if len(argv) != 2 or argv[0] != "report":
        print("usage: python3 -m uwbtdoa.plots report DIR | position TRAJECTORY.csv FLIGHT.csv OUT.png",
              file=sys.stderr)
        return 2
    try:
        for p in render_report(argv[1]):
            print(p)
    except (ReportDataError, OSError, KeyError, TypeError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
