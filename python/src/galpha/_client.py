"""The two clients behind one protocol: ``connect`` (a galpha server over gRPC) and ``local`` (the
embedded engine in this process, CUDA when there is a GPU, else the CPU's cores)."""

from __future__ import annotations

from typing import Any, Callable, List, Optional, Protocol, Union

import numpy as np


from ._encoding import check_encoding
from ._crs import frame_of
from ._errors import GalphaError, InvalidInput, error_for_code
from ._family import Family, weighted_rows
from ._points import as_points

#: ``progress``: None (quiet), True (a tqdm bar on standard error), or a callable receiving
#: (stage, fraction done in [0, 1]).
Progress = Union[None, bool, Callable[[str, float], None]]

#: Point sets below this size get no bar even with progress=True (they take milliseconds).
PROGRESS_BAR_MIN_POINTS = 100_000


class Client(Protocol):
    def build(
        self,
        points: Any,
        *,
        name: str = "",
        progress: Progress = None,
        encoding: str = "auto",
        crs: Any = None,
        weights: Any = None,
    ) -> Family: ...

    def close(self) -> None: ...

    def __enter__(self) -> "Client": ...

    def __exit__(self, *exc: Any) -> None: ...


def checked_weights(weights: Any, array: np.ndarray, frame: Any) -> Optional[np.ndarray]:
    """``weights`` as a (N,) float64 array, or None without weights. InvalidInput for another
    shape, and with a geographic CRS (weights are squared lengths in the coordinates' units, which
    the local projection would change). NaN and infinity are the engine's (or server's) to name."""
    if weights is None:
        return None
    weight_array = np.ascontiguousarray(np.asarray(weights, dtype=np.float64))
    if weight_array.shape != (len(array),):
        raise InvalidInput(f"weights must have shape ({len(array)},): one per point, got {weight_array.shape}")
    if frame.projection is not None:
        raise InvalidInput("weights need planar coordinates: the CRS is geographic (project the points and radii first)")
    return weight_array


def batch_sets(sets: Any, crs: Any) -> List[Any]:
    """build_batch's ``sets`` as (name, points array, frame) triples, each framed on its own."""
    items = list(sets.items()) if hasattr(sets, "items") else list(sets)
    prepared = []
    for item in items:
        if not isinstance(item, tuple) or len(item) != 2 or not isinstance(item[0], str):
            raise InvalidInput("build_batch takes a mapping of name to points, or (name, points) pairs")
        name, points = item
        array, data_crs = as_points(points)
        prepared.append((name, array, frame_of(array, crs, data_crs)))
    return prepared


def batch_results(prepared: List[Any], answers: List[Any], make: Callable[..., Any], return_exceptions: bool) -> List[Any]:
    """build_batch's answer: make(answer, array, frame) per built set; a failed set's error raised
    naming the set, or kept in its place with ``return_exceptions``."""
    from ._errors import GalphaError

    out: List[Any] = []
    for (name, array, frame), answer in zip(prepared, answers):
        if isinstance(answer, GalphaError):
            if not return_exceptions:
                raise error_for_code(answer.code_number, f"set {name!r}: {answer.message}") from None
            out.append(answer)
        else:
            out.append(make(answer, array, frame))
    return out


class _TqdmStages:
    """A tqdm bar per stage, fed fractions."""

    def __init__(self, total_points: int) -> None:
        self._bar: Any = None
        self._stage = ""
        self._points = total_points

    def __call__(self, stage: str, fraction: float) -> None:
        from tqdm import tqdm

        if stage != self._stage:
            self.close()
            self._stage = stage
            self._bar = tqdm(total=1000, desc=f"galpha {stage} ({self._points:,} points)", unit="‰", leave=False)
        self._bar.n = int(round(1000 * min(max(fraction, 0.0), 1.0)))
        self._bar.refresh()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def progress_callback(progress: Progress, points: int) -> tuple:
    """(callable or None, closer or None) for a ``progress`` argument."""
    if progress is None or progress is False:
        return None, None
    if progress is True:
        if points < PROGRESS_BAR_MIN_POINTS:
            return None, None
        bar = _TqdmStages(points)
        return bar, bar.close
    if callable(progress):
        return progress, None
    raise InvalidInput(f"progress must be None, True or a callable (stage, fraction), got {progress!r}")


