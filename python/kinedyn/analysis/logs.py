"""Robot logs for identification: reading, checking, filtering and differentiating (docs/analysis.md).

A log holds, per sample, the time ``t`` (s, strictly increasing), the joint positions ``q1..qn``
(rad or m) and either the joint torques ``tau1..taun`` (N m or N) or the motor currents ``i1..in``
(A) with a torque constant ``k_t`` (N m / A) and a gear ratio ``r`` per joint, so that
``tau_j = r_j k_t,j i_j``. Velocities ``qd1..qdn`` and accelerations ``qdd1..qddn`` are optional.

When velocities or accelerations are absent they are computed from the positions (the usual
processing of identification data, Gautier 1997 "Dynamic identification of robots with power
model", and Swevers et al. 1997 §IV):

1. the positions are low-pass filtered with a zero-phase Butterworth filter (``scipy.signal.butter``
   applied forwards and backwards by ``filtfilt``, so without delay), then differentiated twice by
   central differences (``numpy.gradient``);
2. the torques go through the same filter, so that the torques and the motion they are compared
   with see the same (zero) phase and the same attenuation; so does sign(qd), the Coulomb friction
   column (the filter smears the torque's Coulomb jump at a reversal over ~1 / cutoff: comparing it
   with an unfiltered sign would leave that smear as a residual many times the noise; filtering the
   regressor column and the torque alike is Gautier's "parallel filtering");
3. the filter edges, where ``filtfilt``'s start-up transient lives, are trimmed, and the samples are
   decimated (the signals are already band-limited below the cut-off, so keeping every k-th sample
   aliases nothing).

The cut-off rule (overridable by ``cutoff=``): the *bandwidth* of the motion is the frequency below
which 99.9 % of the power of the positions lies (mean and linear trend removed, Hann-windowed), the largest over the joints; the
cut-off is 5 times that bandwidth, at least 1 Hz and at most 0.4 times the Nyquist frequency. The
factor 5 keeps the attenuation of the motion itself below 1e-3 for a 4th-order filter
(|H(f)|^2 = 1 / (1 + (f/fc)^(2 N)) twice, filtfilt) while cutting the quantisation and torque noise
spread over the whole band.
"""

from __future__ import annotations

import io
import math
import os
import re
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._ui.files import open_regular

__all__ = ["Log", "LogError", "load_log", "motion_bandwidth", "choose_cutoff"]


# A log file, or what an .npz archive inflates to, larger than this is refused before it is read:
# an hour at 1 kHz of 30 float64 columns is 0.9 GB of numbers, 2-3 GB as CSV text
MAX_LOG_BYTES = 4 * 2**30


class LogError(ValueError):
    """A log that cannot be used: the message names the file and the column, row or setting."""


@dataclass
class Log:
    """Samples (S,) / (S, n) ready for identification, and how they were processed."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    #: sample rate after decimation, Hz
    rate: float
    #: low-pass cut-off in Hz (None: the log came with velocities and accelerations, not filtered)
    cutoff: float | None = None
    decimation: int = 1
    source: str = "<data>"
    #: sign(qd) passed through the same low-pass filter as the torques (None when not filtered): the
    #: Coulomb column of the friction regressor, so that it sees the filter the torque's Coulomb part saw
    filtered_sign: np.ndarray | None = None
    #: the filtered velocities at the log's own rate, before trimming and decimation (None when not
    #: filtered), and the Butterworth order: :meth:`parallel` filters other columns of qd with them
    raw_qd: np.ndarray | None = field(default=None, repr=False)
    order: int = 4
    #: (start, stop, step) of the kept samples in the raw ones
    window: tuple | None = None

    def parallel(self, column) -> np.ndarray | None:
        """``column(qd)`` (a function of the velocities, (S, n) -> (S, n), e.g. a friction column)
        computed at the log's own rate, passed through the log's low-pass and kept at its samples:
        the parallel filtering the torques saw (module docstring, step 2). None for an unfiltered log."""
        if self.raw_qd is None or self.cutoff is None or self.window is None:
            return None
        start, stop, step = self.window
        raw_rate = self.rate * self.decimation
        return _lowpass(column(self.raw_qd), self.cutoff, raw_rate, self.order)[start:stop:step]

    def lowpass(self, x: np.ndarray, rate: float) -> np.ndarray:
        """``x`` sampled at ``rate`` Hz (along axis 0) through this log's zero-phase low-pass (the
        unchanged ``x`` for a log that was not filtered): to filter a simulated regressor as the
        log's torques were."""
        if self.cutoff is None:
            return x
        return _lowpass(x, self.cutoff, rate, self.order)

    def subset(self, start: int, stop: int) -> tuple | None:
        """The window of the samples ``start:stop`` of this log (for a copy holding only those)."""
        if self.window is None:
            return None
        s0, _, step = self.window
        return (s0 + start * step, s0 + stop * step, step)

    @property
    def n(self) -> int:
        return int(self.q.shape[1])

    def __len__(self) -> int:
        return int(self.t.shape[0])


