"""Point tables: CSV text (columns x,y,z) and NumPy ``.npy`` arrays of shape ``(N, 3)``, streamed.

Both writers take an iterable of :class:`~lagsym.sampling.Block` and write each
block as it comes, so memory stays at one block whatever the number of points.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import IO

import numpy as np

from ..sampling import Block

__all__ = ["CSV_HEADER", "write_csv", "write_npy", "npy_header"]

CSV_HEADER = "x,y,z"

Progress = Callable[[int], None]


def write_csv(stream: IO[str], blocks: Iterable[Block], progress: Progress | None = None) -> int:
    """Write the points of ``blocks`` as CSV lines ``x,y,z`` after a header; return the number of points.

    Numbers are written in the shortest form that reads back to the same
    float, so the file loses nothing; a sampled file is itself a valid
    points file for ``lagsym``.

    Examples
    --------
    >>> import io
    >>> from lagsym.sampling import Block
    >>> buf = io.StringIO()
    >>> write_csv(buf, [Block(0, np.array([0.1]), np.array([1.0, 2.0]), np.array([[3.0, 0.25]]))])
    2
    >>> print(buf.getvalue(), end="")
    x,y,z
    0.1,1.0,3.0
    0.1,2.0,0.25
    """
    stream.write(CSV_HEADER + "\n")
    ys_text = None
    done = 0
    for block in blocks:
        if ys_text is None:
            ys_text = [f",{v!r}," for v in block.ys.tolist()]
        for x, row in zip(block.xs.tolist(), block.z):
            xt = repr(x)
            stream.write("".join([f"{xt}{yt}{z!r}\n" for yt, z in zip(ys_text, row.tolist())]))
        done += block.z.size
        if progress is not None:
            progress(done)
    return done


def npy_header(rows: int) -> dict:
    """The ``.npy`` header of a little-endian float64 table of shape ``(rows, 3)``."""
    return {"descr": "<f8", "fortran_order": False, "shape": (rows, 3)}


def write_npy(stream: IO[bytes], blocks: Iterable[Block], rows: int, progress: Progress | None = None) -> int:
    """Write the points of ``blocks`` as one ``.npy`` array of shape ``(rows, 3)``, columns x, y, z.

    ``rows`` (the total number of points) goes into the header first; the
    blocks must add up to it.  Returns the number of points written.
    """
    np.lib.format.write_array_header_1_0(stream, npy_header(rows))
    done = 0
    buf = None
    for block in blocks:
        k = block.z.size
        if buf is None or buf.shape[0] < k:
            buf = np.empty((k, 3), dtype="<f8")
        out = buf[:k]
        ny = block.ys.size
        out[:, 0].reshape(-1, ny)[...] = block.xs[:, None]
        out[:, 1].reshape(-1, ny)[...] = block.ys[None, :]
        out[:, 2] = block.z.ravel()
        stream.write(memoryview(out).cast("B"))
        done += k
        if progress is not None:
            progress(done)
    if done != rows:
        raise ValueError(f"the blocks hold {done} points, the header says {rows}")
    return done
