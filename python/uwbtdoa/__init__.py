"""uwbtdoa: UWB TDoA localization of a Crazyflie with sparse-GP bias correction, from Python.

Classes (numpy in and out, SI units; docs/python.md):
    Flight        a flight's sensor streams (tdoa, acc, gyro, tof, pose, ...) as dicts of numpy arrays
    AnchorSurvey  anchor positions by id (read_anchor_survey, read_cfclient_anchors)
    PoseTrack     the motion-capture pose track of a flight, interpolated at any time
    Estimator     the online filter: push IMU / TDoA / ToF events, read the estimate with its covariance
    Kernel        a GP kernel of the paper's bias model (periodic, matern52, rbf, ledergerber; sums, products)
    Svgp          a sparse variational GP (ELBO, prediction with variance)
    BiasDataset   GP training data from flights with ground truth (paper eq. 6)
    BiasModel     a trained bias model: predicts the TDoA bias, drives localize_flight's correction

Main functions:
    import_usd_log        a Crazyflie uSD-card event log as a Flight (`uwbtdoa import`)
    read_flight_csv       a UTIL flight CSV as a Flight; write_flight_csv, write_usd_log the inverse
    read_cfclient_anchors the Crazyflie client's anchor-position YAML as an AnchorSurvey (`uwbtdoa survey`)
    check_survey          the survey's checks as warnings with numbers
    localize_flight       runs the filter on a flight: trajectory with sigma, RMSE when there is ground truth
    write_trajectory_csv, write_trajectory_tum   the trajectory as CSV, or TUM for evo
    train_bias_model, run_evaluation             the paper's bias model and evaluation

The compiled extension ``uwbtdoa._uwbtdoa`` (pybind11) holds the bindings of the C++ library; everything in it
is re-exported here (``__all__``). ``uwbtdoa.plots`` (figures of the evaluation report) needs only numpy and
matplotlib and works without the extension. Build: see docs/python.md (``PYTHONPATH=build/python``).
Example of a whole flight, from the uSD log to the figure: examples/crazyflie_flight.py.
"""
try:
    from ._uwbtdoa import *  # noqa: F401,F403
    from ._uwbtdoa import __version__  # noqa: F401
    from . import _uwbtdoa as _native

    # the public names of the extension: `help(uwbtdoa)` lists these classes and functions
    __all__ = sorted(name for name in dir(_native) if not name.startswith("_"))
    _native_error = None
except ModuleNotFoundError as _e:  # only the extension missing; other import errors propagate
    if _e.name != __name__ + "._uwbtdoa":
        raise
    _native_error = _e
    __all__ = []


_PURE_PYTHON_SUBMODULES = ("plots",)


def __getattr__(name):
    if name in _PURE_PYTHON_SUBMODULES:  # `from uwbtdoa import plots` must work without the extension
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    if _native_error is not None and not name.startswith("__"):
        raise ImportError(f"uwbtdoa.{name} needs the compiled extension uwbtdoa._uwbtdoa, which is not built "
                          f"(cmake --build build --target _uwbtdoa): {_native_error}")
    raise AttributeError(f"module 'uwbtdoa' has no attribute '{name}'")
