"""The paper's experiment from Python (Vollmer et al., sec. III-D/IV) on a real util-pilot flight pair.

Train the TDoA-bias SVGP (k_TDoA kernel, eq. 9) on one flight, localize another flight without and with the
GP correction, print the airborne RMSEs and the improvement, and save Fig. 6, Fig. 7 and a top view.
    PYTHONPATH=build/python /usr/bin/python3 examples/paper_experiment.py [TRAIN[,TRAIN...] TEST [OUT_DIR]]
Data: $UWBTDOA_DATA, default ../shared/data next to the repository.
"""
import os
import pathlib
import sys

import numpy as np

import uwbtdoa as u
from uwbtdoa import plots

repo = pathlib.Path(__file__).resolve().parents[1]
pilot = pathlib.Path(os.environ.get("UWBTDOA_DATA", repo.parent / "shared" / "data")) / "real" / "util-pilot"
train_name, test_name = (sys.argv[1:3] if len(sys.argv) > 2 else ("0425-traj6,0425-traj7,0425-traj8,0425-traj9",
                                                                   "0425-traj2"))
out = pathlib.Path(sys.argv[3] if len(sys.argv) > 3 else "paper_experiment_out")
out.mkdir(exist_ok=True)
flight = lambda name: u.read_flight_csv(str(pilot / name[:4] / f"{name}.csv"), required=["tdoa", "pose"])
survey = u.read_anchor_survey(str(pilot / "survey" / f"anchor_{train_name[:4]}_survey.txt"))
train, test = [flight(n) for n in train_name.split(",")], flight(test_name)

# GP targets ε (eq. 6) from Vicon; GP inputs from the uncorrected filter, as the GP will see them at run time
data = u.build_bias_dataset(train, survey, inputs="estimate")
model, report = u.train_bias_model(data, "tdoa", num_inducing=100, seed=1)
print(f"trained on {train_name}: {report['n_train']} samples, held-out bias RMSE "
      f"{report['bias_rmse_before_m']:.3f} -> {report['bias_rmse_after_m']:.3f} m")

runs = {"uncorrected": u.localize_flight(test, survey), "corrected": u.localize_flight(test, survey, model)}
rmse = {k: r["metrics"]["airborne"]["rmse_m"] for k, r in runs.items()}
print(f"test {test_name}: airborne RMSE uncorrected {rmse['uncorrected']:.3f} m, corrected "
      f"{rmse['corrected']:.3f} m, improvement {100 * (1 - rmse['corrected'] / rmse['uncorrected']):.1f} %")

err = {k: r["metrics"]["samples"]["error_norm"][r["metrics"]["samples"]["airborne"]] for k, r in runs.items()}
plots.fig6_error_distribution(err["uncorrected"], err["corrected"], path=str(out / "fig6_error_distribution.png"))
gt = test.pose["p"]
plots.trajectory_top_view(gt, runs["uncorrected"]["trajectory"]["p"], runs["corrected"]["trajectory"]["p"],
                          survey.positions, path=str(out / "trajectory.png"), anchor_ids=survey.ids)

# Fig. 7: a z1 model (eq. 7) for the anchor pair (0, 1), its mean on a grid of the two anchor yaw angles.
a = data.arrays()
z1, _ = u.train_bias_model(data, "z1", num_inducing=30, seed=1)
pair = (a["id_a"] == 0) & (a["id_b"] == 1)
g = np.linspace(-np.pi, np.pi, 73)
gi, gj = np.meshgrid(g, g)                                          # rows: alpha_j, columns: alpha_i
mean = z1.predict({"id_a": np.zeros(gi.size, int), "id_b": np.ones(gi.size, int), "yaw_a": gi.ravel(),
                   "yaw_b": gj.ravel()})["mean"].reshape(gi.shape)
Z = z1.entries[0]["gp"].inducing
plots.fig7_bias_vs_angles(a["yaw_a"][pair], a["yaw_b"][pair], a["error"][pair], g, g, mean, Z,
                          path=str(out / "fig7_bias_vs_angles.png"), pair=(0, 1))
print(f"figures in {out}/")