class NetworkClient:
    """A connection to a galpha server (``galpha.connect``)."""

    def __init__(
        self,
        target: str,
        *,
        token: Optional[str],
        tls_ca: Optional[str],
        timeout: Optional[float],
        answer_encoding: str = "auto",
        classify_parts: int = 0,
    ) -> None:
        from . import _network

        self._network = _network
        self.target = target
        # Checked before the channels: nothing to close.
        encoding = _network.answer_encoding_number(answer_encoding)
        parts = _network.classify_parts_count(classify_parts)
        self._channel = _network.channel_for(target, tls_ca)
        self._part_channels = [_network.channel_for(target, tls_ca) for _ in range(parts - 1)]
        self._calls = _network.Calls(self._channel, token, timeout, encoding, self._part_channels)

    def __repr__(self) -> str:
        return f"<galpha.NetworkClient {self.target}>"

    def build(
        self,
        points: Any,
        *,
        name: str = "",
        progress: Progress = None,
        encoding: str = "auto",
        crs: Any = None,
        weights: Any = None,
    ) -> Family:
        """Uploads the points (unless the server already holds them) and returns their family.

        ``weights``: one squared radius per point builds the weighted family, as
        :meth:`LocalClient.build` does; the upload carries (x, y, w) and the handle covers the
        weights.

        ``crs``: the CRS of the coordinates ("EPSG:4326", an EPSG code, a pyproj CRS; "none" for
        planar ones), by default a GeoSeries' or GeoDataFrame's own. A geographic CRS is computed
        in metres (alpha, areas) in a local projection, which is what the server receives; the
        shapes keep the input's coordinates (see :attr:`Family.projection`).

        ``encoding``: ``"auto"`` sends each 65,536-point chunk in its smallest lossless form (exact
        scaled integers or float64, a transform, zstd; raw doubles when nothing is smaller);
        ``"raw"`` sends packed doubles, 16 bytes a point, which servers older than the compact
        encodings need (they refuse encoded chunks with InvalidInput: "neither a header nor
        points"). Either way the server builds the same family under the same handle.
        """
        encoding = check_encoding(encoding)
        array, data_crs = as_points(points)
        frame = frame_of(array, crs, data_crs)
        weight_array = checked_weights(weights, array, frame)
        upload = weighted_rows(frame.computed, weight_array)
        callback, close = progress_callback(progress, len(array))
        total = max(len(array), 1)
        try:
            sent = None if callback is None else (lambda n: callback("upload", n / total))
            # The server's build reports no progress: the bar shows the wait as stage "build".
            building = None if callback is None else (lambda done: callback("build", 1.0 if done else 0.0))
            backend = self._network.build_on_server(self._calls, upload, name, sent, encoding, building)
        finally:
            if close is not None:
                close()
        return Family(backend, array, frame, weight_array)

    def build_batch(
        self,
        sets: Any,
        *,
        encoding: str = "auto",
        crs: Any = None,
        return_exceptions: bool = False,
    ) -> List[Any]:
        """Builds many point sets in one call (a GIS layer's features, a group-by's groups): the
        server reads them from one stream and builds them in one job (small sets on its host's
        cores at once, one a core), each cached under its own handle as :meth:`build` would cache it. ``sets``: a mapping of name to points, or
        a sequence of (name, points) pairs, each points argument as :meth:`build` takes it (the
        name labels the set, as :meth:`build`'s ``name``). ``crs`` applies to every set (by
        default each one's own, as :meth:`build`); geographic sets are each projected on their own.

        Returns the families in the sets' order. A set whose build alone fails (a limit of the
        server's, say) raises its error, naming the set, after the others were built (they stay
        cached: build them again to get them); with ``return_exceptions=True`` its place in the
        list holds the error instead. A set the server cannot read fails the whole call.
        """
        encoding = check_encoding(encoding)
        prepared = batch_sets(sets, crs)
        backends = self._network.build_batch_on_server(self._calls, [(n, f.computed) for n, _, f in prepared], encoding)
        return batch_results(prepared, backends, lambda backend, array, frame: Family(backend, array, frame), return_exceptions)

    def family(self, handle: str, points: Any, *, crs: Any = None, weights: Any = None) -> Family:
        """The family the server holds under ``handle`` for these points (NotFound if it holds
        none); the points give the answers' coordinates and must be the ones the handle names
        (with ``crs`` and ``weights`` as :meth:`build` took them: the handle names the computed
        points and their weights)."""
        from ._errors import NotFound
        from ._handle import point_set_handle

        array, data_crs = as_points(points)
        frame = frame_of(array, crs, data_crs)
        weight_array = checked_weights(weights, array, frame)
        if point_set_handle(weighted_rows(frame.computed, weight_array)) != handle:
            raise InvalidInput(f"these points have another handle than {handle}")
        summary = self._network.find_cached(self._calls, handle)
        if summary is None:
            raise NotFound(f"the server holds no family under {handle}")
        return Family(self._network.NetworkFamilyBackend(self._calls, handle, summary), array, frame, weight_array)

    def close(self) -> None:
        self._channel.close()
        for channel in self._part_channels:
            channel.close()

    def __enter__(self) -> "NetworkClient":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


