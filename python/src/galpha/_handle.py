"""The content handle of a point set, computed on the client as the server computes it.

A SHA-256 tree over the coordinates as sent (little-endian doubles x0, y0, x1, ...), cut into
1 MiB leaves; each leaf's digest is SHA-256 of a zero byte and the leaf; the handle is SHA-256 of
the tag "galpha.v2.points" with its NUL, the byte count (little-endian uint64) and the leaf
digests, written "sha256-" + 64 hex digits (proto/galpha/v1/alpha_shapes.proto, BuildResponse).
Weighted points hash their triples (x0, y0, w0, x1, ...) under the tag "galpha.v2.weighted-points"
(core/io/point_set_handle.hpp, WeightedPointSetHandle). Knowing the handle before uploading lets
the client skip the upload of a set the server holds.
"""

from __future__ import annotations

import concurrent.futures
import hashlib
import os
import struct

import numpy as np

LEAF_BYTES = 1 << 20
_TAG = b"galpha.v2.points\x00"
_WEIGHTED_TAG = b"galpha.v2.weighted-points\x00"


def _leaf_digest(view: memoryview) -> bytes:
    h = hashlib.sha256(b"\x00")
    h.update(view)  # hashlib releases the GIL for large buffers, so leaves hash in parallel
    return h.digest()


def point_set_handle(points: np.ndarray) -> str:
    """The handle of an (N, 2) float64 array of points, or of an (N, 3) array of weighted points
    (x, y, w), as the server computes it."""
    array = np.ascontiguousarray(points, dtype="<f8")
    tag = _WEIGHTED_TAG if array.ndim == 2 and array.shape[1] == 3 else _TAG
    # Flat bytes (memoryview cannot cast an array with a zero in its shape: the empty set has no leaves).
    data = memoryview(array.reshape(-1)).cast("B") if array.size else memoryview(b"")
    total = len(data)
    leaves = [data[i : i + LEAF_BYTES] for i in range(0, total, LEAF_BYTES)]
    if len(leaves) > 1:
        workers = min(len(leaves), os.cpu_count() or 1)
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            digests = list(pool.map(_leaf_digest, leaves))
    else:
        digests = [_leaf_digest(leaf) for leaf in leaves]
    root = hashlib.sha256(tag + struct.pack("<Q", total) + b"".join(digests))
    return "sha256-" + root.hexdigest()
