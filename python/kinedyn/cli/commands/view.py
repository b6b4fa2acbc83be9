"""``kinedyn view ROBOT [--q ...]``: the live 3-D viewer (kinedyn.visual.viewer), until Ctrl-C."""

from __future__ import annotations

from ...visual.viewer import Viewer
from .. import app
from ..app import parse_q
from ..options import EXIT_INTERRUPTED, EXIT_OK, state_arguments


def add_arguments(p) -> None:
    p.add_argument(
        "robot", nargs="?", default=None, help="built-in name or robot file (default: planar_2r, the tutorial's arm)"
    )
    state_arguments(p)
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to listen on (default 127.0.0.1: this machine only; over ssh use ssh -L PORT:localhost:PORT)",
    )
    p.add_argument(
        "--port", type=int, default=8080, help="port (default 8080; the next free one if it is taken; 0: any free one)"
    )
    p.add_argument(
        "--allow-remote",
        action="store_true",
        help="answer requests that name the viewer by any host name, not only localhost (a reverse proxy); "
        "the page's WebSocket must still come from the viewer's own page (docs/viewer-security.md)",
    )
    p.add_argument("--collision", action="store_true", help="draw the collision shapes instead of the visual ones")
    p.add_argument("--no-wait", action="store_true", help="start the server, print its URL and stop (a check)")


def run(args) -> int:
    robot = app.robot(args)
    q = None if args.q is None else parse_q(args.q, robot, args.deg)
    viewer = Viewer(
        robot,
        q,
        host=args.host,
        port=args.port,
        geometry="collision" if args.collision else "visual",
        allow_remote=args.allow_remote,
    )
    if args.no_wait:  # for tests and scripts that only want the server checked
        viewer.close()
        return 0
    print("Ctrl-C stops the viewer.", flush=True)
    return EXIT_INTERRUPTED if viewer.wait() else EXIT_OK
