"""The configuration of ``lagsym dnc serve``: a TOML file of ports, each with its profile and folders.

Every key is checked: an unknown key is refused with the keys that are
valid, a bad value with the key that holds it, in one line.
"""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass, fields, replace
from pathlib import Path

from ..errors import InputError, LagsymError
from ..io.files import path_problem, read_bytes
from ..io.tomltext import check_toml_depth
from .settings import LineSettings, check_port, profile

__all__ = ["PortConfig", "ServerConfig", "load_config", "MAX_CONFIG_BYTES"]

MAX_CONFIG_BYTES = 1024 * 1024  # a configuration of many ports is a few kilobytes

_LINE_KEYS = {f.name for f in fields(LineSettings)}


@dataclass(frozen=True)
class PortConfig:
    """One port the server listens on.

    Attributes
    ----------
    name : str
        For the log and the status line.
    device : str
        The port, as ``lagsym send --port`` takes it.
    settings : LineSettings
        The profile with the table's ``[port.line]`` overrides.
    programs, received : Path
        The folder of programs to serve, the folder punched programs go to.
    request_upload, request_drip : int or None
        Program numbers that ask for a program to be uploaded or drip-fed.
    request_delay_s : float
        Wait after a request, so the operator can switch the control to read.
    log : Path
        This port's log file (default: ``NAME.log`` beside the configuration).
    max_punch_bytes : int
        The longest punch kept as a program; a longer one is cut off and
        kept in the ``failed`` folder (every punch streams to disk as it
        arrives, so this bounds the disk a runaway punch takes, and memory).
    """

    name: str
    device: str
    settings: LineSettings
    programs: Path
    received: Path
    request_upload: int | None = 9999
    request_drip: int | None = 9998
    request_delay_s: float = 5.0
    log: Path | None = None
    max_punch_bytes: int = 16 * 1024 * 1024


@dataclass(frozen=True)
class ServerConfig:
    """The ports of one server, and the file they came from."""

    ports: tuple[PortConfig, ...]
    source: str


_PORT_KEYS = ("name", "device", "profile", "programs", "received", "request_upload", "request_drip",
              "request_delay_s", "log", "max_punch_bytes", "line")


def _bad(source: str, key: str, why: str) -> InputError:
    return InputError(f"{source}: {key}: {why}")


def _port(source: str, index: int, table, base: Path) -> PortConfig:
    where = f"port[{index}]"
    if not isinstance(table, dict):
        raise _bad(source, where, "must be a table ([[port]])")
    for key in table:
        if key not in _PORT_KEYS:
            raise _bad(source, f"{where}.{key}", f"unknown key; the keys are {', '.join(_PORT_KEYS)}")
    for key in ("name", "device", "programs", "received"):
        if not isinstance(table.get(key), str) or not table[key]:
            raise _bad(source, f"{where}.{key}", "is required, as a string")
    check_port(table["device"], f"{source}: {where}.device")
    line = table.get("line", {})
    if not isinstance(line, dict):
        raise _bad(source, f"{where}.line", "must be a table of line settings")
    for key in line:
        if key not in _LINE_KEYS:
            raise _bad(source, f"{where}.line.{key}", f"unknown key; the keys are {', '.join(sorted(_LINE_KEYS))}")
    try:
        settings = profile(table.get("profile", "fanuc"))
        settings = replace(settings, **line)
    except (LagsymError, TypeError) as e:
        raise _bad(source, f"{where}.{'line' if line else 'profile'}", str(e)) from None
    numbers = {}
    for key in ("request_upload", "request_drip"):
        value = table.get(key, PortConfig.__dataclass_fields__[key].default)
        if value is not None and (not isinstance(value, int) or isinstance(value, bool) or not 1 <= value <= 99999):
            raise _bad(source, f"{where}.{key}", f"{value!r} must be a program number from 1 to 99999")
        numbers[key] = value
    delay = table.get("request_delay_s", 5.0)
    if isinstance(delay, bool) or not isinstance(delay, (int, float)) or not 0 <= delay <= 3600:
        raise _bad(source, f"{where}.request_delay_s", f"{delay!r} must be 0 to 3600 seconds")
    programs, received = base / table["programs"], base / table["received"]
    try:
        folder = programs.is_dir()
    except OSError as e:  # a path over the system's limit
        raise _bad(source, f"{where}.programs", f"{programs}: {path_problem(e) or e.strerror or e}") from None
    if not folder:
        raise _bad(source, f"{where}.programs", f"{programs} is not a folder")
    limit = table.get("max_punch_bytes", PortConfig.max_punch_bytes)
    if isinstance(limit, bool) or not isinstance(limit, int) or not 1 <= limit <= 2**40:
        raise _bad(source, f"{where}.max_punch_bytes", f"{limit!r} must be a whole number of bytes from 1 to 2**40")
    log = table.get("log")
    if log is not None and not isinstance(log, str):
        raise _bad(source, f"{where}.log", "must be a file name")
    return PortConfig(table["name"], table["device"], settings, programs, received, numbers["request_upload"],
                      numbers["request_drip"], float(delay), base / (log or f"{table['name']}.log"), limit)


