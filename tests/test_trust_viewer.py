"""The live viewer answers only its own page on this machine, and never blocks on a bad address
(issue 25, "The live viewer"; docs/viewer-security.md).

A real viewer is started on an ephemeral port and real WebSocket handshakes are made against it: a
foreign Origin (cross-site WebSocket hijacking), a foreign Host (DNS rebinding), a malformed one,
and the viewer's own page, which must still connect and receive the scene. Bad ports and hosts exit 1
with one line, within a timeout; Ctrl-C exits 130.
"""

from __future__ import annotations

import base64
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("kinedyn._core", reason="the native module is not built")
viser = pytest.importorskip("viser", reason="the live viewer needs viser (the viz extra)")
from websockets.exceptions import InvalidStatus  # noqa: E402
from websockets.sync.client import connect  # noqa: E402

import kinedyn as kd  # noqa: E402
from kinedyn.visual.serving import HandshakeGuard, listen_address  # noqa: E402

PROTOCOL = f"viser-v{viser.__version__}"


@pytest.fixture(scope="module")
def viewer():
    v = kd.robots.planar_2r().show(block=False, port=0, verbose=False)
    yield v
    v.close()


def handshake(port: int, host: str | None, origin: str | None, upgrade: bool = True) -> int:
    """The HTTP status a raw request to the viewer gets (101: a WebSocket was opened)."""
    lines = ["GET / HTTP/1.1"]
    if host is not None:
        lines.append(f"Host: {host}")
    if upgrade:
        key = base64.b64encode(os.urandom(16)).decode()
        lines += [
            "Upgrade: websocket",
            "Connection: Upgrade",
            f"Sec-WebSocket-Key: {key}",
            "Sec-WebSocket-Version: 13",
            f"Sec-WebSocket-Protocol: {PROTOCOL}",
        ]
    if origin is not None:
        lines.append(f"Origin: {origin}")
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        head = b""
        while b"\r\n" not in head:
            chunk = s.recv(4096)
            if not chunk:
                break
            head += chunk
    return int(head.split(b" ", 2)[1])


def test_the_viewers_own_page_connects_and_gets_the_scene(viewer):
    port = viewer.server.get_port()
    for name in ("localhost", "127.0.0.1"):
        with connect(
            f"ws://{name}:{port}", origin=f"http://{name}:{port}", subprotocols=[PROTOCOL], open_timeout=10
        ) as ws:
            assert ws.response.status_code == 101
            assert len(ws.recv(timeout=10)) > 0  # the scene's messages arrive
    assert handshake(port, f"[::1]:{port}", f"http://[::1]:{port}") == 101
    assert handshake(port, f"localhost:{port}", None) == 101  # not a browser: no Origin, nothing to check
    assert handshake(port, f"localhost:{port}", None, upgrade=False) == 200  # the page itself


def test_a_foreign_origin_is_refused(viewer):
    """Cross-site WebSocket hijacking: another page's script opens ws://127.0.0.1:PORT."""
    port = viewer.server.get_port()
    for origin in ("http://evil.example", f"http://evil.example:{port}", "null", f"http://127.0.0.1:{port + 1}"):
        with pytest.raises(InvalidStatus) as refused:
            with connect(f"ws://127.0.0.1:{port}", origin=origin, subprotocols=[PROTOCOL], open_timeout=10):
                pass
        assert refused.value.response.status_code == 403, origin
        assert b"Origin" in refused.value.response.body
    assert handshake(port, f"localhost:{port}", f"file://localhost:{port}") == 403


def test_a_foreign_host_is_refused(viewer):
    """DNS rebinding: a page at evil.example, its name made to point at 127.0.0.1, sends its own name."""
    port = viewer.server.get_port()
    for host in (f"evil.example:{port}", "evil.example", f"127.0.0.1.evil.example:{port}", f"10.0.0.1:{port}"):
        origin = f"http://{host}"
        assert handshake(port, host, origin) == 403, host
        assert handshake(port, host, None, upgrade=False) == 403, host  # the page is not served to it either
    assert handshake(port, None, None) == 403  # no Host: HTTP/1.1 requires one
    assert handshake(port, f"user@localhost:{port}", f"http://localhost:{port}") == 403


