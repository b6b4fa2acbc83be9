"""``Trajectory``: the result of :func:`kinedyn.simulate`.

Arrays, each with the samples on the first axis (a batch of N initial states adds a leading axis):
``t`` (S,) [s]; ``q``, ``qd``, ``qdd``, ``tau`` (S, n) or (N, S, n); energies ``K``, ``P``, ``H = K + P``
(S,) or (N, S) computed on first use. ``tau`` is the generalised force applied at each sample time and
``qdd`` the acceleration there. For constrained systems ``constraint_error`` holds, per sample, the
largest holonomic residual |phi(q)| and velocity residual |A(q) qd|.
"""

from __future__ import annotations

import math
import re
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from .._ui.files import replacing, write_text
from ..coordinates import coordinate_labels, velocity_labels
from ..display import trajectory_html
from ..visual.page import animation_page
from ..visual.viewer import show as show_in_viewer

__all__ = ["Trajectory"]


def _simpson_cumulative(y: np.ndarray, dx: float) -> np.ndarray:
    """Cumulative integral of samples y (S, ...) spaced dx: trapezoid rule, with a Simpson correction
    at even indices (so the value at the last sample is Simpson's when S is odd)."""
    out = np.zeros_like(y)
    out[1:] = np.cumsum(0.5 * dx * (y[1:] + y[:-1]), axis=0)
    if y.shape[0] >= 3:
        # Simpson on pairs of intervals: I_{2k} = sum dx/3 (y0 + 4 y1 + y2)
        pairs = dx / 3.0 * (y[0:-2:2] + 4 * y[1:-1:2] + y[2::2])
        out[2::2] = np.cumsum(pairs, axis=0)
    return out


