"""feedid: short-time identification and prediction of machine-tool feed drives.

NumPy in, NumPy out, over the Rust library's identification pipeline (the
same computation as the command-line tool ``feedid identify``, not a call
of it)::

    import feedid
    rec = feedid.simulate("multisine", seed=1)          # the virtual rig
    run = feedid.identify(rec, method="auto")            # or (time, command, position)
    run.predicted, run.lower, run.upper                  # [m], NaN where not predicted
    run.summary["rms_error_m"]                           # summary.json's keys

Units: time in seconds, positions and commands in metres, rates in Hz,
windows, horizons and hops in samples.

Errors raise :class:`feedid.Error`: :class:`feedid.InputError` (also a
``ValueError``) for bad data or arguments, :class:`feedid.FileError` (also an
``OSError``) for files that cannot be read; the messages are the CLI's.
"""

from __future__ import annotations

import json
import os
import textwrap
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _feedid
from ._feedid import Recording

__all__ = [
    "Error",
    "InputError",
    "FileError",
    "Recording",
    "Identification",
    "Streamer",
    "OnlineCompensator",
    "read",
    "identify",
    "simulate",
    "model",
    "compensate",
    "learn",
    "structure",
    "simulate_structure",
    "fit_structure",
    "tune",
    "__version__",
]

__version__: str = _feedid.__version__

PathLike = Union[str, "os.PathLike[str]"]
Params = Union[None, PathLike, Mapping[str, Any]]


class Error(Exception):
    """Any error reported by feedid (the message is the command-line tool's)."""


class InputError(Error, ValueError):
    """Bad data or arguments: a missing column, NaN, non-monotone time, too
    few samples, an unknown method or option, parameters without a usable
    model."""


class FileError(Error, OSError):
    """A file that cannot be opened or read (the message names it)."""


def _params(params: Params) -> Dict[str, Any]:
    """Rig parameters as the native functions take them."""
    if params is None:
        return {}
    if isinstance(params, Mapping):
        return {"params_json": json.dumps(dict(params))}
    return {"params_path": os.fspath(params)}


def _array(x: Any, name: str) -> np.ndarray:
    """A 1-D contiguous float64 array: the input itself when it already is
    one (no copy), else NumPy's conversion."""
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise InputError(f"{name}: expected a 1-D array, got shape {a.shape}")
    return a


# The method options as the library describes them (``_feedid.method_options()``:
# key, Python keyword, type, range, help, the methods that have it and their
# defaults); ``order`` is a parameter of its own.
_OPTION_SPECS: List[Dict[str, Any]] = [
    s for s in _feedid.method_options() if s["key"] != "order"
]

# Accepted keywords of the method options → the native keyword: the
# library's key (``lambda``) and its Python keyword (``lambda_``).
_METHOD_OPTIONS: Dict[str, str] = {
    **{s["key"]: s["python"] for s in _OPTION_SPECS},
    **{s["python"]: s["python"] for s in _OPTION_SPECS},
}


def _options_doc(indent: str) -> str:
    """The method options' entries for a docstring, from the library's descriptions."""
    lines = []
    for s in _OPTION_SPECS:
        name = f"``{s['key']}``"
        if s["python"] != s["key"]:
            name += f" or ``{s['python']}``"
        kind = {"float": "float", "int": "int"}.get(s["kind"], "str")
        lines.append(
            textwrap.fill(
                f"{name} ({kind}): {s['help']}.",
                width=76,
                initial_indent=indent,
                subsequent_indent=indent + "    ",
                break_on_hyphens=False,
            )
        )
    return "\n".join(lines)


def _method_options(order: Any, options: Mapping[str, Any]) -> Dict[str, Any]:
    """``order`` and the method options as the native functions take them."""
    out: Dict[str, Any] = {}
    for key, value in options.items():
        if key not in _METHOD_OPTIONS:
            known = "; ".join(f"{s['key']} ({s['applies_to']})" for s in _OPTION_SPECS)
            raise TypeError(f"unknown option {key!r}; method options are: {known}")
        out[_METHOD_OPTIONS[key]] = value
    if order is not None:
        if isinstance(order, str):
            out["order"] = order
        else:
            out["order"] = ",".join(str(int(v)) for v in order)
    return out


