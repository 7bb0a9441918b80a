"""Your own Crazyflie flight, from the uSD-card log to the figure: the steps of docs/crazyflie.md in Python.

    PYTHONPATH=build/python python3 examples/crazyflie_flight.py LOG ANCHORS.yaml OUT_DIR

LOG is the uSD-card deck's event log (logged with examples/usd/config.txt), ANCHORS.yaml the anchor positions
the Crazyflie client's Loco Positioning tab saves. Writes OUT_DIR/survey.txt, traj.csv, traj.tum and traj.png.
"""
import pathlib
import sys

import numpy as np

import uwbtdoa as u
from uwbtdoa import plots


def main(log: str, anchors_yaml: str, out_dir: str) -> int:
    out = pathlib.Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # 1. the log as a flight (`uwbtdoa import`)
    flight, report = u.import_usd_log(log, with_report=True)
    print("streams:", ", ".join(f"{s['stream']} {s['count']}" for s in report["sources"]))
    # 2. the survey from the client's anchor positions, checked against the flight (`uwbtdoa survey`)
    survey = u.read_cfclient_anchors(anchors_yaml)
    for warning in u.check_survey(survey, flight):
        print("warning:", warning)
    u.write_anchor_survey(survey, str(out / "survey.txt"))
    # 3. localize (`uwbtdoa localize`): position with its sigma; RMSE only when the log holds motion capture
    run = u.localize_flight(flight, survey)
    traj = run["trajectory"]
    u.write_trajectory_csv(traj, str(out / "traj.csv"))
    u.write_trajectory_tum(traj, str(out / "traj.tum"))  # for evo
    if run["metrics"] is not None:
        print(f"airborne RMSE {run['metrics']['airborne']['rmse_m']:.3f} m")
    else:
        print(f"no motion capture: no RMSE; median sigma {np.median(np.linalg.norm(traj['sigma_p'], axis=1)):.3f} m")
    # 4. the figure (`localize --plot`): x, y, z against time with the ±2σ band and the motion capture
    pose = flight.pose
    plots.position_vs_time(traj["t"], traj["p"], traj["sigma_p"], pose["t"], pose["p"], path=str(out / "traj.png"),
                           title=pathlib.Path(log).name)
    print("wrote", out / "traj.png")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(*sys.argv[1:]))