class Trajectory:
    """Samples of a simulated motion (see the module docstring)."""

    def __init__(
        self,
        system,
        t,
        q,
        qd,
        qdd,
        tau,
        *,
        method: str = "",
        dt: float | None = None,
        info: dict | None = None,
        failure=None,
    ):
        self.system = system
        self.t = np.asarray(t, dtype=float)
        self.q = np.asarray(q, dtype=float)
        self.qd = np.asarray(qd, dtype=float)
        self.qdd = np.asarray(qdd, dtype=float)
        self.tau = np.asarray(tau, dtype=float)
        self.method = method
        self.dt = dt
        self.info = dict(info or {})
        self.failure = failure
        # a robot with closed loops: the loops' multipliers per sample, (S, m) or (N, S, m)
        # (docs/closed-loops.md, "Motion"); None otherwise
        self.loop_forces: np.ndarray | None = None

    # ------------------------------------------------------------------ shape
    @property
    def n(self) -> int:
        return self.q.shape[-1]

    @property
    def batch(self) -> int | None:
        """N for a batch of trajectories, else None."""
        return self.q.shape[0] if self.q.ndim == 3 else None

    def __len__(self) -> int:
        return self.t.size

    def __getitem__(self, i) -> Trajectory:
        """Trajectory ``i`` of a batch."""
        if self.batch is None:
            raise TypeError("this is a single trajectory; index its arrays (.q[k]) instead")
        one = Trajectory(
            self.system,
            self.t,
            self.q[i],
            self.qd[i],
            self.qdd[i],
            self.tau[i],
            method=self.method,
            dt=self.dt,
            info=self.info,
        )
        one.loop_forces = None if self.loop_forces is None else self.loop_forces[i]
        return one

    @property
    def x(self) -> np.ndarray:
        """States concatenate([q, qd]) per sample."""
        return np.concatenate([self.q, self.qd], axis=-1)

    @property
    def names(self) -> list:
        s = self.system
        if hasattr(s, "joint_names"):
            return list(s.joint_names)
        return list(getattr(s, "names", [f"q{i + 1}" for i in range(self.n)]))

    def labels(self) -> tuple[list, list]:
        """The names of q's columns (nq) and of qd's, qdd's and tau's (nv): a robot's from
        :mod:`kinedyn.coordinates` (a free-flyer's seven coordinates and six velocities each named),
        another system's ``names`` for both."""
        s = self.system
        if hasattr(s, "joints") and hasattr(s, "nq"):
            return coordinate_labels(s), velocity_labels(s)
        return self.names, self.names

    def __repr__(self) -> str:
        b = f", batch={self.batch}" if self.batch is not None else ""
        return f"Trajectory(system={getattr(self.system, 'name', '?')!r}, samples={len(self)}, t=[{self.t[0]:g}, {self.t[-1]:g}] s, method={self.method!r}{b})"

    def _repr_html_(self) -> str:  # notebooks: q(t) plotted as inline SVG (kinedyn.display)
        return trajectory_html(self)

    # ------------------------------------------------------------------ energies
    def _flat(self, a):
        # (samples..., n) -> (all samples, n); explicit so that n = 0 (a robot with no moving joint) works
        return a.reshape(int(np.prod(a.shape[:-1])), a.shape[-1])

    def _per_sample(self, fn_batch, fn_single, *arrays):
        shape = arrays[0].shape[:-1]
        if fn_batch is not None:
            out = np.asarray(fn_batch(*(np.ascontiguousarray(self._flat(a)) for a in arrays)), dtype=float)
        else:
            out = np.array([fn_single(*args) for args in zip(*(self._flat(a) for a in arrays))], dtype=float)
        return out.reshape(shape)

    @cached_property
    def K(self) -> np.ndarray:
        """Kinetic energy per sample [J]."""
        s = self.system
        if hasattr(s, "_model"):
            return self._per_sample(s.kinetic_energy, None, self.q, self.qd)
        if getattr(s, "kinetic_energy", None) is not None:
            return self._per_sample(None, s.kinetic_energy, self.q, self.qd)
        raise AttributeError("this system gives no kinetic energy (use .H)")

    @cached_property
    def P(self) -> np.ndarray:
        """Potential energy per sample [J]."""
        s = self.system
        if hasattr(s, "_model"):
            return self._per_sample(s.potential_energy, None, self.q)
        if getattr(s, "potential_energy", None) is not None:
            return self._per_sample(None, s.potential_energy, self.q)
        raise AttributeError("this system gives no potential energy (use .H)")

    @cached_property
    def H(self) -> np.ndarray:
        """Total energy K + P (the energy function qd . dL/dqd - L of a Lagrangian system) [J]."""
        s = self.system
        if not hasattr(s, "_model") and getattr(s, "energy", None) is not None:
            return self._per_sample(None, s.energy, self.q, self.qd)
        return self.K + self.P

    @cached_property
    def constraint_error(self) -> np.ndarray:
        """(S, 2) or (N, S, 2): per sample [max |phi(q)|, max |A(q) qd|] (zeros if unconstrained)."""
        s = self.system
        if not getattr(s, "constrained", False):
            return np.zeros(self.q.shape[:-1] + (2,))
        out = np.array([s.constraint_residuals(a, b) for a, b in zip(self._flat(self.q), self._flat(self.qd))])
        return out.reshape(self.q.shape[:-1] + (2,))

    def friction_torque(self) -> np.ndarray:
        """Joint friction of a robot per sample, :meth:`kinedyn.Robot.friction_torque` (zeros otherwise)."""
        s = self.system
        if not hasattr(s, "friction_torque"):
            return np.zeros_like(self.qd)
        return s.friction_torque(self.qd)

    def energy_balance(self) -> dict:
        """Passivity along the trajectory (Spong eq. 9.117, dH/dt = qd . tau): the work of the input
        W(t) = int qd . tau dt, the energy dissipated by friction D(t) = int qd . friction dt, and
        the residual H(t) - H(0) - (W - D), each (S,) (Simpson's rule on the samples; uniform
        spacing required). ``relative``: max |residual| / max(1, max |W|, max |H - H(0)|)."""
        if self.batch is not None:
            raise TypeError("energy_balance() is per trajectory: use traj[i].energy_balance()")
        dt = np.diff(self.t)
        if dt.size and not np.allclose(dt, dt[0], rtol=1e-9, atol=0):
            raise ValueError("energy_balance needs uniformly spaced samples")
        h = float(dt[0]) if dt.size else 0.0
        power = np.einsum("...i,...i->...", self.qd, self.tau)
        loss = np.einsum("...i,...i->...", self.qd, self.friction_torque())
        W = _simpson_cumulative(power, h)
        D = _simpson_cumulative(loss, h)
        dH = self.H - self.H[0]
        residual = dH - (W - D)
        # only the even samples carry Simpson's value; report the residual there
        at = np.arange(0, len(self), 2) if len(self) >= 3 else np.arange(len(self))
        scale = max(1.0, float(np.abs(W).max(initial=0)), float(np.abs(dH).max(initial=0)))
        return {
            "t": self.t,
            "work": W,
            "dissipated": D,
            "dH": dH,
            "residual": residual,
            "relative": float(np.abs(residual[at]).max(initial=0)) / scale,
        }

    # ------------------------------------------------------------------ export
    def _columns(self) -> tuple:
        q_names, v_names = self.labels()
        cols = {"t": self.t}
        for key, arr, names in (
            ("q", self.q, q_names),
            ("qd", self.qd, v_names),
            ("qdd", self.qdd, v_names),
            ("tau", self.tau, v_names),
        ):
            for i, nm in enumerate(names):
                cols[f"{key}[{nm}]"] = arr[:, i]
        try:
            cols["K"], cols["P"] = self.K, self.P
        except AttributeError:
            pass
        try:
            cols["H"] = self.H
        except AttributeError:
            pass
        return list(cols), np.column_stack(list(cols.values()))

    def to_csv(self, path) -> Path:
        """One row per sample: t, q, qd, qdd, tau per joint, K, P, H (a header names the columns)."""
        if self.batch is not None:
            raise TypeError("to_csv writes one trajectory: use traj[i].to_csv(...) or to_npz for a batch")
        header, data = self._columns()
        path = Path(path)
        with replacing(path) as tmp:  # atomic: a failed run leaves the old file (kinedyn._ui.files)
            np.savetxt(tmp, data, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
        return path

    def to_npz(self, path) -> Path:
        """Arrays t, q, qd, qdd, tau, K, P, H and joint names in one compressed NumPy file."""
        path = Path(path)
        arrays: dict[str, Any] = dict(
            t=self.t, q=self.q, qd=self.qd, qdd=self.qdd, tau=self.tau, names=np.array(self.names)
        )
        for key in ("K", "P", "H"):
            try:
                arrays[key] = getattr(self, key)
            except AttributeError:
                pass
        if path.suffix != ".npz":  # NumPy's own rule: the name gets .npz
            path = path.with_name(path.name + ".npz")
        with replacing(path) as tmp, open(tmp, "wb") as f:  # atomic (kinedyn._ui.files)
            np.savez_compressed(f, **arrays)
        return path

    # ------------------------------------------------------------------ plots
    def plot(self, path=None, show: bool = False):
        """Joint positions, velocities, torques and energies against time (matplotlib); saved to
        ``path`` if given. Returns the Figure. Works with any backend (Agg included)."""
        import matplotlib.pyplot as plt  # matplotlib loads only when a figure is drawn

        if self.batch is not None:
            raise TypeError("plot() draws one trajectory: use traj[i].plot()")
        # the joints' legend goes beside the plots, in a layout that makes room for it (constrained
        # layout counts an axes' legend in its extent): inside the axes, many joints' names ran past
        # the figure's edge and were cut off
        q_names, v_names = self.labels()
        rows = max(len(q_names), len(v_names))
        columns = 1 if rows <= 14 else 2 if rows <= 28 else 3
        fig, axes = plt.subplots(4, 1, figsize=(8 + 1.6 * columns, 9), sharex=True, layout="constrained")
        for ax, arr, label, names in zip(
            axes[:3],
            (self.q, self.qd, self.tau),
            ("q [rad | m]", "qd [rad/s | m/s]", "tau [N m | N]"),
            (q_names, v_names, v_names),
        ):
            for i, name in enumerate(names):
                ax.plot(self.t, arr[:, i], label=name)
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        # a legend beside the q plot (the same colours in qd and tau, a line per joint); with multi-DOF
        # joints (nq != nv) the qd plot's entries are others, so it gets its own
        legend = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", ncols=columns)
        axes[0].legend(**legend)
        if q_names != v_names:
            axes[1].legend(**legend)
        ax = axes[3]
        for key in ("K", "P", "H"):
            try:
                ax.plot(self.t, getattr(self, key), label=key)
            except AttributeError:
                pass
        ax.set_ylabel("energy [J]")
        ax.set_xlabel("t [s]")
        ax.legend(loc="upper right", fontsize="small")
        ax.grid(True, alpha=0.3)
        fig.suptitle(f"{getattr(self.system, 'name', '')} ({self.method})")
        if path is not None:
            with replacing(path) as tmp:  # atomic (kinedyn._ui.files); the same extension, so the same format
                fig.savefig(tmp, dpi=100)
        if show:
            plt.show()
        else:
            plt.close(fig)
        return fig

    def _points(self) -> np.ndarray:
        """(S, m, 3) positions to draw: base origin and every link frame origin of a robot, or the
        system's ``points(q)``."""
        s = self.system
        if hasattr(s, "_model"):
            T = s.forward_kinematics(np.ascontiguousarray(self.q))  # (S, n, 4, 4)
            tool = s.pose(np.ascontiguousarray(self.q))[:, None, :3, 3]
            base = np.zeros((len(self), 1, 3))
            return np.concatenate([base, T[:, :, :3, 3], tool], axis=1)
        if getattr(s, "points", None) is None:
            raise ValueError("animate() needs positions: build the MechanicalSystem with points=...")
        P = np.array([np.atleast_2d(s.points(qk)) for qk in self.q], dtype=float)
        if P.shape[-1] == 2:
            P = np.concatenate([P, np.zeros(P.shape[:-1] + (1,))], axis=-1)
        return P

    def show(self, *, block: bool | None = None, **kwargs):
        """Play the motion in the live 3-D viewer (:meth:`kinedyn.Robot.show`, with a time slider and
        play/pause). Returns the viewer; ``block`` as for ``Robot.show``."""
        if self.batch is not None:
            raise TypeError("show() plays one trajectory: use traj[i].show()")
        if not hasattr(self.system, "frame_poses"):
            raise TypeError("show() needs a trajectory of a kinedyn.Robot; use animate() for other systems")
        return show_in_viewer(self.system, np.asarray(self.q, dtype=float)[0], trajectory=self, block=block, **kwargs)

    def animate(self, path, fps: int = 25, duration: float | None = None, trail: bool = True):
        """A stick figure of the motion: GIF (``.gif``, Pillow), HTML (``.html``, self-contained
        JavaScript player; a robot's is its meshes in a 3-D view, as in the report) or MP4 (``.mp4``, needs ffmpeg). 2-D when every point stays in a plane
        z = const (planar arms), else 3-D. Frames are taken every 1/fps seconds of simulated time.
        Returns the path."""
        import matplotlib.pyplot as plt  # matplotlib loads only when a figure is drawn
        from matplotlib import animation

        if self.batch is not None:
            raise TypeError("animate() draws one trajectory: use traj[i].animate(...)")
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".gif", ".html", ".mp4"):
            raise ValueError(f"animate writes .gif, .html or .mp4 files, got '{path.name}'")
        span = self.t[-1] - self.t[0]
        frames = max(2, int(math.ceil((duration or span) * fps)) + 1)
        idx = np.unique(np.round(np.linspace(0, len(self) - 1, frames)).astype(int))
        if suffix == ".html" and hasattr(self.system, "frame_poses"):
            # a robot: its meshes in the report's 3-D view, sent once, then joint values per frame
            write_text(path, animation_page(self.system, np.asarray(self.t)[idx], np.asarray(self.q)[idx]))
            return path
        P = self._points()
        planar = np.ptp(P[..., 2]) < 1e-9
        lo, hi = P.reshape(-1, 3).min(axis=0), P.reshape(-1, 3).max(axis=0)
        centre, radius = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3) * 1.1
        fig = plt.figure(figsize=(5, 5))
        # a 2-D Axes or an mplot3d Axes3D, whose text2D and Line3D.set_3d_properties are untyped
        ax: Any
        line: Any
        path_line: Any
        if planar:
            ax = fig.add_subplot(111)
            ax.set_aspect("equal")
            ax.set_xlim(centre[0] - radius, centre[0] + radius)
            ax.set_ylim(centre[1] - radius, centre[1] + radius)
            (line,) = ax.plot([], [], "o-", lw=3, color="tab:blue")
            (path_line,) = ax.plot([], [], "-", lw=1, color="tab:orange", alpha=0.6)
        else:
            ax = fig.add_subplot(111, projection="3d")
            for setl, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
                setl(c - radius, c + radius)
            (line,) = ax.plot([], [], [], "o-", lw=3, color="tab:blue")
            (path_line,) = ax.plot([], [], [], "-", lw=1, color="tab:orange", alpha=0.6)
        ax.set_title(getattr(self.system, "name", ""))
        label = (
            ax.text2D(0.02, 0.95, "", transform=ax.transAxes)
            if not planar
            else ax.text(0.02, 0.95, "", transform=ax.transAxes)
        )

        def draw(k):
            i = idx[k]
            p = P[i]
            tip = P[idx[: k + 1], -1]
            if planar:
                line.set_data(p[:, 0], p[:, 1])
                if trail:
                    path_line.set_data(tip[:, 0], tip[:, 1])
            else:
                line.set_data(p[:, 0], p[:, 1])
                line.set_3d_properties(p[:, 2])
                if trail:
                    path_line.set_data(tip[:, 0], tip[:, 1])
                    path_line.set_3d_properties(tip[:, 2])
            label.set_text(f"t = {self.t[i]:.2f} s")
            return line, path_line, label

        anim = animation.FuncAnimation(fig, draw, frames=len(idx), interval=1000 / fps, blit=False)
        try:
            if suffix == ".gif":
                with replacing(path) as tmp:  # atomic (kinedyn._ui.files)
                    anim.save(tmp, writer=animation.PillowWriter(fps=fps))
            elif suffix == ".html":
                write_text(path, _offline_jshtml(anim.to_jshtml(fps=fps)))
            else:
                if not animation.FFMpegWriter.isAvailable():
                    raise RuntimeError("writing .mp4 needs ffmpeg on the PATH; write a .gif or .html instead")
                with replacing(path) as tmp:  # atomic (kinedyn._ui.files)
                    anim.save(tmp, writer=animation.FFMpegWriter(fps=fps))
        finally:
            plt.close(fig)
        return path


# matplotlib's JavaScript player draws its buttons with Font Awesome from a CDN: the page would make a
# network request, and show empty buttons offline. The same buttons as plain characters instead.
_PLAYER_GLYPHS = {
    "fa fa-minus": "\u2212",
    "fa fa-fast-backward": "\u23ee",
    "fa fa-step-backward": "\u23f4\u23f4",
    "fa fa-play fa-flip-horizontal": "\u25c0",
    "fa fa-pause": "\u23f8",
    "fa fa-play": "\u25b6",
    "fa fa-step-forward": "\u23f5\u23f5",
    "fa fa-fast-forward": "\u23ed",
    "fa fa-plus": "+",
}


def _offline_jshtml(page: str) -> str:
    """matplotlib's to_jshtml() page without its Font Awesome stylesheet link (see _PLAYER_GLYPHS)."""
    page = re.sub(r"<link[^>]*font-awesome[^>]*>", "", page)
    for css, glyph in _PLAYER_GLYPHS.items():
        page = page.replace(f'<i class="{css}"></i>', f"<span>{glyph}</span>")
    return page
