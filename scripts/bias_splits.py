#!/usr/bin/env python3
"""The bias-correction splits of docs/math/filter.md F24 and F27: does a GP model of other flights help the filter on a
flight it was not trained on, with and without the range-bias states learned online (F27)?

Splits (the util-pilot TDoA2 flights and the six TDoA-only flights of util-final-extract, const4; a model is `uwbtdoa
train TRAIN... --kernel tdoa --inducing 30`, or the kernel and M given by --kernel=K --inducing=M):
  0426 1->1     a model of one 0426 flight on each other 0426 flight (12 pairs)
  0426 LOO      each 0426 flight with a model of the three others (4)
  0425->0426    a model of the 12 TDoA2 flights of 0425 on each 0426 flight (4)
  0425 1->1     models of 0425-traj1, 6 and 11 on each other 0425 flight (33)
  0425 LOO      each 0425 flight with a model of the 11 others (12)
  0426->0425    a model of the four 0426 flights on each 0425 flight (12)
  const4 1->1   a model of one const4 flight on each other flight of its trial (12)
  const4 LOO    each const4 flight with a model of the five others (6)
  const4 T->T   a model of the three flights of one trial on each flight of the other (6)
  0425->const4, 0426->const4   a model of another room (its session's TDoA2 flights) on each const4 flight (6 each)
  const4->0426, const4->0425   a model of the six const4 flights on each flight of another room (4, 12)
A const4 flight has no IMU and a position-only pose: its model's features are taken in the world frame, which is what the
filter reports without an IMU (eval/BiasDataset.h).
For each test flight `uwbtdoa localize FLIGHT --json` gives the airborne RMSE for four filters: without the range-bias
states (--range-bias-sigma-m 0 --tdoa-sigma-m 0.35), uncorrected and with the model ("offline"); with them (the
defaults), uncorrected ("online") and with the model ("offline + online"). Change = 100 (RMSE / reference - 1).

With --pairs, each train -> test pair is printed as well: its four RMSEs, and from the run with the model and the states
the model's mean scale at the end and its lowest (filter.md F24b, F24c), the flight's uncorrected bias level and the
level of the model's mean on it.

With --calibration, instead of the filters: `uwbtdoa predict-bias TEST --model M --json` scores the model's predictive
distribution of the bias (docs/math/gp.md P43) on each test flight; per split the 1σ and 2σ coverage (nominal 68.3 and
95.4 %; mean, lowest, highest over the pairs) and the mean NLPD. With --keep=DIR, each pair's `predict-bias` rows
(error, bias mean, predictive std per TDoA) are kept there as SPLIT__TRAIN__TEST.csv, and its JSON summary (levels,
calibration) as SPLIT__TRAIN__TEST.json, to rescore other predictive shapes.

With --with="FLAGS", every run with a model gets these localize flags too (e.g. --with="--bias-guard").
With --only=TEXT, only the splits whose label contains TEXT run (e.g. --only=const4).

Usage: scripts/bias_splits.py [BUILD_DIR] [--calibration | --pairs] [--with="FLAGS"] [--kernel=K] [--inducing=M] [--keep=DIR]
                              [--only=TEXT]   (data: $UWBTDOA_DATA or ../shared/data)
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile

OPTS = ("--with=", "--kernel=", "--inducing=", "--keep=", "--only=")
ARGS = [a for a in sys.argv[1:] if a not in ("--calibration", "--pairs") and not a.startswith(OPTS)]
# --with="FLAGS": more localize flags for every run with a model (e.g. --with="--bias-guard")
WITH = [f for a in sys.argv[1:] if a.startswith("--with=") for f in a[len("--with="):].split()]
# --kernel=K, --inducing=M: the model trained for every split (default the paper's tdoa kernel with M = 30)
KERNEL = next((a[len("--kernel="):] for a in sys.argv[1:] if a.startswith("--kernel=")), "tdoa")
INDUCING = next((a[len("--inducing="):] for a in sys.argv[1:] if a.startswith("--inducing=")), "30")
# --keep=DIR: with --calibration, the predict-bias rows of every pair
KEEP = next((a[len("--keep="):] for a in sys.argv[1:] if a.startswith("--keep=")), None)
# --only=TEXT: the splits whose label contains TEXT
ONLY = next((a[len("--only="):] for a in sys.argv[1:] if a.startswith("--only=")), "")
CALIBRATION = "--calibration" in sys.argv[1:]
PAIRS = "--pairs" in sys.argv[1:]
BUILD = ARGS[0] if ARGS else "build"
CLI = os.path.join(BUILD, "uwbtdoa")
DATA = os.environ.get("UWBTDOA_DATA", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                                                   "data"))
PILOT = os.path.join(DATA, "real", "util-pilot")
EXTRACT = os.path.join(DATA, "real", "util-final-extract")
PLAIN = ["--range-bias-sigma-m", "0", "--tdoa-sigma-m", "0.35"]
FLIGHTS = {"0425": [f"0425-traj{i}" for i in range(1, 13)], "0426": [f"0426-traj{i}" for i in (1, 2, 11, 12)],
           "const4": [f"const4-trial{t}-tdoa2-traj{i}" for t in (1, 2) for i in (1, 2, 3)]}


def session_of(name):
    return name.split("-")[0]


def path(name):
    if session_of(name) == "const4":
        return os.path.join(EXTRACT, name + ".csv")
    return os.path.join(PILOT, name[:4], name + ".csv")


def survey(session):
    if session == "const4":
        return os.path.join(EXTRACT, "survey", "anchor_const4_survey.txt")
    return os.path.join(PILOT, "survey", f"anchor_{session}_survey.txt")


def train(names, out):
    subprocess.run([CLI, "train", *map(path, names), "--anchors", survey(session_of(names[0])), "--kernel", KERNEL,
                    "--inducing", INDUCING, "--out", out], check=True, capture_output=True)


def localize(name, flags):
    cmd = [CLI, "localize", path(name), "--anchors", survey(session_of(name)), "--json", *flags]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def rmse(name, flags):
    return localize(name, flags)["rmse_airborne_m"]


def level_cell(run, key):
    return "–" if run.get(key) is None else f"{run[key]:.3f}"


def calibration(name, model, rows):
    cmd = [CLI, "predict-bias", path(name), "--anchors", survey(session_of(name)), "--model", model, "--json", "--out",
           rows]
    summary = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    if KEEP:  # the levels and the calibration beside the rows
        with open(rows[:-len(".csv")] + ".json", "w") as f:
            json.dump(summary, f, indent=1)
    return summary["calibration"]


def main_calibration():
    print(f"{'split':13s} {'n':>3s} | {'1σ coverage % mean [min, max]':>30s} | {'2σ coverage % mean [min, max]':>30s} | "
          f"{'NLPD':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        cache = {}
        for label, pairs in splits():
            c1, c2, nlpd = [], [], []
            for train_set, test in pairs:
                key = tuple(train_set)
                if key not in cache:
                    cache[key] = os.path.join(tmp, f"model{len(cache)}.json")
                    train(train_set, cache[key])
                rows = os.path.join(tmp, "predicted.csv")
                if KEEP:
                    os.makedirs(KEEP, exist_ok=True)
                    rows = os.path.join(KEEP, f"{label.replace(' ', '_')}__{'+'.join(train_set)}__{test}.csv")
                c = calibration(test, cache[key], rows)
                c1.append(100 * c["coverage_1sigma"])
                c2.append(100 * c["coverage_2sigma"])
                nlpd.append(c["nlpd"])

            def cell(v):
                return f"{statistics.mean(v):5.1f} [{min(v):5.1f}, {max(v):5.1f}]"
            print(f"{label:13s} {len(pairs):3d} | {cell(c1):>30s} | {cell(c2):>30s} | {statistics.mean(nlpd):+6.3f}",
                  flush=True)


def splits():
    s = []
    for session in ("0426", "0425"):
        f = FLIGHTS[session]
        models = f if session == "0426" else ["0425-traj1", "0425-traj6", "0425-traj11"]
        s.append((f"{session} 1->1", [([m], t) for m in models for t in f if t != m]))
        s.append((f"{session} LOO", [([o for o in f if o != t], t) for t in f]))
        other = "0425" if session == "0426" else "0426"
        s.append((f"{other}->{session}", [(FLIGHTS[other], t) for t in f]))
    f = FLIGHTS["const4"]

    def trial(name):
        return name.split("-")[1]
    s.append(("const4 1->1", [([m], t) for m in f for t in f if t != m and trial(t) == trial(m)]))
    s.append(("const4 LOO", [([o for o in f if o != t], t) for t in f]))
    s.append(("const4 T->T", [([o for o in f if trial(o) != trial(t)], t) for t in f]))
    for other in ("0425", "0426"):
        s.append((f"{other}->const4", [(FLIGHTS[other], t) for t in f]))
    for other in ("0426", "0425"):
        s.append((f"const4->{other}", [(f, t) for t in FLIGHTS[other]]))
    return [(label, pairs) for label, pairs in s if ONLY in label]


def main():
    cache, base = {}, {}
    print(f"{'split':13s} {'n':>3s} | {'offline vs plain':>22s} | {'online vs plain':>22s} | "
          f"{'off+on vs plain':>22s} | {'off+on vs online':>22s}")
    with tempfile.TemporaryDirectory() as tmp:
        for label, pairs in splits():
            ch = {k: [] for k in ("offline", "online", "both", "both_vs_online")}
            for train_set, test in pairs:
                key = tuple(train_set)
                if key not in cache:
                    cache[key] = os.path.join(tmp, f"model{len(cache)}.json")
                    train(train_set, cache[key])
                if test not in base:
                    base[test] = (rmse(test, PLAIN), rmse(test, []))
                plain, online = base[test]
                offline = rmse(test, PLAIN + ["--bias-model", cache[key], *WITH])
                run = localize(test, ["--bias-model", cache[key], *WITH])
                both = run["rmse_airborne_m"]
                if PAIRS:
                    trained = train_set[0] if len(train_set) == 1 else f"{len(train_set)} flights"
                    print(f"  {label:13s} {trained:>12s} -> {test:12s} plain {plain:.3f} online {online:.3f} "
                          f"offline {offline:.3f} both {both:.3f} ({100 * (both / plain - 1):+6.1f} %) scale "
                          f"{run['bias_model_mean_scale']:.2f} (lowest {run['min_bias_model_mean_scale']:.2f}) level "
                          f"{level_cell(run, 'raw_bias_level_m')} model mean level {level_cell(run, 'model_mean_level_m')}", flush=True)
                ch["offline"].append(100 * (offline / plain - 1))
                ch["online"].append(100 * (online / plain - 1))
                ch["both"].append(100 * (both / plain - 1))
                ch["both_vs_online"].append(100 * (both / online - 1))

            def cell(v):
                return f"{statistics.mean(v):+6.1f} {max(v):+6.1f} {sum(x > 1 for x in v):3d}"
            print(f"{label:13s} {len(pairs):3d} | {cell(ch['offline']):>22s} | {cell(ch['online']):>22s} | "
                  f"{cell(ch['both']):>22s} | {cell(ch['both_vs_online']):>22s}", flush=True)
    print("cells: mean change [%], worst change [%], flights above +1 %")


if __name__ == "__main__":
    main_calibration() if CALIBRATION else main()
