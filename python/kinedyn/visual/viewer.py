"""A live 3-D viewer in the browser: ``robot.show(q)``, ``trajectory.show()``, ``kinedyn view ROBOT``.

It runs a viser server (a real web server with a three.js client, both from the installed ``viser``
package; nothing is fetched from elsewhere) on this machine, by default on ``127.0.0.1`` (only this
machine can connect), and prints its URL. The robot's meshes (:func:`kinedyn.visual.robot_scene`) are
sent once, each fixed to a scene frame whose pose follows the forward kinematics; the stick figure,
the base and tool frames, a slider per joint (a robot with closed loops: per independent coordinate,
the other joints solved as it moves) and, for a trajectory, a time slider with play/pause.

On a remote machine, forward the port: ``ssh -L 8080:localhost:8080 user@host``, then open
http://localhost:8080 here (docs/visualisation.md).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import math
import sys
import threading
import time
import warnings
from typing import Any

import numpy as np

from .._ui import interrupts
from ..configuration import default_configuration
from .loops import CLOSED, LiveLoop
from .scene import DEFAULT_BUDGET, robot_scene, scene_bounds
from .serving import HandshakeGuard, guarded_viser, listen_address

__all__ = ["Viewer", "show"]


def _in_notebook() -> bool:
    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    try:
        ip = shell.get_ipython()
    except Exception:
        return False
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def _view_direction(robot, q, up: np.ndarray) -> np.ndarray:
    """From the scene towards the eye: front-right and above the base (as the report's view)."""
    side = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
    side /= np.linalg.norm(side)
    front = np.cross(side, up)
    return 0.8 * front - 0.6 * side + 0.45 * up


def _wxyz(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method: the largest of the
    four squares first, so no division by a small number)."""
    m = np.asarray(R, dtype=float)
    t = np.trace(m)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    out = np.array(q)
    return out / np.linalg.norm(out)


class Viewer:
    """A running viewer of ``robot`` at ``q`` (default: the report's configuration), optionally
    playing back ``trajectory`` (a :class:`kinedyn.simulate.Trajectory` of this robot).

    ``host``/``port``: where the server listens (``127.0.0.1``: this machine only; the next free port
    if ``port`` is busy, any free one for 0); a bad port, a host that does not resolve or an address
    this machine does not have is a ValueError, and listening beyond loopback warns. The viewer
    answers only requests that name it by a loopback Host and WebSockets from its own page;
    ``allow_remote=True`` accepts any Host (docs/viewer-security.md: an ssh tunnel is the safe route). ``geometry``: "visual" or "collision" shapes. Attributes:
    ``url``, ``server`` (the viser server), ``q``. ``set_q(q)`` moves the robot, ``close()`` stops."""

    def __init__(
        self,
        robot,
        q=None,
        *,
        trajectory=None,
        host: str = "127.0.0.1",
        port: int = 8080,
        geometry: str = "visual",
        budget: int = DEFAULT_BUDGET,
        verbose: bool = True,
        allow_remote: bool = False,
    ):
        try:
            import viser
        except ImportError:
            raise ImportError("the live viewer needs viser: pip install 'kinedyn[viz]'") from None

        self.robot = robot
        self.trajectory = trajectory
        self.q = np.asarray(default_configuration(robot) if q is None else q, dtype=float).copy()
        if self.q.shape != (robot.nq,):
            raise ValueError(f"q needs {robot.nq} values for robot '{robot.name}', got shape {self.q.shape}")
        if trajectory is not None:
            tq = np.asarray(trajectory.q, dtype=float)
            if tq.ndim != 2 or tq.shape[1] != robot.nq:
                raise ValueError(f"the trajectory's q must have shape (N, {robot.nq}), got {tq.shape}")
        self.scene = robot_scene(robot, geometry, budget)
        # host and port checked (and a free port found) before viser's thread starts, and each handshake
        # checked for a loopback Host and the viewer's own Origin (kinedyn.visual.serving)
        address = listen_address(host, port)
        exposure = address.exposure()
        if exposure is not None:
            warnings.warn(exposure, stacklevel=2)
        with guarded_viser(HandshakeGuard(beyond_loopback=not address.loopback, allow_remote=allow_remote)) as state:
            # viser prints its own panel of URLs (``http://:PORT`` for host ""); the viewer prints the right one
            with contextlib.redirect_stdout(io.StringIO()):
                self.server = viser.ViserServer(host=host, port=address.port, verbose=False)
        if not state["guarded"]:  # a viser that builds its server otherwise: refuse to serve unchecked
            self.server.stop()
            raise RuntimeError(
                f"the live viewer could not install its handshake check in viser {viser.__version__}; "
                "please report it (docs/viewer-security.md)"
            )
        self.address = dataclasses.replace(address, port=self.server.get_port())
        self.url = self.address.url
        # viser's share button opens a public tunnel to the viewer: not from a viewer that answers only this machine
        self.server.gui.configure_theme(show_share_button=False)
        poses = robot.frame_poses(self.q)
        reach = max(float(np.max(np.linalg.norm(poses[:, :3, 3], axis=-1))), 0.05)
        self._reach = reach
        self._frame_index = {name: k for k, name in enumerate(robot.frame_names)}
        self._frames: dict = {}
        self._lock = threading.Lock()
        self._playing = False
        scene = self.server.scene
        scene.set_up_direction(np.asarray(self._up(), dtype=float))
        scene.add_frame("/base_axes", axes_length=0.25 * reach, axes_radius=0.006 * reach)
        up = self._up()
        if abs(up[2]) > 0.99:  # a floor grid through the base, perpendicular to "up"
            scene.add_grid(
                "/grid",
                width=2.4 * reach,
                height=2.4 * reach,
                cell_size=reach / 5,
                section_size=reach,
                position=(0.0, 0.0, 0.0),
            )
        lo, hi = scene_bounds(robot, self.scene, self.q)  # look at the robot as it stands at q
        look = (lo + hi) / 2
        view_from = np.asarray(_view_direction(robot, self.q, up), dtype=float)
        camera = self.server.initial_camera
        camera.look_at = tuple(look)
        camera.position = tuple(look + 0.95 * float(np.linalg.norm(hi - lo)) * view_from / np.linalg.norm(view_from))
        camera.up = tuple(up)
        self._mesh_handles: list[Any] = []
        for k, name in enumerate(self.scene.frames):
            self._frames[name] = scene.add_frame(f"/robot/f{k}", show_axes=False)
        for m, sp in enumerate(self.scene.parts):
            frame = self.scene.frames.index(sp.frame)
            rgba = sp.part.rgba or (0.7, 0.7, 0.7, 1.0)
            self._mesh_handles.append(
                scene.add_mesh_simple(
                    f"/robot/f{frame}/mesh{m}",
                    np.asarray(sp.part.vertices, dtype=np.float32),
                    np.asarray(sp.part.faces, dtype=np.uint32),
                    color=np.round(255 * np.asarray(rgba[:3], dtype=float)).astype(np.uint8),
                    opacity=None if rgba[3] >= 1 else float(rgba[3]),
                    side="double",
                )
            )
        self._tool = scene.add_frame("/tool", axes_length=0.12 * reach, axes_radius=0.005 * reach)
        self._stick = scene.add_line_segments(
            "/stick", self._stick_points(self.q), (55, 71, 79), thickness=3.0, thickness_units="screen"
        )
        self._gui(robot)
        self.set_q(self.q)
        if verbose:
            print(
                f"kinedyn viewer of '{robot.name}': {self.url}  (over ssh: ssh -L {self.server.get_port()}:localhost:{self.server.get_port()} HOST)",
                flush=True,
            )

    # ------------------------------------------------------------------ drawing
    def _up(self) -> np.ndarray:
        g = np.asarray(self.robot.gravity, dtype=float)
        return -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])

    def _stick_points(self, q) -> np.ndarray:
        tree = self.robot.tree
        bodies = self.robot.forward_kinematics(q)
        poses = self.robot.frame_poses(q)
        segments = []
        for i, b in enumerate(tree.bodies):
            start = np.zeros(3) if b.parent < 0 else bodies[b.parent][:3, 3]
            segments.append([start, bodies[i][:3, 3]])
        for k, f in enumerate(tree.frames):
            if f.body >= 0:
                segments.append([bodies[f.body][:3, 3], poses[k][:3, 3]])
        return np.asarray(segments, dtype=np.float32).reshape(-1, 2, 3)

    def set_q(self, q) -> None:
        """Move the robot to ``q`` (and its sliders with it)."""
        q = np.asarray(q, dtype=float)
        if q.shape != (self.robot.nq,) or not np.all(np.isfinite(q)):
            raise ValueError(f"q needs {self.robot.nq} finite values, got {q!r}")
        with self._lock:
            self.q = q.copy()
            poses = self.robot.frame_poses(q)
            with self.server.atomic():
                for name, handle in self._frames.items():
                    T = poses[self._frame_index[name]]
                    handle.wxyz = _wxyz(T[:3, :3])
                    handle.position = T[:3, 3]
                T = poses[self._frame_index[self.robot.tool]]
                self._tool.wxyz, self._tool.position = _wxyz(T[:3, :3]), T[:3, 3]
                self._stick.points = self._stick_points(q)
            for i, s in zip(self._slider_coordinates, self._sliders):
                value = float(q[i])
                if abs(s.value - value) > 1e-12:
                    self._quiet = True
                    try:
                        s.value = value
                    finally:
                        self._quiet = False

    # ------------------------------------------------------------------ controls
    def _gui(self, robot) -> None:
        gui = self.server.gui
        self._sliders: list[Any] = []
        self._slider_coordinates: list[int] = []  # the entry of q each slider moves
        self._quiet = False
        # a robot with closed loops, drawn closed: a slider per independent coordinate, the other
        # joints solved as it moves (kinedyn.visual.loops.LiveLoop); otherwise a slider per joint
        self._loop = None
        if getattr(robot, "loops", ()):
            try:
                if np.abs(robot.loop_residual(self.q)).max() < CLOSED:
                    self._loop = LiveLoop(robot, self.q)
            except ValueError:  # loops the core cannot hold (reduced mimic joints): a slider per joint
                self._loop = None
        with gui.add_folder("Joints"):
            start = 0
            for j in robot.joints:
                i, start = start, start + j.nq
                if self._loop is not None and j.name not in self._loop.joints:
                    continue
                if j.is_multi_dof:
                    # a quaternion or (cos, sin) block is no slider: it stays where q puts it
                    gui.add_markdown(f"{j.kind} joint `{j.name}`: held at q[{i}:{start}]")
                    continue
                span = math.pi if j.kind == "revolute" else self._reach
                lo = float(robot.lower_limits[i]) if math.isfinite(robot.lower_limits[i]) else -span
                hi = float(robot.upper_limits[i]) if math.isfinite(robot.upper_limits[i]) else span
                if hi <= lo:
                    lo, hi = lo - 1e-3, lo + 1e-3
                value = float(np.clip(self.q[i], lo, hi))
                slider = gui.add_slider(j.name, min=lo, max=hi, step=(hi - lo) / 1000, initial_value=value)
                slider.on_update(self._slider_moved(len(self._sliders), i))
                self._sliders.append(slider)
                self._slider_coordinates.append(i)
            if self._loop is not None:
                names = ", ".join(self._loop.joints) or "none"
                gui.add_markdown(
                    f"Closed loops: the sliders move the independent coordinates ({names}); the other joints are "
                    "solved as they move (project_configuration). A position the loops cannot close leaves the "
                    "robot where it was."
                )
            reset = gui.add_button("reset")
            start = self.q.copy()
            reset.on_click(lambda _: self.set_q(start))
        self._time: Any = None
        if self.trajectory is not None:
            t = np.asarray(self.trajectory.t, dtype=float)
            with gui.add_folder("Playback"):
                self._time = gui.add_slider(
                    "t [s]",
                    min=float(t[0]),
                    max=float(t[-1]),
                    step=float((t[-1] - t[0]) / max(len(t) - 1, 1)) or 1.0,
                    initial_value=float(t[0]),
                )
                time_slider = self._time
                time_slider.on_update(lambda _: None if self._quiet else self.show_time(time_slider.value))
                play = gui.add_button("play / pause")
                play.on_click(lambda _: self.play() if not self._playing else self.pause())

    def _slider_moved(self, k: int, i: int):
        """Slider k moves q[i]."""

        def moved(_event) -> None:
            if self._quiet:
                return
            q = self.q.copy()
            if self._loop is not None:  # the other joints follow, solved onto the loops
                closed = self._loop.move(q, k, float(self._sliders[k].value))
                self.set_q(q if closed is None else closed)  # unsolved: the robot (and its slider) stay
                return
            q[i] = float(self._sliders[k].value)
            self.set_q(q)

        return moved

    # ------------------------------------------------------------------ playback
    def show_time(self, t: float) -> None:
        """Show the trajectory's sample nearest before time ``t``."""
        if self.trajectory is None:
            raise ValueError("this viewer has no trajectory")
        ts = np.asarray(self.trajectory.t, dtype=float)
        k = int(np.clip(np.searchsorted(ts, t, side="right") - 1, 0, len(ts) - 1))
        self.set_q(np.asarray(self.trajectory.q, dtype=float)[k])

    def play(self, speed: float = 1.0) -> None:
        """Play the trajectory in real time (``speed`` x), in a background thread."""
        if self.trajectory is None:
            raise ValueError("this viewer has no trajectory")
        self._playing = True
        ts = np.asarray(self.trajectory.t, dtype=float)

        def run() -> None:
            start, wall = ts[0], time.monotonic()
            while self._playing:
                t = start + speed * (time.monotonic() - wall)
                if t > ts[-1]:
                    t = ts[-1]
                    self._playing = False
                self.show_time(t)
                if self._time is not None:
                    self._quiet = True
                    try:
                        self._time.value = float(min(t, ts[-1]))
                    finally:
                        self._quiet = False
                time.sleep(1 / 30)

        threading.Thread(target=run, daemon=True, name="kinedyn-viewer-playback").start()

    def pause(self) -> None:
        self._playing = False

    # ------------------------------------------------------------------ lifetime
    def wait(self) -> bool:
        """Block until Ctrl-C (what ``kinedyn view`` and a script's ``show()`` do), then stop; True
        when Ctrl-C ended it (``kinedyn view`` then exits 130)."""
        try:
            while True:
                time.sleep(0.5)
        except KeyboardInterrupt:
            interrupts.taken()  # Ctrl-C is how this ends: the close below is not interrupted again
            return True
        finally:
            self.close()

    def close(self) -> None:
        self._playing = False
        self.server.stop()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<kinedyn viewer of '{self.robot.name}' at {self.url}>"

    def _repr_html_(self) -> str:
        import html

        url = html.escape(self.url)
        return (
            f'<p>kinedyn viewer of {html.escape(self.robot.name)}: <a href="{url}" target="_blank">{url}</a></p>'
            f'<iframe src="{url}" width="100%" height="520" style="border: 1px solid #ccc"></iframe>'
        )


def show(robot, q=None, *, trajectory=None, block: bool | None = None, **kwargs) -> Viewer:
    """Open the viewer (see :class:`Viewer`); ``block``: wait until Ctrl-C (default: yes from a
    script, no in Jupyter or an interactive session)."""
    viewer = Viewer(robot, q, trajectory=trajectory, **kwargs)
    if block is None:
        block = not (_in_notebook() or hasattr(sys, "ps1") or sys.flags.interactive)
    if block:
        viewer.wait()
    return viewer
