"""The content handle of a point set, computed on the client as the server computes it.

A SHA-256 tree over the coordinates as sent (little-endian doubles x0, y0, x1, ...), cut into
1 MiB leaves; each leaf's digest is SHA-256 of a zero byte and the leaf; the handle is SHA-256 of
the tag "galpha.v2.points" with its NUL, the byte count (little-endian uint64) and the leaf
digests, written "sha256-" + 64 hex digits (proto/galpha/v1/alpha_shapes.proto, BuildResponse).
Knowing the handle before uploading lets the client skip the upload of a set the server holds.
"""

from __future__ import annotations

import concurrent.futures
import hashlib
import os
import struct

import numpy as np

LEAF_BYTES = 1 << 20
_TAG = b"galpha.v2.points\x00"


def _leaf_digest(view: memoryview) -> bytes:
    h = hashlib.sha256(b"\x00")
    h.update(view)  # hashlib releases the GIL for large buffers, so leaves hash in parallel
    return h.digest()


def point_set_handle(points: np.ndarray) -> str:
    """The handle of an (N, 2) float64 C-contiguous array (little-endian on every supported host)."""
    data = memoryview(np.ascontiguousarray(points, dtype="<f8")).cast("B")
    total = len(data)
    leaves = [data[i : i + LEAF_BYTES] for i in range(0, total, LEAF_BYTES)]
    if len(leaves) > 1:
        workers = min(len(leaves), os.cpu_count() or 1)
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            digests = list(pool.map(_leaf_digest, leaves))
    else:
        digests = [_leaf_digest(leaf) for leaf in leaves]
    root = hashlib.sha256(_TAG + struct.pack("<Q", total) + b"".join(digests))
    return "sha256-" + root.hexdigest()
