"""A small RFC 2217 server in front of a pty pair, built on pyserial's own server side (``serial.rfc2217.PortManager``).

lagsym's ``rfc2217://`` client talks real RFC 2217 to it; the server passes
the data to the near end of a pty pair, whose far end the simulated control
holds.  A pty has no modem lines, so the server reports the CTS, DSR and DCD
the test sets on :attr:`Rfc2217Server.lines`, as a serial server would
report its port's.
"""

from __future__ import annotations

import socket
import termios
import threading
import time

import serial
import serial.rfc2217

__all__ = ["Rfc2217Server"]


class _Lines:
    """The server's serial port: data to the pty, modem lines from the test, control lines ignored."""

    _SIGNALS = ("cts", "dsr", "cd", "ri")

    def __init__(self, ser):
        object.__setattr__(self, "_ser", ser)
        for name in self._SIGNALS:
            object.__setattr__(self, name, name != "ri")

    def __getattr__(self, name):
        return getattr(self._ser, name)

    def __setattr__(self, name, value):
        if name in self._SIGNALS:
            object.__setattr__(self, name, value)
        elif name in ("rts", "dtr", "break_condition"):
            pass  # a pty has no control lines to set
        else:
            try:
                setattr(self._ser, name, value)
            except termios.error:
                pass  # a character format the pty cannot take one at a time; a pty carries bytes regardless


class _Connection:
    def __init__(self, sock):
        self.sock = sock

    def write(self, data: bytes) -> None:
        self.sock.sendall(data)


class Rfc2217Server:
    """Serve the pty end ``device`` as ``rfc2217://127.0.0.1:PORT`` (:attr:`url`) to one client at a time."""

    def __init__(self, device: str):
        self.lines = _Lines(serial.Serial(device, timeout=0.02))
        self._listener = socket.socket()
        self._listener.bind(("127.0.0.1", 0))
        self._listener.listen(1)
        self.url = f"rfc2217://127.0.0.1:{self._listener.getsockname()[1]}"
        self._stop = threading.Event()
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._listener.accept()
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            manager = serial.rfc2217.PortManager(self.lines, _Connection(conn))
            done = threading.Event()
            reader = threading.Thread(target=self._to_client, args=(conn, manager, done), daemon=True)
            reader.start()
            try:
                while not self._stop.is_set():
                    data = conn.recv(4096)
                    if not data:
                        break
                    self.lines.write(b"".join(manager.filter(data)))
            except OSError:
                pass
            done.set()
            reader.join(2)
            conn.close()

    def _to_client(self, conn, manager, done) -> None:
        last_check = 0.0
        while not done.is_set():
            try:
                data = self.lines.read(4096)
                if data:
                    conn.sendall(b"".join(manager.escape(data)))
                if time.monotonic() - last_check > 0.05:
                    manager.check_modem_lines()
                    last_check = time.monotonic()
            except OSError:
                return

    def close(self) -> None:
        self._stop.set()
        self._listener.close()
        self.lines.close()