def motion_bandwidth(q: np.ndarray, rate: float, fraction: float = 0.999) -> float:
    """Frequency (Hz) below which ``fraction`` of the power of each joint's mean-removed position
    lies, the largest over the joints (0 for a log without motion)."""
    x = np.asarray(q, dtype=float)
    x = x - x.mean(axis=0)
    # the jump between the log's last and first sample would leak power over every frequency (the
    # FFT sees the record as periodic): a linear trend is taken out, then a Hann window tapers the ends
    s = np.arange(x.shape[0]) - (x.shape[0] - 1) / 2
    x = x - np.outer(s, (s @ x) / max(float(s @ s), 1.0))
    x = x * np.hanning(x.shape[0])[:, None]
    power = np.abs(np.fft.rfft(x, axis=0)) ** 2
    freqs = np.fft.rfftfreq(x.shape[0], 1.0 / rate)
    band = 0.0
    for j in range(x.shape[1]):
        total = power[:, j].sum()
        if total <= 0:
            continue
        k = int(np.searchsorted(np.cumsum(power[:, j]) / total, fraction))
        band = max(band, float(freqs[min(k, len(freqs) - 1)]))
    return band


def choose_cutoff(q: np.ndarray, rate: float) -> float:
    """The cut-off rule of this module: 5 x :func:`motion_bandwidth`, within [1 Hz, 0.4 Nyquist]."""
    nyquist = rate / 2
    return float(min(max(5.0 * motion_bandwidth(q, rate), 1.0), 0.4 * nyquist))


def _columns_from_table(names: Sequence[str], data: np.ndarray) -> dict:
    return {str(nm).strip(): data[:, k] for k, nm in enumerate(names)}


def _read(source: Any) -> tuple[dict, str]:
    """A mapping column name -> 1-D array, and a name for messages."""
    try:
        import pandas as pd  # type: ignore[import-untyped]  # optional and heavy: only to recognise a DataFrame
    except ImportError:  # pragma: no cover - pandas is optional
        pd = None
    if pd is not None and isinstance(source, pd.DataFrame):
        cols = {}
        for c in source.columns:
            try:
                cols[str(c).strip()] = source[c].to_numpy(dtype=float)
            except (TypeError, ValueError):
                raise LogError(f"data frame: column '{c}' is not numeric") from None
        return cols, "data frame"
    if isinstance(source, dict):
        return {str(k): np.asarray(v, dtype=float) for k, v in source.items()}, "mapping"
    path = os.fspath(source)
    if not os.path.exists(path):
        raise LogError(f"{path}: no such file")
    try:  # a FIFO, /dev/zero or a folder: refused, never waited on (kinedyn._ui.files)
        stream = open_regular(path, "log")
    except ValueError as e:
        raise LogError(str(e)) from None
    with stream:
        size = os.fstat(stream.fileno()).st_size
        if size > MAX_LOG_BYTES:
            raise LogError(
                f"{path}: the log is {size / 2**20:.0f} MiB, more than the {MAX_LOG_BYTES // 2**20} MiB kinedyn reads"
            )
        if path.lower().endswith(".npz"):
            return _read_npz(path, stream), path
        return _read_csv(path, stream), path


