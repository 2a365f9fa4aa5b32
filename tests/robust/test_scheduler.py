"""``--scheduler`` fails fast (cell.experiments.sweep.cluster): one line, exit 2, no output folder.

Fake schedulers are loopback listeners (127.0.0.1 only), listening before the test connects
(no race): one that accepts and never answers, one that answers junk, one that sends a
frame header and then nothing, one that hangs up.  A real (in-process) scheduler that goes
away mid-sweep gives one line, and ``--resume`` then finishes the sweep with the numbers a
local run gives.
"""

from __future__ import annotations

import importlib.util
import socket
import struct
import threading
import time

import pytest

from cell.cli.main import main
from cell.experiments.sweep import cluster
from cell.scenario import catalog

pytest.importorskip("distributed")


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "sweep.yaml"
    path.write_text(f"base: {catalog.path('baseline')}\nset: {{run.parts: 20}}\n"
                    "replications: 2\nseed: 1\n")
    return path


def _listener(reply):
    """A loopback listener, listening on return; ``reply(conn)`` on each connection."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    kept = []

    def serve():
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            kept.append(conn)
            reply(conn)

    threading.Thread(target=serve, daemon=True).start()
    return server, kept


@pytest.fixture
def fake(monkeypatch):
    monkeypatch.setattr(cluster, "PROBE_TIMEOUT_S", 0.5)
    made = []

    def start(reply):
        server, kept = _listener(reply)
        made.append((server, kept))
        return f"tcp://127.0.0.1:{server.getsockname()[1]}"

    yield start
    for server, kept in made:
        server.close()
        for conn in kept:
            conn.close()


def _sweep(sweep_file, address, capsys):
    out = sweep_file.parent / "out"
    started = time.monotonic()
    code = main(["sweep", str(sweep_file), "--out", str(out), "--scheduler", address])
    took = time.monotonic() - started
    err = capsys.readouterr().err.splitlines()
    return code, err, out, took


REPLIES = {
    "accepts and never answers": (lambda c: None, "sent no dask handshake within 0.5 s"),
    "answers junk": (lambda c: c.sendall(b"HTTP/1.0 200 OK\r\n\r\n" * 20),
                     "answered, but not as a dask scheduler does"),
    "a frame header, then nothing": (lambda c: c.sendall(struct.pack("<Q", 200)),
                                     "sent no dask handshake within 0.5 s"),
    "hangs up at once": (lambda c: c.close(), "closed the connection before its handshake"),
}


@pytest.mark.parametrize("kind", REPLIES)
def test_a_fake_scheduler_is_one_line_in_bounded_time(fake, sweep_file, capsys, kind):
    reply, says = REPLIES[kind]
    address = fake(reply)
    code, err, out, took = _sweep(sweep_file, address, capsys)
    assert code == 2
    assert err[-1] == f"cell: error: --scheduler {address}: " + err[-1].split(": ", 3)[-1]
    assert says in err[-1] and len(err) == 2  # "connecting to ...", then the error
    assert not out.exists()
    started = time.monotonic()  # the bound: the probe's connection and two reads at most
    with pytest.raises(cluster.CellError, match=says):
        cluster.connect(address)
    # three probe timeouts, with room for a loaded machine (a hang would be dask's own 20 s+)
    assert time.monotonic() - started < 3 * 0.5 + 4


def test_nothing_listening_is_refused_at_once(sweep_file, capsys):
    free = socket.socket()
    free.bind(("127.0.0.1", 0))  # bound, never listening: a port nobody answers on
    port = free.getsockname()[1]
    try:
        code, err, out, took = _sweep(sweep_file, f"127.0.0.1:{port}", capsys)
    finally:
        free.close()
    assert code == 2 and err[-1].endswith("(connection refused)") and f":{port}" in err[-1]
    assert not out.exists()


@pytest.mark.parametrize("address,says", [
    ("tls://127.0.0.1:1", "tls:// needs TLS certificates"),
    ("ucx://127.0.0.1:1", "ucx:// needs ucx-py"),
    ("foo://127.0.0.1:1", "unknown address scheme 'foo'"),
    ("127.0.0.1", "not a scheduler address"),
    ("", "empty address"),
])
def test_what_cannot_work_here_is_refused_before_connecting(sweep_file, capsys, address, says,
                                                             monkeypatch):
    if address.startswith("ucx") and importlib.util.find_spec("ucp"):
        pytest.skip("ucx-py is installed here")
    monkeypatch.setattr(socket, "create_connection", None)  # never gets as far as a socket
    code, err, out, _ = _sweep(sweep_file, address, capsys)
    assert code == 2 and says in err[-1] and err[-1].startswith(f"cell: error: --scheduler {address}")
    assert not out.exists()


def test_a_scheduler_that_goes_away_mid_sweep_is_one_line_and_resume_finishes(
        tmp_path, capsys, monkeypatch):
    import distributed

    from tests.robust import midsweep

    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {catalog.path('baseline')}\n"
                     "grid: {run.parts: [20, 21, 22, 23]}\nreplications: 2\nseed: 1\n")
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", midsweep.replicate)
    midsweep.reset(stop_after=2)
    out = tmp_path / "out"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as lc:
        def close_when_told():
            midsweep.STARTED.wait(120)
            deadline = time.monotonic() + 120  # the first task on disk, however loaded the machine
            while not any((out / "tasks").glob("*")) and time.monotonic() < deadline:
                time.sleep(0.05)
            midsweep.CLOSING.set()
            lc.close()
        threading.Thread(target=close_when_told, daemon=True).start()
        code = main(["sweep", str(sweep), "--out", str(out), "--scheduler",
                     lc.scheduler_address])
    err = capsys.readouterr().err.splitlines()
    assert code == 2, err
    assert err[-1].startswith("cell: error: --scheduler ")
    assert "the scheduler went away during the sweep" in err[-1] and "--resume" in err[-1]
    kept = sorted(p.name for p in (out / "tasks").iterdir())
    assert 1 <= len(kept) < 4 and not (out / "replications.csv").exists()
    midsweep.reset(stop_after=None)
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "1", "--resume"]) == 0
    assert main(["sweep", str(sweep), "--out", str(tmp_path / "local"), "--workers", "1"]) == 0
    assert ((out / "replications.csv").read_bytes()
            == (tmp_path / "local" / "replications.csv").read_bytes())