def read(
    path: PathLike,
    time: Optional[Union[str, int]] = None,
    command: Optional[Union[str, int]] = None,
    position: Optional[Union[str, int]] = None,
    unit: str = "m",
    *,
    rate: Optional[float] = None,
    delimiter: Optional[str] = None,
    header: Optional[bool] = None,
    scale: Optional[float] = None,
    time_unit: str = "s",
    jitter_tol: float = 0.01,
    allow_gaps: bool = False,
) -> Recording:
    """Read a recording from a CSV/text file or a MATLAB MAT-file, as
    ``feedid identify`` reads it (same options, same defaults, same messages).

    Parameters
    ----------
    path : str or path-like
        The file (``.mat`` or MAT content: a MAT-file; anything else: text).
    time, command, position : str or int, optional
        Column (header name or 1-based index) or MAT variable of the time,
        the position command and the measured position. Defaults (text):
        ``time_s``, ``command_m``, ``position_m``; a MAT-file needs command
        and position named, and time or ``rate``.
    unit : str
        Unit of command and position in the file: ``m`` (default), ``mm``,
        ``um``, ``nm``; converted to metres.
    rate : float, optional
        Sampling rate [Hz] for a file without a time column (t_k = k / rate).
    delimiter : str, optional
        ``,`` ``;`` ``tab`` or ``space``; default: detected.
    header : bool, optional
        Whether the first row is a header; default: detected.
    scale : float, optional
        Metres per file unit (encoder counts and the like; overrides ``unit``).
    time_unit : str
        Unit of the time column: ``s`` (default), ``ms``, ``us``.
    jitter_tol : float
        Largest relative deviation of a sampling interval from the mean
        (default 0.01).
    allow_gaps : bool
        Accept dropped samples (an interval of a whole number of typical
        ones) as gaps between segments (``.gaps``), as ``feedid identify``
        does; :func:`identify` restarts its windows after each. Default
        False: such an interval is an error naming the missing samples.

    Returns
    -------
    Recording
        ``.time`` [s], ``.command`` [m], ``.position`` [m] as read-only
        float64 NumPy views (no copies), ``.rate_hz`` [Hz], ``.dt`` [s].

    Raises
    ------
    FileError
        The file cannot be opened or read.
    InputError
        A missing column, a cell that is not a number, NaN, time not
        increasing, too few samples.
    """
    return _feedid.read(
        os.fspath(path),
        time=None if time is None else str(time),
        command=None if command is None else str(command),
        position=None if position is None else str(position),
        rate=rate,
        delimiter=delimiter,
        header=header,
        unit=unit,
        scale=scale,
        time_unit=time_unit,
        jitter_tol=jitter_tol,
        allow_gaps=allow_gaps,
    )


