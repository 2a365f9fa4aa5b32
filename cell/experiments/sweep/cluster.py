"""Reaching a dask scheduler (``--scheduler``), failing fast and in one line.

:func:`connect` gives a ``distributed.Client`` or raises :class:`~cell.plumbing.errors.CellError`
within a bounded time (:data:`CONNECT_TIMEOUT_S`, plus a few seconds at most), whatever is
at the address:

* an address dask cannot parse, or a scheme it does not know, at once;
* ``tls://`` (``wss://``) without the certificates dask's configuration must name, and
  ``ucx://`` without ucx-py installed, at once: what is missing is named;
* nothing listening (connection refused), at once; no answer to the connection at all (a
  filtered port), after :data:`PROBE_TIMEOUT_S`;
* a listener that accepts and then says nothing, or not what a dask scheduler says first
  (its handshake: a small message in dask's framing), or stops half-way, after at most
  :data:`PROBE_TIMEOUT_S`: a plain-TCP scheduler is probed with a socket of our own before
  dask connects, so junk never reaches dask's reader (which would take a junk length for
  the size of a buffer to allocate);
* and anything else dask itself raises or waits for, after :data:`CONNECT_TIMEOUT_S`.

:func:`lost` turns the error a sweep meets when the scheduler goes away mid-run into one
line that says how to finish it (``--resume``).
"""

from __future__ import annotations

import importlib.util
import logging
import socket
import struct
import threading
from typing import Any

from cell.plumbing.errors import CellError, one_line

#: Seconds dask gets to connect to a scheduler that answered the probe.
CONNECT_TIMEOUT_S = 10.0
#: Seconds a listener gets to accept the probe and to send its first message.
PROBE_TIMEOUT_S = 5.0
#: A scheduler's first message (its handshake) is a few hundred bytes; more than this is junk.
HANDSHAKE_MAX_BYTES = 1 << 20
#: Its frames: a handful.
HANDSHAKE_MAX_FRAMES = 64


def _refuse(address: str, why: str) -> CellError:
    return CellError(f"--scheduler {address}: {one_line(why, 300)}")


def parse(address: str) -> tuple[str, str]:
    """(scheme, host:port) of a scheduler address (``host:port`` is ``tcp://``)."""
    from distributed.comm.addressing import parse_address

    if not address.strip():
        raise _refuse(address, "empty address")
    try:
        scheme, location = parse_address(address)
    except (ValueError, TypeError) as exc:
        raise _refuse(address, f"not a scheduler address ({exc})") from None
    return scheme, location


def _needs(address: str, scheme: str) -> None:
    """Refuse at once a scheme whose needs are not met (certificates, a library)."""
    if scheme in ("tls", "wss"):
        import dask

        conf = dask.config.get("distributed.comm.tls", default={}) or {}
        client = conf.get("client", {}) or {}
        if not (conf.get("ca-file") and client.get("cert")):
            raise _refuse(address, f"{scheme}:// needs TLS certificates: set dask's "
                                   "distributed.comm.tls.ca-file and "
                                   "distributed.comm.tls.client.cert (and .key), e.g. in "
                                   "~/.config/dask/distributed.yaml")
    elif scheme == "ucx":
        if not any(importlib.util.find_spec(m) for m in ("ucp", "distributed_ucxx")):
            raise _refuse(address, "ucx:// needs ucx-py (or distributed-ucxx), "
                                   "which is not installed")
    elif scheme not in ("tcp", "ws", "inproc"):  # inproc: a scheduler in this process
        raise _refuse(address, f"unknown address scheme {scheme!r}")


def _host_port(address: str, location: str) -> tuple[str, int]:
    from distributed.comm.addressing import parse_host_port

    try:
        host, port = parse_host_port(location)
    except (ValueError, TypeError) as exc:
        raise _refuse(address, f"not a scheduler address ({exc})") from None
    return host, int(port)


def _read(sock: socket.socket, n: int) -> bytes:
    data = bytearray()
    while len(data) < n:
        chunk = sock.recv(min(n - len(data), 65536))
        if not chunk:
            raise ConnectionResetError("closed the connection")
        data += chunk
    return bytes(data)


