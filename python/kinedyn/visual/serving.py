"""Where the live viewer listens and whom it answers (docs/viewer-security.md).

The viewer is a viser server: one port serves the page (HTTP) and its WebSocket, through which the
page sees the robot and moves its joints. A browser lets any web page open a WebSocket to any address,
127.0.0.1 included, and sends the page's own origin with it; it leaves the answer to the server (RFC
6455, section 10.2). So, as Jupyter's and TensorBoard's servers do:

- **Host.** Every request must name the viewer by a loopback name in its ``Host`` header
  (``localhost``, ``*.localhost``, ``127.0.0.1``, ``[::1]``), or by an IP address when the viewer
  listens beyond loopback. A page that reaches the viewer by DNS rebinding (its own name, made to point
  at 127.0.0.1) sends its own name, and is refused.
- **Origin.** A WebSocket handshake that carries an ``Origin`` (every browser's does) must come from
  the viewer's own page: the origin's host and port are the request's ``Host``. A page elsewhere that
  opens ``ws://127.0.0.1:8080`` (cross-site WebSocket hijacking) is refused. A client that is not a
  browser sends no Origin and could open a plain TCP connection anyway; it is let through.

``allow_remote=True`` (``kinedyn view --allow-remote``) accepts any ``Host`` (the viewer behind a
name of its own, e.g. a reverse proxy); the Origin must still match it. The safe route to a remote
viewer stays an ssh tunnel, which keeps it on loopback.

The checks run in the WebSocket server's ``process_request`` hook, before the handshake is answered:
a refused request gets ``403 Forbidden`` and never reaches viser. viser builds its server inside
``ViserServer()``, so :func:`guarded_viser` hands websockets' ``serve`` a ``process_request`` that
checks first while that server is built, and refuses to return a viewer it could not guard.

:func:`listen_address` checks ``host`` and ``port`` before anything starts (a port outside 0-65535, a
name that does not resolve, an address this machine does not have, a port it may not use): each is a
ValueError naming the value, where the server's thread would otherwise fail and leave the caller
waiting forever.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import http
import ipaddress
import socket
import threading
from collections.abc import Iterator
from urllib.parse import urlsplit

__all__ = ["Address", "HandshakeGuard", "guarded_viser", "listen_address"]

PORT_TRIES = 100  # a busy port: the next ones are tried, as viser does


def _ip(text: str):
    try:
        return ipaddress.ip_address(text.split("%", 1)[0])
    except ValueError:
        return None


@dataclasses.dataclass(frozen=True)
class Address:
    """Where the viewer will listen: ``host`` as given, the free ``port`` found, whether every
    address it binds is a loopback one, and the URL to open."""

    host: str
    port: int
    loopback: bool
    everywhere: bool  # "" or a wildcard address: every interface of this machine

    @property
    def url(self) -> str:
        if self.loopback or self.everywhere:
            return f"http://localhost:{self.port}"
        ip = _ip(self.host)
        return (
            f"http://[{self.host}]:{self.port}"
            if ip is not None and ip.version == 6
            else f"http://{self.host}:{self.port}"
        )

    def exposure(self) -> str | None:
        """A line for the terminal when the viewer can be reached from other machines, else None."""
        if self.loopback:
            return None
        where = "every network interface of this machine" if self.everywhere else f"{self.host}"
        return (
            f"the viewer listens on {where} (port {self.port}): anyone who can reach it can see the robot and move "
            f"its joints; to see a remote robot, keep the default --host 127.0.0.1 and use ssh -L {self.port}:localhost:{self.port} HOST"
        )


def listen_address(host: str, port: int) -> Address:
    """``host`` and ``port`` checked and a free port found (``port`` or the next free one; 0: any free
    port), by binding each address ``host`` resolves to, as the server will. ValueError naming the
    value otherwise."""
    if not isinstance(host, str):
        raise ValueError(f"host must be a string (an address or a name), got {host!r}")
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ValueError(f"port must be a whole number from 0 to 65535 (0: any free port), got {port!r}")
    shown = host or '""'
    try:
        infos = socket.getaddrinfo(host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as e:
        raise ValueError(f"host {shown}: cannot resolve it ({getattr(e, 'strerror', None) or e})") from None
    addresses = list(dict.fromkeys((family, sockaddr[0]) for family, _, _, _, sockaddr in infos))
    ips = [_ip(str(a)) for _, a in addresses]
    loopback = all(ip is not None and ip.is_loopback for ip in ips)
    everywhere = not host or any(ip is not None and ip.is_unspecified for ip in ips)
    last: OSError | None = None
    for candidate in [port] if port == 0 else range(port, min(port + PORT_TRIES, 65536)):
        try:
            return Address(host, _bind_all(addresses, candidate), loopback, everywhere)
        except OSError as e:
            if e.errno != errno.EADDRINUSE:
                raise ValueError(f"cannot listen on {shown} port {candidate}: {e.strerror or e}") from None
            last = e
    raise ValueError(f"cannot listen on {shown}: ports {port} to {candidate} are all in use ({last})")


def _bind_all(addresses, port: int) -> int:
    """Bind every address on ``port`` at once (as asyncio's create_server does), then let go; the
    port bound (the one the system chose for 0)."""
    sockets: list[socket.socket] = []
    try:
        for family, address in addresses:
            s = socket.socket(family, socket.SOCK_STREAM)
            sockets.append(s)
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # asyncio's default on POSIX
            if family == socket.AF_INET6:
                s.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)  # as asyncio binds both families
            s.bind((address, port))
            if port == 0:
                port = s.getsockname()[1]
            s.listen(1)
        return port
    finally:
        for s in sockets:
            s.close()


def _split_host(value: str) -> tuple[str, int | None] | None:
    """``Host``/``Origin`` netloc as (lower-case name, port or None); None when malformed."""
    try:
        parts = urlsplit(f"//{value.strip()}")
        name, port = parts.hostname, parts.port
    except ValueError:
        return None
    if not name or parts.username is not None or parts.path or parts.query or parts.fragment:
        return None
    return name.rstrip(".").lower(), port


@dataclasses.dataclass(frozen=True)
class HandshakeGuard:
    """The viewer's rule for each request (module docstring): :meth:`refusal` is None or the reason."""

    beyond_loopback: bool = False  # the server listens on more than loopback addresses
    allow_remote: bool = False

    def host_allowed(self, name: str) -> bool:
        if self.allow_remote or name == "localhost" or name.endswith(".localhost"):
            return True
        ip = _ip(name)
        if ip is None:
            return False
        # an address cannot be rebound by DNS; beyond loopback, the machine's own addresses reach it
        return ip.is_loopback or self.beyond_loopback

    def refusal(self, headers) -> str | None:
        host = headers.get("Host")
        parsed = _split_host(host) if host else None
        if parsed is None:
            return "the request names no valid Host"
        if not self.host_allowed(parsed[0]):
            return (
                f"Host '{host}' is not this viewer's (it answers to localhost and loopback addresses; "
                "see docs/viewer-security.md for --allow-remote)"
            )
        if (headers.get("Upgrade") or "").lower() != "websocket":
            return None
        origin = headers.get("Origin")
        if origin is None:
            return None  # not a browser: it could open a TCP connection just the same
        try:
            o = urlsplit(origin)
            o_name, o_port = (o.hostname or "").rstrip(".").lower(), o.port
        except ValueError:
            return f"Origin '{origin}' is malformed"
        default = {"http": 80, "https": 443}.get(o.scheme)
        if default is None or not o_name:
            return f"Origin '{origin}' is not a web page of this viewer"
        if (o_name, o_port or default) != (parsed[0], parsed[1] or default):
            return f"Origin '{origin}' is not this viewer's page (http://{host})"
        return None

    def wrap(self, process_request):
        """viser's ``process_request`` with this check before it."""

        def checked(connection, request):
            why = self.refusal(request.headers)
            if why is not None:
                return connection.respond(http.HTTPStatus.FORBIDDEN, f"kinedyn viewer: refused: {why}\n")
            return None if process_request is None else process_request(connection, request)

        return checked


_CONSTRUCTION = threading.Lock()  # one guarded viser server built at a time


@contextlib.contextmanager
def guarded_viser(guard: HandshakeGuard) -> Iterator[dict]:
    """While the block builds a ``viser.ViserServer``, the WebSocket server viser starts gets
    ``guard``'s check in its ``process_request``; after the block, ``state["guarded"]`` says whether
    it did (the caller refuses a viewer that was not guarded, e.g. after a change in viser)."""
    import websockets.asyncio.server as ws_server  # viser's own dependency, loaded with the viewer

    state = {"guarded": False}
    plain = ws_server.serve

    class serve(plain):  # type: ignore[misc, valid-type]
        def __init__(self, handler, *args, process_request=None, **kwargs):
            if getattr(handler, "__module__", "").split(".")[0] == "viser":
                process_request = guard.wrap(process_request)
                state["guarded"] = True
            super().__init__(handler, *args, process_request=process_request, **kwargs)

    with _CONSTRUCTION:
        ws_server.serve = serve  # type: ignore[misc]
        try:
            yield state
        finally:
            ws_server.serve = plain  # type: ignore[misc]