class Identification:
    """The result of :func:`identify`.

    Attributes
    ----------
    time, command, position : numpy.ndarray
        The recording identified: time [s], command [m], measured position [m].
    predicted : numpy.ndarray
        Predicted position per sample [m]; NaN where nothing was predicted
        (before the first window's horizon, failed or withheld windows).
    lower, upper : numpy.ndarray
        Prediction interval per sample [m] (probability ``interval``, 95 %
        by default); NaN where nothing was predicted.
    coefficients : numpy.ndarray
        Per-window coefficients, shape (windows, len(coefficient_names)).
    coefficient_names : list of str
        The coefficients' names (the columns of coefficients.csv).
    window_start, window_end : numpy.ndarray
        Sample range ``[start, end)`` of each window (int64).
    recording : Recording
        The recording identified (with arrays given to :func:`identify`, a
        checked copy made on first use).
    window_outcome : list of str
        What became of each window (``converged``, ``fallback``, ``failed``, ...).
    simulated : numpy.ndarray
        The nominal physical model driven by the command [m] (predictions.csv's
        ``simulated_m``).
    summary : dict
        The run's summary with the keys of ``feedid identify --summary``'s
        summary.json (``rms_error_m``, ``coverage_percent``, ...).
    model : dict or None
        The method's global model (as ``--model-out`` writes it), if fitted;
        usable by :func:`compensate`.
    warnings : list of str
        What the user should know about this run (also in the summary).
    """

    def __init__(
        self,
        recording: Optional[Recording],
        parts: Dict[str, Any],
        data: Optional[Dict[str, Any]] = None,
        jitter_tol: float = 0.01,
    ):
        self._recording = recording
        self._jitter_tol = jitter_tol
        src: Any = recording if recording is not None else data
        get = (lambda k: getattr(src, k)) if recording is not None else (lambda k: src[k])
        self.time: np.ndarray = get("time")
        self.command: np.ndarray = get("command")
        self.position: np.ndarray = get("position")
        self.predicted: np.ndarray = parts["predicted"]
        self.lower: np.ndarray = parts["lower"]
        self.upper: np.ndarray = parts["upper"]
        self.coefficients: np.ndarray = parts["coefficients"]
        self.coefficient_names: List[str] = list(parts["coefficient_names"])
        self.window_start: np.ndarray = parts["window_start"]
        self.window_end: np.ndarray = parts["window_end"]
        self.window_outcome: List[str] = list(parts["window_outcome"])
        self.simulated: Optional[np.ndarray] = parts["simulated"]
        self.summary: Dict[str, Any] = json.loads(parts["summary_json"])
        model_json = parts["model_json"]
        self.model: Optional[Dict[str, Any]] = (
            None if model_json is None else json.loads(model_json)
        )
        self.warnings: List[str] = list(parts["warnings"])

    @property
    def recording(self) -> Recording:
        """The recording identified (built on first use from the arrays
        ``identify`` was given, a checked copy of them)."""
        if self._recording is None:
            self._recording = Recording(
                self.time,
                self.command,
                self.position,
                jitter_tol=self._jitter_tol,
                allow_gaps=True,
            )
        return self._recording

    def __repr__(self) -> str:
        s = self.summary
        rms = s.get("rms_error_m")
        return (
            f"Identification(method={s['method']!r}, samples={s['samples']}, "
            f"windows={s['windows']}, coverage={s['coverage_percent']:.1f} %, "
            f"rms_error_m={'none' if rms is None else format(rms, '.3e')})"
        )

    def to_pandas(self) -> "Any":
        """The per-sample table as a pandas DataFrame: ``time_s``,
        ``command_m``, ``measured_m``, ``predicted_m``, ``lower_m``,
        ``upper_m``, ``simulated_m`` (predictions.csv's columns plus the
        interval; NaN where empty). Needs pandas."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_pandas() needs pandas: pip install pandas") from e
        cols = {
            "time_s": self.time,
            "command_m": self.command,
            "measured_m": self.position,
            "predicted_m": self.predicted,
            "lower_m": self.lower,
            "upper_m": self.upper,
        }
        if self.simulated is not None:
            cols["simulated_m"] = self.simulated
        return pd.DataFrame(cols)

    def coefficients_to_pandas(self) -> "Any":
        """The per-window coefficients as a pandas DataFrame (coefficients.csv's
        content): ``start_s``, ``end_s``, ``outcome`` and one column per name."""
        import pandas as pd

        t = self.time
        df = pd.DataFrame(self.coefficients, columns=self.coefficient_names)
        df.insert(0, "start_s", t[self.window_start] if len(t) else [])
        df.insert(1, "end_s", t[np.maximum(self.window_end - 1, 0)] if len(t) else [])
        df.insert(2, "outcome", self.window_outcome)
        return df


def identify(
    time: Union[Recording, Any],
    command: Any = None,
    position: Any = None,
    method: str = "auto",
    window: Optional[int] = None,
    horizon: int = 10,
    order: Optional[Union[str, Sequence[int]]] = None,
    *,
    hop: Optional[int] = None,
    params: Params = None,
    allow_unstable: bool = False,
    jitter_tol: float = 0.01,
    nominal: bool = True,
    global_model: bool = True,
    residuals: bool = True,
    interval: float = 95.0,
    runaway: Optional[float] = 1.5,
    **options: Any,
) -> Identification:
    """Identify a recording in short sliding windows and predict the next
    samples, as ``feedid identify`` does (same defaults, same numbers).

    Call as ``identify(recording, ...)`` or ``identify(time, command, position, ...)``.

    Parameters
    ----------
    time : Recording or array_like
        A :class:`Recording`, or the sample times [s] (strictly increasing,
        uniformly sampled within ``jitter_tol``). Dropped samples (an
        interval of a whole number of typical ones) are gaps: the windows
        restart after each, as ``feedid identify`` does (``summary["gaps"]``).
    command, position : array_like
        Position command [m] and measured position [m] (with ``time`` as
        arrays). Contiguous float64 arrays are checked and read in place,
        not copied (others are converted first); do not change them while
        ``identify`` runs.
    method : str
        {method_names}
    window : int, optional
        Window length W [samples]; default: the method's own (as the CLI:
        {method_windows}).
    horizon : int
        Prediction horizon H [samples]; default 10 (2 ms at 5 kHz).
    order : str or (na, nb, nk), optional
        ARX orders of arx, rls, auto (``"8,8,1"`` or ``(8, 8, 1)``), or
        ``"auto"`` to choose them from the recording by BIC.
    hop : int, optional
        Shift between windows [samples]; default the horizon.
    params : path or dict, optional
        Rig parameters (a rig.toml, or a dict of its sections) of the nominal
        model simulated beside the predictions; default the built-in rig.
    allow_unstable : bool
        Use an unstable nominal model anyway (default False: refused).
    jitter_tol : float
        Sampling jitter tolerance of arrays (relative; default 0.01).
    nominal, global_model, residuals : bool
        What ``feedid identify`` computes beside the sliding predictions
        (default True, all three): the nominal model's simulation (the
        summary's ``sim_rms_error_m``, ``sim_max_abs_error_m``,
        ``nominal_fit_percent`` and ``nominal_rig`` — ``"built-in"``, the
        rig.toml's path or ``"dict"`` —, ``simulated``), the method's global model
        and its free-run fit (``global_model``, ``global_model_samples``,
        ``sim_fit_percent``, ``model``), the residual analysis
        (``residuals``). On long recordings they cost several times the
        sliding identification (python/README.md): False leaves them out
        and their keys out of the summary.
    interval : float
        Probability of the prediction intervals ``lower``/``upper`` [%],
        in (0, 100); default 95 (``--interval``). The summary has their
        median width (``interval_median_width_m``) and their coverage per
        command regime (``interval_by_regime``).
    runaway : float or None
        A predicted sample farther from the last measured position than
        this many times the motion the axis has shown in as many samples is
        cut back, its interval widened (``--runaway``; default 1.5; the
        summary counts ``runaway_windows``, ``runaway_samples``); None keeps
        every prediction as the method made it.
    **options
        Method options (each given to a method that does not have it is an
        :class:`InputError`):