def _read_npz(path: str, stream) -> dict:
    """The arrays of an .npz archive, their sizes checked from the archive's headers before any is
    inflated (a small archive can hold gigabytes of zeros)."""
    try:
        with zipfile.ZipFile(stream) as archive:
            inflated = sum(info.file_size for info in archive.infolist())
    except (zipfile.BadZipFile, OSError, ValueError) as e:
        raise LogError(f"{path}: not a NumPy .npz archive ({e})") from None
    if inflated > MAX_LOG_BYTES:
        raise LogError(
            f"{path}: the archive inflates to {inflated / 2**20:.0f} MiB, more than the {MAX_LOG_BYTES // 2**20} MiB kinedyn reads"
        )
    stream.seek(0)
    cols = {}
    try:
        with np.load(stream, allow_pickle=False) as z:
            for k in z.files:
                raw = z[k]
                if raw.dtype.kind not in "biuf":  # complex, strings, objects: not a measured signal
                    raise LogError(f"{path}: array '{k}' holds {raw.dtype} values, not real numbers")
                a = np.asarray(raw, dtype=float)
                if a.ndim == 2 and k in ("q", "qd", "qdd", "tau", "i"):  # whole (S, n) arrays
                    for j in range(a.shape[1]):
                        cols[f"{k}{j + 1}"] = a[:, j]
                else:
                    cols[k] = a.reshape(-1) if a.ndim <= 1 else a
    except LogError:
        raise
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as e:
        raise LogError(f"{path}: not a readable NumPy .npz archive ({e})") from None
    return cols


def _read_csv(path: str, stream) -> dict:
    raw = stream.read()
    try:
        text = raw.decode("utf-8-sig")  # a UTF-8 byte-order mark is not part of the first column's name
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise LogError(f"{path}: line {line}: the log is not UTF-8 text (byte {e.start})") from None
    f = io.StringIO(text)
    header = f.readline()
    names = [h.strip() for h in header.strip().split(",")]
    if not names or not any(names):
        raise LogError(f"{path}: line 1 should be a header of column names (t, q1..qn, tau1..taun)")
    try:
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    except ValueError as e:
        # NumPy counts the rows after the header from 0 in a conversion error and from 1 in a change of
        # the column count (numpy.loadtxt, NumPy 1.23+): line = row + 2 and row + 1 of the file
        changed = re.search(r"number of columns changed from (\d+) to (\d+) at row (\d+)", str(e))
        if changed:
            raise LogError(
                f"{path}: line {int(changed.group(3)) + 1}: {changed.group(2)} values, where the lines before "
                f"have {changed.group(1)}"
            ) from None
        m = re.search(r"at row (\d+)", str(e))
        where = f" line {int(m.group(1)) + 2}:" if m else ""
        raise LogError(f"{path}:{where} not a number ({e})") from None
    if data.shape[1] != len(names):
        raise LogError(f"{path}: the header names {len(names)} columns but the rows have {data.shape[1]}")
    return _columns_from_table(names, data)


def _numbered(cols: dict, prefix: str) -> list:
    """Columns prefix1, prefix2, ... (consecutive from 1)."""
    out: list = []
    while f"{prefix}{len(out) + 1}" in cols:
        out.append(f"{prefix}{len(out) + 1}")
    return out


def _lowpass(x: np.ndarray, cutoff: float, rate: float, order: int) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt  # scipy loads only when a log is filtered

    sos = butter(order, cutoff, btype="low", fs=rate, output="sos")
    return sosfiltfilt(sos, x, axis=0)