class LocalClient:
    """The embedded engine in this process (``galpha.local``): no server, no GPU needed."""

    def __init__(self, backend: str) -> None:
        if backend not in ("auto", "cpu", "cuda"):
            raise InvalidInput(f"unknown backend {backend!r} (expected 'auto', 'cpu' or 'cuda')")
        from . import _local  # imports the compiled extension: fail here, not at the first build

        self._local = _local
        self.backend = backend

    def __repr__(self) -> str:
        return f"<galpha.LocalClient backend={self.backend}>"

    def build(
        self,
        points: Any,
        *,
        name: str = "",
        progress: Progress = None,
        encoding: str = "auto",
        crs: Any = None,
        weights: Any = None,
    ) -> Family:
        """Builds the family in this process (the GIL is released while the engine runs).
        ``encoding`` ("auto" or "raw") is checked and ignored: nothing is uploaded, and code can
        switch between the clients unchanged. ``crs`` as :meth:`NetworkClient.build` takes it.

        ``weights``: one squared radius per point (an atom of radius r weighs r**2; negative
        values are valid) builds the weighted family: the alpha shapes of the disks, over their
        regular triangulation; points it hides are EXTERIOR at every threshold
        (:attr:`Family.hidden_points`). Weights are squared lengths in the coordinates' units, so
        a geographic CRS is refused with them."""
        check_encoding(encoding)
        array, data_crs = as_points(points)
        frame = frame_of(array, crs, data_crs)
        weight_array = checked_weights(weights, array, frame)
        callback, close = progress_callback(progress, len(array))
        try:
            backend = self._local.build_local(
                frame.computed, self.backend, callback, name=name, weights=weight_array
            )
        finally:
            if close is not None:
                close()
        return Family(backend, array, frame)

    def build_batch(
        self,
        sets: Any,
        *,
        encoding: str = "auto",
        crs: Any = None,
        return_exceptions: bool = False,
    ) -> List[Any]:
        """Builds many point sets (a GIS layer's features, a group-by's groups) in one packed
        engine build: the sets' triangulations and families are computed by the same launches, and
        each family equals :meth:`build`'s of the set alone. ``sets``, ``crs`` and
        ``return_exceptions`` as :meth:`NetworkClient.build_batch` takes them (``encoding`` is
        checked and ignored). When the packed build fails, the sets are built one by one, so that a
        set's error names it as the network client's does. Unweighted."""
        check_encoding(encoding)
        prepared = batch_sets(sets, crs)
        computed = [np.ascontiguousarray(frame.computed, dtype=np.float64).reshape(-1, 2) for _, _, frame in prepared]
        points = np.concatenate(computed) if computed else np.empty((0, 2))
        set_begin = np.cumsum([0] + [len(c) for c in computed], dtype=np.int64)
        answers: List[Any]
        try:
            answers = self._local.build_many_local(points, set_begin, self.backend, [n for n, _, _ in prepared])
        except GalphaError:
            answers = []
            for (name, _, frame) in prepared:
                try:
                    answers.append(self._local.build_local(frame.computed, self.backend, None, name=name))
                except GalphaError as e:
                    answers.append(e)
        return batch_results(prepared, answers, lambda backend, array, frame: Family(backend, array, frame), return_exceptions)

    def close(self) -> None:
        pass

    def __enter__(self) -> "LocalClient":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def connect(
    target: str,
    *,
    token: Optional[str] = None,
    tls_ca: Optional[str] = None,
    timeout: Optional[float] = None,
    answer_encoding: str = "auto",
    classify_parts: int = 0,
) -> NetworkClient:
    """A client of the galpha server at ``target`` ("host:port").

    ``token``: the bearer token, when the server requires one. ``tls_ca``: a PEM file of root
    certificates, which turns TLS on. ``timeout``: seconds per call (None: no deadline).
    ``answer_encoding``: how :meth:`Family.classify`'s simplices come down, never what it returns:
    "raw" (4-byte indices, 58 MB for a 1M-point answer, which NumPy takes as it comes), "delta"
    (varint differences and 2-bit classes, 0.3-0.5x the bytes), "zstd" (delta compressed,
    0.06-0.36x) or "auto" (the default: "delta" when galpha's compiled module is there, else
    "raw"). The compiled module decodes the compact forms in C++ on up to 4 threads, as fast as the
    C++ client (1M points over loopback on 2 cores: raw 43-56 ms, delta 72-82, zstd 93-97); without
    it NumPy does, 3-3.4x slower (zstd then needs the zstandard module, Debian's
    python3-zstandard), which pays off only on links slower than a few hundred Mb/s. Servers
    older than compact answers send raw whatever is asked. ``classify_parts``: a Classify answer is
    read as that many parts at once, each on a connection of its own, and put back in order (one
    gRPC stream carries about 1 GB/s; several add up on a host with cores to spare); 1 reads it in
    one call, 0 (the default) in half this machine's cores' worth, at most 8. Summary-only
    requests are one call. gRPC connects lazily: an unreachable server shows as
    :class:`galpha.Unavailable` on the first call.
    """
    return NetworkClient(
        target, token=token, tls_ca=tls_ca, timeout=timeout, answer_encoding=answer_encoding, classify_parts=classify_parts
    )


def local(backend: str = "auto") -> LocalClient:
    """A client of the engine embedded in this process: ``"auto"`` (CUDA when a GPU is visible,
    else the CPU), ``"cpu"`` or ``"cuda"``."""
    return LocalClient(backend)


