"""uwbtdoa: UWB TDoA localization of a Crazyflie with sparse-GP bias correction, from Python.

The compiled extension ``uwbtdoa._uwbtdoa`` (pybind11) holds the bindings of the C++ library; everything in it
is re-exported here. ``uwbtdoa.plots`` (figures of the evaluation report) needs only numpy and matplotlib and
works without the extension. Build: see docs/python.md (``PYTHONPATH=build/python``).
"""
try:
    from ._uwbtdoa import *  # noqa: F401,F403
    from ._uwbtdoa import __version__  # noqa: F401
    _native_error = None
except ModuleNotFoundError as _e:  # only the extension missing; other import errors propagate
    if _e.name != __name__ + "._uwbtdoa":
        raise
    _native_error = _e


_PURE_PYTHON_SUBMODULES = ("plots",)


def __getattr__(name):
    if name in _PURE_PYTHON_SUBMODULES:  # `from uwbtdoa import plots` must work without the extension
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    if _native_error is not None and not name.startswith("__"):
        raise ImportError(f"uwbtdoa.{name} needs the compiled extension uwbtdoa._uwbtdoa, which is not built "
                          f"(cmake --build build --target _uwbtdoa): {_native_error}")
    raise AttributeError(f"module 'uwbtdoa' has no attribute '{name}'")