{method_options}

    Returns
    -------
    Identification
        ``predicted``, ``lower``, ``upper`` [m] (NaN where nothing was
        predicted), ``coefficients`` (windows × names), ``summary`` (dict,
        summary.json's keys), ``to_pandas()``.

    The identification runs with the GIL released: threads identifying
    several recordings run in parallel.
    """
    if isinstance(time, Recording):
        if command is not None or position is not None:
            raise TypeError("identify(recording, ...) takes no command or position arrays")
        rec: Optional[Recording] = time
        data: Dict[str, Any] = {"recording": time}
    else:
        if command is None or position is None:
            raise TypeError("identify(time, command, position, ...) needs all three arrays")
        rec = None
        data = {
            "time": _array(time, "time"),
            "command": _array(command, "command"),
            "position": _array(position, "position"),
            "jitter_tol": jitter_tol,
        }
    parts = _feedid.identify(
        **data,
        method=method,
        window=window,
        horizon=horizon,
        hop=hop,
        allow_unstable=allow_unstable,
        nominal=nominal,
        global_model=global_model,
        residuals=residuals,
        interval=interval,
        runaway=runaway,
        **_params(params),
        **_method_options(order, options),
    )
    return Identification(rec, parts, data, jitter_tol)


class Streamer:
    """Streaming identification: push one line ``(t, u, y)`` at a time and
    get each window's prediction of the next ``horizon`` samples as soon as
    it is due (``feedid stream`` as a library call).

    Parameters
    ----------
    rate : float, optional
        Sampling rate [Hz]; with it the intervals are exact (a skipped line
        is a gap). Default: the running mean interval.
    method : str
        {method_names}
    window : int, optional
        Window length W [samples]; default the method's own ({method_windows}).
    horizon : int
        Prediction horizon H [samples]; default 10.
    hop : int, optional
        Shift between windows [samples]; default the horizon.
    command_lead : int
        The command on each pushed line belongs to the sample this many
        lines later (a CNC interpolator runs ahead); default 0.
    extrapolate : str, optional
        How the command over a horizon not yet received is filled: ``hold``,
        ``velocity``, ``acceleration`` (default) or ``wait`` (each window
        waits for its command: the predictions then equal :func:`identify`'s).
    jitter_tol : float
        Relative interval deviation reported as irregular (default 0.01).
    order : str or (na, nb, nk), optional
        ARX orders (``"auto"`` is refused: a stream needs them given).
    interval : float
        Probability of the prediction intervals [%]; default 95.
    runaway : float or None
        The runaway cut as for :func:`identify` (default 1.5; None: off).
    **options
        Method options as for :func:`identify`:

{method_options}

    ``push`` and ``finish`` return lists of ``(time [s], predicted [m],
    lower [m], upper [m])``.
    """

    def __init__(
        self,
        rate: Optional[float] = None,
        method: str = "auto",
        window: Optional[int] = None,
        horizon: int = 10,
        command_lead: int = 0,
        *,
        hop: Optional[int] = None,
        extrapolate: Optional[str] = None,
        jitter_tol: float = 0.01,
        order: Optional[Union[str, Sequence[int]]] = None,
        interval: float = 95.0,
        runaway: Optional[float] = 1.5,
        **options: Any,
    ):
        self._s = _feedid.Streamer(
            interval=interval,
            runaway=runaway,
            rate=rate,
            method=method,
            window=window,
            horizon=horizon,
            hop=hop,
            command_lead=command_lead,
            extrapolate=extrapolate,
            jitter_tol=jitter_tol,
            **_method_options(order, options),
        )

    def push(self, t: float, u: float, y: float) -> List[Tuple[float, float, float, float]]:
        """Push one line: time ``t`` [s], command ``u`` [m] (of the sample
        ``command_lead`` lines later), measured position ``y`` [m]. Returns
        the predictions that became due. A time not after the previous one
        raises :class:`InputError` (nothing is stored)."""
        return self._s.push(float(t), float(u), float(y))

    def push_many(
        self, t: Any, u: Any, y: Any
    ) -> List[Tuple[float, float, float, float]]:
        """Push many lines at once (equal-length arrays; GIL released);
        returns the predictions that became due, in order."""
        return self._s.push_many(_array(t, "t"), _array(u, "u"), _array(y, "y"))

    def finish(self) -> List[Tuple[float, float, float, float]]:
        """End of the input: the predictions still due."""
        return self._s.finish()

    @property
    def stats(self) -> Dict[str, Any]:
        """Counters and scores so far: lines, samples, windows,
        predicted_ahead, predicted_late, gaps, rms_error_m (None before any
        sample was scored), hold_rms_error_m (the hold baseline on the same
        samples), interval_coverage_percent, interval_by_regime (per command
        regime: samples, coverage_percent), runaway_windows,
        runaway_samples, outliers, ..."""
        return self._s.stats

    @property
    def dt(self) -> Optional[float]:
        """The sampling interval in use [s] (None before two samples)."""
        return self._s.dt


def _fill_doc(doc: Optional[str]) -> str:
    """A docstring with the library's methods and options filled in."""
    methods = _feedid.methods()
    names = ", ".join(
        f"``{m['name']}``" + (" (default)" if i == 0 else "") for i, m in enumerate(methods)
    )
    windows = ", ".join(f"{m['name']} {m['default_window']}" for m in methods)
    return (
        (doc or "")
        .replace("{method_names}", names + ".")
        .replace("{method_windows}", windows)
        .replace("{method_options}", _options_doc(" " * 8))
    )


identify.__doc__ = _fill_doc(identify.__doc__)
Streamer.__doc__ = _fill_doc(Streamer.__doc__)


class OnlineCompensator:
    """Online compensation: push one line ``(t, u, y)`` at a time and get
    the corrected command of the coming sample before the drive needs it
    (``feedid stream --compensate`` as a library call).

    The model is the axis's following error as velocity and acceleration
    feed-forward time constants, identified while it runs (recursive least
    squares with forgetting); the command is the desired position plus
    their correction, switched off (the plain command) while the model is
    implausible, within the velocity and acceleration limits.

    Parameters
    ----------
    rate : float
        Sampling rate [Hz].
    command_lead : int
        Online: the command on each pushed line is the desired position of
        the sample this many lines later (at least 3).
    replay : bool
        The lines are a recorded run (command and position of the same
        sample; the positions answer the recording's own command): the
        commands returned are what the compensation would have sent.
        Default False (online: the positions answer the commands returned).
    max_velocity, max_acceleration : float
        Command limits [m/s], [m/s²]; defaults 1.0 and 30.0.
    model : Identification, dict or path, optional
        Start from this identified model (its following-error time
        constants at ``rate``) instead of from nothing: compensated from the
        first sample, refined as it runs (``--model``).

    ``push`` returns ``None`` or ``(time [s], desired [m], command [m])``
    of the sample the command is for; ``push_many`` a list of them.
    """

    def __init__(
        self,
        rate: float,
        command_lead: int,
        *,
        replay: bool = False,
        max_velocity: float = 1.0,
        max_acceleration: float = 30.0,
        model: Union[None, "Identification", Mapping[str, Any], PathLike] = None,
    ):
        self._c = _feedid.OnlineCompensator(
            rate=float(rate),
            command_lead=int(command_lead),
            replay=bool(replay),
            max_velocity=float(max_velocity),
            max_acceleration=float(max_acceleration),
            **({} if model is None else _model_kw(model, "start the compensation")),
        )

    def push(self, t: float, u: float, y: float) -> Optional[Tuple[float, float, float]]:
        """Push one line: time ``t`` [s], command ``u`` [m], measured
        position ``y`` [m]; returns the command due next, if any."""
        return self._c.push(float(t), float(u), float(y))

    def push_many(self, t: Any, u: Any, y: Any) -> List[Tuple[float, float, float]]:
        """Push many lines at once (equal-length arrays; GIL released);
        returns the commands that became due, in order."""
        return self._c.push_many(_array(t, "t"), _array(u, "u"), _array(y, "y"))

    @property
    def stats(self) -> Dict[str, Any]:
        """Counters (commands, compensated, limited, model_updates,
        implausible, withheld, segments), the guard's ``state``
        (``learning``, ``unexplained``, ``invalid``, ``worse``, ``active``),
        ``time_constants`` [T1 s, T2 s², T3 s³] in use, the identified
        ``following_error_model`` and the correction's ``weight``."""
        return self._c.stats


def simulate(
    scenario: str,
    seed: int = 0,
    duration: Optional[float] = None,
    rate: float = 5000.0,
    params: Params = None,
    linear: bool = False,
    *,
    effects: Optional[PathLike] = None,
    allow_unstable: bool = False,
) -> Recording:
    """Simulate a test command on the nonlinear virtual rig (``feedid simulate``).

    Parameters
    ----------
    scenario : str
        ``ramp``, ``step``, ``scurve``, ``chirp``, ``prbs``, ``multisine``.
    seed : int
        Random seed of the command and the measurement noise (default 0,
        as ``feedid simulate --seed``).
    duration : float, optional
        Duration [s]; default the scenario's own.
    rate : float
        Sampling rate [Hz]; default 5000.
    params : path or dict, optional
        Rig parameters (rig.toml or a dict of its sections); default the
        built-in rig.
    linear : bool
        Without friction, limits, quantisation and noise (default False).
    effects : path, optional
        An effects.toml (friction law, limits, noise); not with ``linear``.
    allow_unstable : bool
        Simulate an unstable parameter set anyway (default False: refused).

    Returns
    -------
    Recording
        time [s], command [m], measured position [m], and the channels
        ``true_position`` [m], ``current`` [A], ``velocity`` [m/s]
        (``rec.true_position`` ...).
    """
    return _feedid.simulate(
        scenario,
        seed=seed,
        duration=duration,
        rate=rate,
        linear=linear,
        effects=None if effects is None else os.fspath(effects),
        allow_unstable=allow_unstable,
        **_params(params),
    )


def model(params: Params = None, d1: str = "corrected") -> Dict[str, Any]:
    """The nominal model in numbers, as ``feedid model --json``: transfer
    function coefficients, poles [rad/s], damping, bandwidth, steady-state
    errors.

    ``params``: rig.toml path or dict (default the built-in rig); ``d1``:
    ``corrected`` (default) or ``paper`` (the paper's printed D1).
    """
    return json.loads(_feedid.model(d1=d1, **_params(params)))


def compensate(
    time: Any,
    desired: Any,
    model: Union[None, "Identification", Mapping[str, Any], PathLike] = None,
    *,
    position_loop: str = "sampled",
    smooth: Union[None, float, str] = None,
    max_smoothing: float = 0.02,
    max_velocity: float = 1.0,
    max_acceleration: float = 30.0,
    keep_dc_gain: bool = False,
    allow_unstable: bool = False,
    start: str = "rest",
    min_benefit: float = 1.25,
    min_fit: float = 90.0,
    fallback: bool = True,
    check: Union[None, Recording, "Identification", PathLike, Sequence[Any]] = None,
    encoder_resolution: Optional[float] = None,
) -> Dict[str, Any]:
    """The command that makes a model follow the desired trajectory
    (``feedid compensate``).

    Parameters
    ----------
    time, desired : array_like
        Time [s] and desired position [m].
    model
        An :class:`Identification` (its global model), a model dict or
        model.json path (``feedid identify --model-out``), a rig.toml path or
        parameter dict (the physical model), or None (the built-in rig).
    position_loop : str
        Physical model only: ``sampled`` (default) or ``continuous``.
    smooth : float or "auto", optional
        Gaussian smoothing σ [s] of the desired trajectory; default auto (the
        smallest that keeps the limits).
    max_smoothing : float
        Largest automatic σ [s]; default 0.02.
    max_velocity, max_acceleration : float
        Command limits [m/s], [m/s²]; defaults 1.0 and 30.0.
    keep_dc_gain : bool
        Keep the model's DC gain (default False: scaled to 1).
    allow_unstable : bool
        Use an unstable physical model anyway (default False: refused).
    start : str
        The axis before the first desired sample: ``rest`` (default, at the
        first value) or ``moving`` (a segment cut from a longer program, at
        the first sample's velocity); ``--start``.
    min_benefit : float
        Send the plain command (the desired trajectory) when the model
        expects the rms error to fall less than this many times; default
        1.25 (``--min-benefit``).
    min_fit : float
        Send the plain command when the model's free-run position fit is
        below this [%]; default 90 (``--min-fit``).
    fallback : bool
        Allow that fall-back to the plain command (default True; False is
        ``--no-fallback``: always the compensated command).
    check : Recording, Identification, path or (time, command, position), optional
        A recording of the axis on which the identified model's fits are
        measured for the fall-back (``--check``); default the model's own
        fit. Identified models only. Dropped samples are read as gaps: the
        model runs through them and only the measured samples are compared.
        A list of two of them: two complete runs of the same program, whose
        noise is taken out by their cross-products (``--check a --check b``).
    encoder_resolution : float, optional
        The encoder's resolution [m] (its data sheet), with two check runs
        whose positions lie on no grid (noise after the count): the rounding
        both runs share is not counted as the model's error
        (``--encoder-resolution``).

    Returns
    -------
    dict
        ``command`` [m] and ``predicted`` [m] (NumPy), and the summary's
        keys (``predicted_error``, ``smoothing_s``, ``peak_velocity``, ...).
    """
    kw: Dict[str, Any] = {}
    if isinstance(model, Identification):
        if model.model is None:
            raise InputError("this identification has no global model to compensate with")
        kw["model_json"] = json.dumps(model.model)
    elif isinstance(model, Mapping):
        if "model" in model:
            kw["model_json"] = json.dumps(dict(model))
        else:
            kw.update(_params(model))
    elif model is not None:
        path = os.fspath(model)
        if path.lower().endswith(".toml"):
            kw["params_path"] = path
        else:
            kw["model_path"] = path
    if isinstance(smooth, str):
        if smooth.strip() != "auto":
            raise InputError(f"invalid smooth `{smooth}`: expected a time in seconds or auto")
        smooth = None
    def as_check(c: Any, allow_gaps: bool) -> Optional[Recording]:
        if c is None or isinstance(c, Recording):
            return c
        if isinstance(c, Identification):
            return c.recording
        if isinstance(c, (str, bytes, os.PathLike)):
            # (dropped samples: the model runs through them, as ``--check``)
            return read(c, allow_gaps=allow_gaps)
        t, u, y = c
        return Recording(
            _array(t, "time"), _array(u, "command"), _array(y, "position"), allow_gaps=allow_gaps
        )

    check_rec, check2_rec = None, None
    if isinstance(check, list) and len(check) == 2:
        # two complete runs of the same program
        check_rec, check2_rec = as_check(check[0], False), as_check(check[1], False)
    else:
        check_rec = as_check(check, True)
    command, predicted, summary = _feedid.compensate(
        _array(time, "time"),
        _array(desired, "desired"),
        position_loop=position_loop,
        smooth=smooth,
        max_smoothing=max_smoothing,
        max_velocity=max_velocity,
        max_acceleration=max_acceleration,
        keep_dc_gain=keep_dc_gain,
        allow_unstable=allow_unstable,
        start=start,
        min_benefit=min_benefit,
        min_fit=min_fit,
        fallback=fallback,
        check=check_rec,
        check2=check2_rec,
        encoder_resolution=encoder_resolution,
        **kw,
    )
    out: Dict[str, Any] = json.loads(summary)
    out["command"] = command
    out["predicted"] = predicted
    return out


def _model_kw(model: Any, what: str) -> Dict[str, Any]:
    """The identified model as keyword arguments of the native functions."""
    if isinstance(model, Identification):
        if model.model is None:
            raise InputError(f"this identification has no global model to {what} with")
        return {"model_json": json.dumps(model.model)}
    if isinstance(model, Mapping):
        return {"model_json": json.dumps(dict(model))}
    if model is None:
        raise InputError(f"{what} needs an identified model (Identification, model dict or model.json)")
    return {"model_path": os.fspath(model)}


def learn(
    time: Any,
    desired: Any,
    model: Union["Identification", Mapping[str, Any], PathLike],
    measured: Any,
    sent: Any = None,
    history: Union[None, Mapping[str, Any], PathLike] = None,
    *,
    gain: float = 1.0,
    noise_filter: Union[None, float, str] = None,
    smooth: Union[None, float, str] = None,
    max_smoothing: float = 0.02,
    max_velocity: float = 1.0,
    max_acceleration: float = 30.0,
    keep_dc_gain: bool = False,
    start: str = "rest",
) -> Dict[str, Any]:
    """The next run's command learned from a measured run of the program
    (``feedid compensate --measured``): iterative learning control with the
    identified model as its learning filter.

    Parameters
    ----------
    time, desired : array_like
        Time [s] and desired position [m] of the program.
    model
        The identified model: an :class:`Identification`, a model dict or a
        model.json path (``feedid identify --model-out``).
    measured : Recording, path or array_like
        The last run: a :class:`Recording` or recording path (its position,
        and its command as ``sent`` unless given), or its measured position
        [m], one value per desired sample.
    sent : array_like, optional
        The command sent in that run [m] (``--sent``); default the run's own
        command (required when ``measured`` is an array).
    history : dict or path, optional
        The learning history: ``result["history"]`` of the previous step, or a
        history.json written by ``--history``; default a new history (run 1).
    gain : float
        Learning gain of a step, 0 < gain < 2 (``--learning-gain``); default 1.
    noise_filter : float or "auto", optional
        σ [s] of the filter of the measured error; default auto
        (``--noise-filter``).
    smooth, max_smoothing, max_velocity, max_acceleration, keep_dc_gain, start
        The command's limits and settings, as for :func:`compensate`.

    Returns
    -------
    dict
        ``command`` [m] and ``predicted`` [m] (NumPy), ``history`` (a dict:
        pass it to the next step, or ``json.dump`` it), and the summary's keys
        (``run``, ``measured``, ``status``, ``gain``, ``unanswered_share``,
        ``predicted_next_rms_m``, ...). ``status["status"]`` is ``first``,
        ``improving``, ``at_noise``, ``damped``, ``settled`` (what is left is
        not what the model can correct: the best run's command again) or
        ``stopped``.
    """
    kw = _model_kw(model, "learn")
    if isinstance(measured, (str, bytes, os.PathLike)):
        measured = read(measured)
    if isinstance(measured, Recording):
        position = np.asarray(measured.position, dtype=np.float64)
        if sent is None:
            sent = measured.command
    else:
        position = _array(measured, "measured")
        if sent is None:
            raise InputError("give sent= (the command of the run) when measured is an array")
    if history is None:
        history_json = None
    elif isinstance(history, Mapping):
        history_json = json.dumps(dict(history))
    else:
        with open(os.fspath(history), encoding="utf-8") as f:
            history_json = f.read()
    for name, value in (("smooth", smooth), ("noise_filter", noise_filter)):
        if isinstance(value, str) and value.strip() != "auto":
            raise InputError(f"invalid {name} `{value}`: expected a time in seconds or auto")
    command, predicted, summary, new_history = _feedid.learn(
        _array(time, "time"),
        _array(desired, "desired"),
        _array(sent, "sent"),
        position,
        history_json=history_json,
        gain=gain,
        noise_filter=None if isinstance(noise_filter, str) else noise_filter,
        smooth=None if isinstance(smooth, str) else smooth,
        max_smoothing=max_smoothing,
        max_velocity=max_velocity,
        max_acceleration=max_acceleration,
        keep_dc_gain=keep_dc_gain,
        start=start,
        **kw,
    )
    out: Dict[str, Any] = json.loads(summary)
    out["command"] = command
    out["predicted"] = predicted
    out["history"] = json.loads(new_history)
    return out


def structure(path: PathLike) -> Dict[str, Any]:
    """The closed loop of a drive structure file (``examples/emps.toml``), as
    ``feedid model --params s.toml --json``: numerator and denominator,
    poles, stability, bandwidth [Hz], following error per velocity [s]."""
    return json.loads(_feedid.structure_model(os.fspath(path)))


def simulate_structure(
    path: PathLike, command: Any, rate: float, initial_position: Optional[float] = None
) -> Dict[str, np.ndarray]:
    """Run ``command`` [m] sampled at ``rate`` [Hz] through a drive structure's
    nonlinear simulation (friction, output limit, its controller), from rest
    at ``initial_position`` (default the command's first value). Returns
    ``position`` [m], ``velocity`` [m/s] and ``output`` (the controller's)."""
    position, velocity, output = _feedid.structure_simulate(
        os.fspath(path), _array(command, "command"), rate, initial_position=initial_position
    )
    return {"position": position, "velocity": velocity, "output": output}


def fit_structure(
    path: PathLike,
    command: Any,
    position: Any,
    rate: float,
    estimate: Sequence[str],
    restarts: int = 2,
) -> Dict[str, Any]:
    """Estimate a drive structure's parameters (``M``, ``Fv``, ``Fc``,
    ``offset``, ``gain``, ``kp``, ``kv``, ``Fs``; two-mass ``Mm``, ``k``,
    ``c``) from command and measured position by output error, as ``feedid
    greybox --params s.toml --estimate …``, with ``restarts`` fits started
    ±22 % away; the best of them is the estimate. Each estimate's
    ``verdict``: ``"identifiable"``, ``"imprecise"`` (the restarts agree but
    three standard errors exceed 5 % of it) or ``"not_identifiable"``
    (equally good fits end apart); ``restarts_elsewhere``: fits that ended
    in a local minimum. The result has the estimates with standard errors, the rms
    error before and after, the fit [%], and ``toml``: the structure with
    the estimates."""
    if isinstance(estimate, str):
        estimate = [e for e in estimate.split(",") if e.strip()]
    fit, toml = _feedid.structure_fit(
        os.fspath(path),
        _array(command, "command"),
        _array(position, "position"),
        rate,
        [str(e) for e in estimate],
        restarts=restarts,
    )
    out: Dict[str, Any] = json.loads(fit)
    out["toml"] = toml
    return out


def tune(path: PathLike, bandwidth: float, damping: float = 0.7071067811865476) -> Dict[str, Any]:
    """Gains of a rigid drive structure — a P position loop around a P or PI
    velocity loop, or a PD or PID position loop commanding the force — for
    a closed-loop bandwidth [Hz] and damping ratio, as ``feedid tune``: the
    gains before and after (``position_kp``, ``velocity_kp``,
    ``velocity_ki``, ``position_ki``, ``position_kd``), both closed loops,
    the step overshoot [%], and ``toml``: the retuned structure."""
    out_json, toml = _feedid.structure_tune(os.fspath(path), bandwidth, damping)
    out: Dict[str, Any] = json.loads(out_json)
    out["toml"] = toml
    return out
