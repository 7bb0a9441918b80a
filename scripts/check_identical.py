#!/usr/bin/env python3
"""Runs `uwbtdoa protocol`, `localize` on every dev flight and `train` + `predict-bias`, writes every output into
OUT_DIR and, given a reference run directory, compares them byte for byte.

Usage: scripts/check_identical.py OUT_DIR [--reference REF_DIR] [--cli build/uwbtdoa] [--full-protocol]

Run it once with the binary built from the reference commit (OUT_DIR becomes the reference), then with the changed
binary and --reference. Measured times (wall and CPU seconds, real-time factors) differ from run to run: those keys
are removed from the JSON outputs (listed in OUT_DIR/normalized.txt) before they are written; every other byte
is compared (the run's own folder, where it appears in an output, reads OUT_DIR). Exit status 1 when a file
differs or is missing. Data: $UWBTDOA_DATA (default ../shared/data).
"""
import argparse
import json
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TIMING_KEY = re.compile(r"(^|_)(wall|cpu)_time_s$|^real_time_factor(_cpu)?$|(^|_)seconds$|^elapsed_s$")


def strip_timing(value, dropped, path=""):
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if TIMING_KEY.search(k):
                dropped.add(f"{path}/{k}" if path else k)
                continue
            out[k] = strip_timing(v, dropped, f"{path}/{k}" if path else k)
        return out
    if isinstance(value, list):
        return [strip_timing(v, dropped, path + "[]") for v in value]
    return value


def dev_flights(data):
    pilot = data / "real" / "util-pilot"
    out = []
    for i in list(range(1, 13)):
        out.append((f"0425-traj{i}", pilot / "0425" / f"0425-traj{i}.csv", pilot / "survey" / "anchor_0425_survey.txt"))
    for i in (1, 2, 11, 12):
        out.append((f"0426-traj{i}", pilot / "0426" / f"0426-traj{i}.csv", pilot / "survey" / "anchor_0426_survey.txt"))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--reference")
    ap.add_argument("--cli", default=str(ROOT / "build" / "uwbtdoa"))
    ap.add_argument("--full-protocol", action="store_true",
                    help="the whole protocol (default: real flights whole and cut, without the simulated scenarios)")
    a = ap.parse_args()
    data = Path(os.environ.get("UWBTDOA_DATA", ROOT.parent / "shared" / "data"))
    out = Path(a.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    dropped = set()

    def run(name, args, json_stdout=True):
        r = subprocess.run([a.cli] + [str(x) for x in args], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{name}: exit {r.returncode}\n{r.stderr[-2000:]}")
        text = r.stdout.replace(str(out), "OUT_DIR")  # the run's own folder differs between the two runs
        if json_stdout:
            text = json.dumps(strip_timing(json.loads(text), dropped), indent=1, sort_keys=True) + "\n"
        (out / f"{name}.json").write_text(text)
        print(f"ran {name}", file=sys.stderr)

    def normalize_file(path):
        j = json.loads(path.read_text().replace(str(out), "OUT_DIR"))
        path.write_text(json.dumps(strip_timing(j, dropped), indent=1, sort_keys=True) + "\n")

    flights = dev_flights(data)
    for name, csv, survey in flights:
        run(f"localize-{name}", ["localize", csv, "--anchors", survey, "--json", "--out", out / f"traj-{name}.csv"])
    protocol = ["protocol", "--json"] + ([] if a.full_protocol else ["--no-sim"])
    run("protocol", protocol)
    train = [f for n, f, _ in flights if n in ("0425-traj1", "0425-traj2", "0425-traj3")]
    survey_0425 = flights[0][2]
    run("train", ["train", *train, "--anchors", survey_0425, "--epochs", "3", "--inducing", "30", "--threads", "1",
                  "--out", out / "model.json", "--json", "--quiet"])
    normalize_file(out / "model.json")
    run("predict-bias", ["predict-bias", flights[3][1], "--anchors", survey_0425, "--model", out / "model.json",
                         "--out", out / "bias-0425-traj4.csv", "--json"])
    (out / "normalized.txt").write_text("".join(k + "\n" for k in sorted(dropped)))

    if not a.reference:
        print(f"wrote {len(list(out.iterdir()))} files to {out}")
        return 0
    ref = Path(a.reference)
    names = sorted({p.name for p in ref.iterdir()} | {p.name for p in out.iterdir()})
    bad = 0
    for n in names:
        x, y = ref / n, out / n
        if not x.exists() or not y.exists():
            print(f"MISSING {n}")
            bad += 1
        elif x.read_bytes() != y.read_bytes():
            print(f"DIFFERS {n}")
            bad += 1
        else:
            print(f"identical {n} ({y.stat().st_size} bytes)")
    print(f"{len(names) - bad} of {len(names)} files byte-identical" + ("" if bad == 0 else f"; {bad} differ"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