def probe(address: str, host: str, port: int, timeout_s: float | None = None) -> None:
    """Refuse unless a dask scheduler's first message comes from ``host:port`` in time
    (see the module): connected, one length (8 bytes, little-endian) of a small message,
    the message, which starts with its frame count and the frames' lengths."""
    timeout_s = PROBE_TIMEOUT_S if timeout_s is None else timeout_s
    try:
        sock = socket.create_connection((host, port), timeout=timeout_s)
    except ConnectionRefusedError:
        raise _refuse(address, "nothing listens there (connection refused)") from None
    except TimeoutError:
        raise _refuse(address, f"no answer to a connection within {timeout_s:g} s") from None
    except OSError as exc:
        raise _refuse(address, f"cannot connect ({exc.strerror or exc})") from None
    with sock:
        sock.settimeout(timeout_s)  # each read; the whole message is at most a few reads
        try:
            (size,) = struct.unpack("<Q", _read(sock, 8))
            if not 16 <= size <= HANDSHAKE_MAX_BYTES:
                raise ValueError
            message = _read(sock, size)
            (frames,) = struct.unpack_from("<Q", message)
            if not 1 <= frames <= HANDSHAKE_MAX_FRAMES or 8 + 8 * frames > size:
                raise ValueError
        except TimeoutError:
            raise _refuse(address, "accepted the connection but sent no dask handshake "
                                   f"within {timeout_s:g} s (not a dask scheduler?)") from None
        except (ValueError, struct.error):
            raise _refuse(address, "answered, but not as a dask scheduler does") from None
        except OSError as exc:
            why = f" ({exc.strerror})" if exc.strerror else ""
            raise _refuse(address, f"closed the connection before its handshake{why}") from None


def connect(address: str, timeout_s: float | None = None) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address``, or a one-line
    :class:`CellError` within about ``timeout_s`` (default :data:`CONNECT_TIMEOUT_S`) +
    :data:`PROBE_TIMEOUT_S` seconds."""
    timeout_s = CONNECT_TIMEOUT_S if timeout_s is None else timeout_s
    try:
        import distributed
    except ImportError:
        raise CellError("--scheduler needs dask.distributed: pip install 'cell[dist]'") from None
    scheme, location = parse(address)
    _needs(address, scheme)
    if scheme == "tcp":
        probe(address, *_host_port(address, location))
    got: dict[str, Any] = {}

    def attempt() -> None:
        try:
            got["client"] = distributed.Client(address, timeout=timeout_s)
        except BaseException as exc:  # noqa: BLE001 - reported by the caller's thread
            got["error"] = exc

    thread = threading.Thread(target=attempt, daemon=True, name="cell-connect")
    thread.start()
    thread.join(timeout_s + 2.0)
    if "client" in got:
        # dask's own log lines (a scheduler gone away logs tracebacks): critical ones only,
        # as the sweep says in one line what happened (:func:`lost`)
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        return got["client"]
    exc = got.get("error")
    if exc is None:
        raise _refuse(address, f"the scheduler did not let us connect within {timeout_s:g} s")
    if isinstance(exc, KeyboardInterrupt):
        raise exc
    raise _refuse(address, f"cannot reach the dask scheduler ({type(exc).__name__}: "
                           f"{exc})") from None


def lost(address: str, exc: BaseException, out: object, client: Any = None) -> CellError | None:
    """The one line for a sweep whose scheduler went away (``exc``, what the sweep met),
    or None if ``exc`` is not that.  With the ``client``: whatever error the sweep met once it
    is no longer connected (dask's own bookkeeping can fail in any way as the scheduler goes:
    a ValueError in its futures was seen) counts as the scheduler gone."""
    import concurrent.futures as cf

    names = {c.__name__ for c in type(exc).__mro__}
    gone = (client is not None and isinstance(exc, Exception) and not isinstance(exc, CellError)
            and getattr(client, "status", "running") != "running")
    if not (gone or isinstance(exc, (cf.CancelledError, OSError, TimeoutError))
            or names & {"CommClosedError", "FutureCancelledError", "CancelledError"}):
        return None
    return CellError(f"--scheduler {address}: the scheduler went away during the sweep "
                     f"({type(exc).__name__}); its finished tasks are kept in {out}: the same "
                     "command with --resume runs only the rest")