def load_log(
    source: Any,
    *,
    n: int | None = None,
    torque_constants: Any | None = None,
    gear_ratios: Any | None = None,
    cutoff: float | None = None,
    order: int = 4,
    decimate: int | None = None,
    trim: float | None = None,
) -> Log:
    """Read and prepare a log (CSV with a header line, NPZ, a pandas DataFrame or a dict of columns).

    ``n``: the number of joints expected (e.g. ``robot.n``); ``torque_constants`` / ``gear_ratios``:
    per joint, to turn the currents ``i1..in`` into torques; ``cutoff``: the low-pass cut-off in Hz
    (default: the rule in the module docstring); ``order``: Butterworth order; ``decimate``: keep
    every k-th sample (default: the largest k with ``rate / k >= 5 cutoff``); ``trim``: seconds cut at each end (default ``3 / cutoff``).
    Raises :class:`LogError` (a ValueError) naming the file and the missing, non-finite or
    inconsistent column."""
    if isinstance(source, Log):
        return source
    # the settings first, before a byte is read: a decimation of 0 or -1 (a log reversed), a negative trim
    if decimate is not None and (
        isinstance(decimate, bool) or not isinstance(decimate, (int, np.integer)) or decimate < 1
    ):
        raise LogError(f"decimate must be a whole number >= 1 (keep every k-th sample), got {decimate!r}")
    for setting, value in (("trim", trim), ("cutoff", cutoff)):
        if value is not None and not (
            isinstance(value, (int, float, np.number)) and math.isfinite(value) and value >= 0
        ):
            raise LogError(f"{setting} must be a finite number >= 0, got {value!r}")
    if cutoff is not None and not cutoff > 0:
        raise LogError(f"cutoff must be a positive frequency in Hz, got {cutoff!r}")
    cols, name = _read(source)
    if "t" not in cols:
        raise LogError(f"{name}: missing column 't' (time, s); columns: {sorted(cols)}")
    qn = _numbered(cols, "q")
    if not qn:
        raise LogError(f"{name}: missing columns 'q1'..'qn' (joint positions); columns: {sorted(cols)}")
    if n is not None and len(qn) != n:
        raise LogError(f"{name}: {len(qn)} position columns q1..q{len(qn)} but the robot has {n} joints")
    n = len(qn)
    S = len(cols["t"])
    for k, v in cols.items():
        if np.asarray(v).shape != (S,):
            raise LogError(f"{name}: column '{k}' has {np.asarray(v).shape} values, 't' has {S}")
    t = cols["t"]

    def block(prefix: str, what: str, required: bool = True) -> np.ndarray | None:
        present = [f"{prefix}{j}" for j in range(1, n + 1) if f"{prefix}{j}" in cols]
        if not present:
            if required:
                raise LogError(f"{name}: missing columns '{prefix}1'..'{prefix}{n}' ({what})")
            return None
        if len(present) < n:
            missing = next(f"{prefix}{j}" for j in range(1, n + 1) if f"{prefix}{j}" not in cols)
            raise LogError(f"{name}: missing column '{missing}' ({what})")
        return np.column_stack([cols[c] for c in present])

    q = block("q", "joint positions")
    assert q is not None
    tau = block("tau", "joint torques", required=False)
    if tau is None:
        cur = block("i", "motor currents", required=False)
        if cur is None:
            raise LogError(
                f"{name}: missing columns 'tau1'..'tau{n}' (joint torques, N m) or 'i1'..'i{n}' (motor currents, A)"
            )
        if torque_constants is None or gear_ratios is None:
            raise LogError(
                f"{name}: the log has motor currents i1..i{n}: give torque_constants and gear_ratios to turn them into torques"
            )
        kt = np.broadcast_to(np.asarray(torque_constants, dtype=float), (n,))
        r = np.broadcast_to(np.asarray(gear_ratios, dtype=float), (n,))
        if not (np.all(np.isfinite(kt)) and np.all(np.isfinite(r))):
            raise LogError(f"{name}: torque_constants and gear_ratios must be finite")
        tau = cur * kt * r
    qd = block("qd", "joint velocities", required=False)
    qdd = block("qdd", "joint accelerations", required=False)
    for label, arr in (("t", t[:, None]), ("q", q), ("tau" if "tau1" in cols else "i", tau), ("qd", qd), ("qdd", qdd)):
        if arr is None:
            continue
        bad = ~np.isfinite(arr)
        if bad.any():
            row, j = (int(x) for x in np.argwhere(bad)[0])
            col = label if label == "t" else f"{label}{j + 1}"
            raise LogError(
                f"{name}: column '{col}' has a non-finite value (NaN or inf) at sample {row} (t index), data row {row + 1}"
            )
    if S < 10:
        raise LogError(f"{name}: {S} samples are too few to identify anything")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise LogError(f"{name}: time is not increasing at sample {k + 1} (t = {t[k]:g} then {t[k + 1]:g})")
    rate = float(1.0 / np.median(dt))
    if np.max(np.abs(dt * rate - 1.0)) > 0.05:
        raise LogError(
            f"{name}: the sampling is not uniform (steps from {dt.min():g} to {dt.max():g} s); resample the log first"
        )
    if qd is not None and qdd is not None and cutoff is None:
        k = 1 if decimate is None else int(decimate)
        return Log(t[::k], q[::k], qd[::k], qdd[::k], tau[::k], rate / k, None, k, name)
    if cutoff is None:
        cutoff = choose_cutoff(q, rate)
    if not 0 < cutoff < rate / 2:
        raise LogError(f"{name}: cutoff {cutoff:g} Hz must lie between 0 and the Nyquist frequency {rate / 2:g} Hz")
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # checked just below, with a message
            qf = _lowpass(q, cutoff, rate, order)
            h = 1.0 / rate
            qd_f = np.gradient(qf, h, axis=0) if qd is None else _lowpass(qd, cutoff, rate, order)
            qdd_f = np.gradient(qd_f, h, axis=0) if qdd is None else _lowpass(qdd, cutoff, rate, order)
            tau_f = _lowpass(tau, cutoff, rate, order)
    except ValueError as e:  # scipy's filtfilt needs more samples than its padding (15 at order 4)
        raise LogError(f"{name}: {S} samples are too few to filter (scipy: {e})") from None
    for what, x in (("velocities", qd_f), ("accelerations", qdd_f), ("torques", tau_f)):
        if not np.all(np.isfinite(x)):  # e.g. a step of 1e-302 s: differences over it overflow
            raise LogError(
                f"{name}: the filtered {what} are not finite numbers (a time step of {float(np.median(dt)):g} s "
                "is too small to differentiate over; give t in seconds)"
            )
    if trim is None:
        trim = 3.0 / cutoff
    edge = int(np.ceil(trim * rate))
    if 2 * edge >= S - 10:
        raise LogError(f"{name}: the log ({S / rate:g} s) is too short to trim {trim:g} s of filter edge at each end")
    k = max(1, int(np.floor(rate / (5.0 * cutoff)))) if decimate is None else int(decimate)
    if k < 1:
        raise LogError(f"{name}: decimate must be a whole number >= 1, got {decimate}")
    sl = slice(edge, S - edge, k)
    # a joint that never moves has a filtered velocity of round-off (~1e-13), whose sign would be a
    # Coulomb column of +-1 noise: velocities below 1e-9 of the log's largest count as rest
    rest = np.abs(qd_f) <= 1e-9 * max(float(np.abs(qd_f).max()), 1e-300)
    sign_f = _lowpass(np.where(rest, 0.0, np.sign(qd_f)), cutoff, rate, order)
    return Log(
        t[sl],
        qf[sl],
        qd_f[sl],
        qdd_f[sl],
        tau_f[sl],
        rate / k,
        float(cutoff),
        k,
        name,
        sign_f[sl],
        raw_qd=qd_f,
        order=order,
        window=(edge, S - edge, k),
    )
