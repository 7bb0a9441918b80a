"""Command-line options of the scripts (scripts/sim_sweep.py, scripts/real_window_sweep.py: `--name VALUE`) and the
build and data they run on (scripts/ground_coverage.py, scripts/coverage_oracle.py)."""
import os
import subprocess
import sys
from pathlib import Path


def option(args, name, default, kind):
    """The value after `name` in `args`, converted by `kind` (int, float, str) and taken out of `args` with `name`;
    `default` when `name` is absent. A missing or unconvertible value ends the script with a message naming it."""
    if name not in args:
        return default
    script = os.path.basename(sys.argv[0])
    i = args.index(name)
    if i + 1 >= len(args):
        sys.exit(f"{script}: {name} needs a value")
    try:
        value = kind(args[i + 1])
    except ValueError:
        sys.exit(f"{script}: {name} {args[i + 1]}: not a {kind.__name__}")
    del args[i:i + 2]
    return value


def pilot_setup(build_dir):
    """The Python module and the CLI of `build_dir` and the util-pilot folder of the data directory (`uwbtdoa paths`):
    (uwbtdoa, cli, pilot). Ends the script with a message naming the folder when the flights are absent."""
    build = Path(build_dir).resolve()
    sys.path.insert(0, str(build / "python"))
    import uwbtdoa  # noqa: E402

    cli = str(build / "uwbtdoa")
    data = Path(subprocess.run([cli, "paths"], capture_output=True, text=True, check=True).stdout.strip())
    pilot = data / "real" / "util-pilot"
    if not (pilot / "survey").is_dir():
        sys.exit(f"{os.path.basename(sys.argv[0])}: no util-pilot flights under {pilot}")
    return uwbtdoa, cli, pilot