def load_config(path: str | Path) -> ServerConfig:
    """Read and check a server configuration; relative folders are relative to the file.

    Raises
    ------
    InputError
        Naming the file and the key, for a file that cannot be read, is not
        TOML, holds an unknown key or a bad value.
    """
    source = str(path)
    raw = read_bytes(path, "a DNC configuration", MAX_CONFIG_BYTES)  # a regular file, within a limit: never /dev/zero
    try:
        text = raw.decode("utf-8")
        check_toml_depth(text, source, "a configuration")
        data = tomllib.loads(text)
    except UnicodeDecodeError as e:
        raise InputError(f"{source}: not UTF-8 text (byte {e.start}); a configuration is a TOML text file") from None
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{source}: not TOML: {e}") from None
    except RecursionError:
        raise InputError(f"{source}: not a configuration: arrays or tables nested too deep to read") from None
    for key in data:
        if key != "port":
            raise _bad(source, key, "unknown key; the keys are port")
    tables = data.get("port")
    if not isinstance(tables, list) or not tables:
        raise _bad(source, "port", "at least one [[port]] table is required")
    base = Path(path).resolve().parent
    ports = tuple(_port(source, i, t, base) for i, t in enumerate(tables))
    for key in ("name", "device"):
        seen = [getattr(p, key) for p in ports]
        dup = next((v for v in seen if seen.count(v) > 1), None)
        if dup is not None:
            raise _bad(source, f"port.{key}", f"{dup!r} is given twice")
    _check_logs(source, _real(Path(path)), ports)
    return ServerConfig(ports, source)


# The names the server serves a program by and saves a punch as (server.py): 1234.nc, O1234, 1234.txt, 3002.nc,
# 3002.received-2.nc, unnumbered.nc.
_PROGRAM_NAME = re.compile(r"O?\d+(\.nc|\.txt)?|(\d+|unnumbered)(\.received-\d+)?\.nc")


def _real(path: Path) -> Path:
    """``path`` with its links followed where they can be (a loop of links stays as written)."""
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return Path(os.path.abspath(path))


def _check_logs(source: str, config: Path, ports: tuple[PortConfig, ...]) -> None:
    """Each port's log is a file of its own: not the configuration, a device, another port's log, or a file named as
    a program in a folder of programs (the server appends to it as it runs)."""
    owner: dict[Path, str] = {}
    for index, port in enumerate(ports):
        where, log = f"port[{index}].log", _real(port.log)
        if log == config:
            raise _bad(source, where, f"{port.log} is this configuration file")
        if log in owner:
            raise _bad(source, where, f"{port.log} is also port {owner[log]!r}'s log: give each port its own")
        for other in ports:
            if log == _real(Path(other.device)):
                raise _bad(source, where, f"{port.log} is port {other.name!r}'s device")
            for kind in ("programs", "received"):
                if log.parent == _real(getattr(other, kind)) and _PROGRAM_NAME.fullmatch(log.name):
                    raise _bad(source, where, f"{port.log} is named as a program in port {other.name!r}'s {kind} "
                                              f"folder: the server would serve it or save a punch there")
        owner[log] = port.name