def test_allow_remote_accepts_any_host_but_only_its_own_page():
    v = kd.robots.planar_2r().show(block=False, port=0, verbose=False, allow_remote=True)
    try:
        port = v.server.get_port()
        assert handshake(port, f"viewer.example:{port}", f"http://viewer.example:{port}") == 101
        assert handshake(port, f"viewer.example:{port}", f"http://evil.example:{port}") == 403
    finally:
        v.close()


def test_the_guard_rules():
    g = HandshakeGuard()
    ok = {"Upgrade": "websocket"}
    assert g.refusal({**ok, "Host": "LOCALHOST.:8080", "Origin": "http://localhost:8080"}) is None
    assert g.refusal({**ok, "Host": "app.localhost:80", "Origin": "http://app.localhost"}) is None
    assert g.refusal({**ok, "Host": "127.0.0.2:9", "Origin": "http://127.0.0.2:9"}) is None
    assert "Origin" in g.refusal({**ok, "Host": "localhost:80", "Origin": "http://localhost:81"})
    assert "Host" in g.refusal({**ok, "Host": "192.168.1.5:8080", "Origin": "http://192.168.1.5:8080"})
    beyond = HandshakeGuard(beyond_loopback=True)  # listening on the network: the machine's addresses reach it
    assert beyond.refusal({**ok, "Host": "192.168.1.5:8080", "Origin": "http://192.168.1.5:8080"}) is None
    assert "Host" in beyond.refusal({**ok, "Host": "evil.example:8080", "Origin": "http://evil.example:8080"})


def test_listen_address_checks_before_anything_starts():
    for port in (70000, -1, True, 1.5):
        with pytest.raises(ValueError, match="port must be a whole number from 0 to 65535"):
            listen_address("127.0.0.1", port)
    with pytest.raises(ValueError, match="cannot listen on 8.8.8.8"):
        listen_address("8.8.8.8", 0)
    with pytest.raises(ValueError, match="cannot resolve"):
        listen_address("no-such-host.invalid", 0)
    a = listen_address("127.0.0.1", 0)
    assert a.loopback and a.port > 0 and a.exposure() is None and a.url == f"http://localhost:{a.port}"
    with socket.socket() as busy:  # a busy port: the next free one
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        taken = busy.getsockname()[1]
        assert listen_address("127.0.0.1", taken).port != taken
    everywhere = listen_address("", 0)
    assert not everywhere.loopback and everywhere.url.startswith("http://localhost:")
    assert "every network interface" in everywhere.exposure()


# ------------------------------------------------------------------ the command
def kinedyn(*argv, timeout=60):
    env = dict(os.environ, PYTHONPATH=str(Path(kd.__file__).parents[1]))
    return subprocess.run(
        [sys.executable, "-m", "kinedyn", *map(str, argv)], capture_output=True, text=True, env=env, timeout=timeout
    )


@pytest.mark.parametrize(
    "args, words",
    [
        (["--port", "70000"], "got 70000"),
        (["--port", "-1"], "got -1"),
        (["--host", "8.8.8.8"], "cannot listen on 8.8.8.8"),
        (["--host", "no-such-host.invalid"], "no-such-host.invalid: cannot resolve"),
    ],
)
def test_bad_ports_and_hosts_exit_1_with_one_line(args, words):
    done = kinedyn("view", "planar_2r", *args, timeout=60)  # before the fix: never returned
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinedyn view: error:") and words in lines[0], done.stderr


def test_listening_everywhere_says_so():
    done = kinedyn("view", "planar_2r", "--no-wait", "--host", "", "--port", "0")
    assert done.returncode == 0, done.stderr
    assert "http://:" not in done.stdout + done.stderr
    assert "every network interface" in done.stderr and "ssh -L" in done.stderr
    assert "http://localhost:" in done.stdout


def test_ctrl_c_exits_130():
    env = dict(os.environ, PYTHONPATH=str(Path(kd.__file__).parents[1]))
    proc = subprocess.Popen(
        [sys.executable, "-m", "kinedyn", "view", "planar_2r", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        deadline = time.monotonic() + 60
        line = ""
        while "Ctrl-C" not in line and time.monotonic() < deadline:
            line = proc.stdout.readline()
        assert "Ctrl-C" in line
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130 and "Traceback" not in err, err
