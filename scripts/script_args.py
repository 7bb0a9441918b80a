"""Command-line options of the sweep scripts (scripts/sim_sweep.py, scripts/real_window_sweep.py): `--name VALUE`."""
import os
import sys


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
