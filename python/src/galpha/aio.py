"""asyncio variants of the network client (grpc.aio), for services written with asyncio.

``client = galpha.aio.connect("host:port")``; ``family = await client.build(points)``; every query
of :class:`galpha.Family` is a coroutine here with the same arguments and results. The answers are
decoded by the same code as the blocking client's (``_network.py``, ``_wire.py``).
"""

from __future__ import annotations

import asyncio
import dataclasses
from typing import Any, AsyncIterator, Callable, Iterable, List, Optional, Union

import grpc
import numpy as np

from . import _network, _wire
from ._client import Progress, batch_results, batch_sets, checked_weights, progress_callback
from ._crs import Frame, frame_of
from ._encoding import check_encoding
from ._errors import InvalidInput
from ._family import (
    _mode,
    _rule,
    area_argument,
    holes_from_rings,
    holes_geodataframe,
    level_range,
    optimal_bounds,
    persistence_arguments,
    rings_to_shapely,
    threshold_from,
    weighted_rows,
)
from ._handle import point_set_handle
from ._points import as_points
from ._types import (
    BettiCurves,
    BuildSummary,
    Classification,
    ComponentCurve,
    MasterList,
    Mode,
    Optimal,
    PersistenceDiagram,
    ShapeRings,
    VertexRule,
)
from .v1 import alpha_shapes_pb2 as pb

__all__ = ["connect", "AsyncClient", "AsyncFamily"]


def _aio_channel(target: str, tls_ca: Optional[str]) -> grpc.aio.Channel:
    options = _network.CHANNEL_OPTIONS
    if tls_ca is None:
        return grpc.aio.insecure_channel(target, options=options)
    with open(tls_ca, "rb") as f:
        credentials = grpc.ssl_channel_credentials(root_certificates=f.read())
    return grpc.aio.secure_channel(target, credentials, options=options)


class AsyncFamily:
    """A family on a galpha server, queried with coroutines (see :class:`galpha.Family`)."""

    def __init__(
        self,
        calls: _network.Calls,
        handle: str,
        summary: BuildSummary,
        points: np.ndarray,
        frame: Frame,
        rows: Optional[np.ndarray] = None,
    ) -> None:
        self._calls = calls
        # What the family was built from: the computed points, with their weights when weighted.
        self._rows = rows if rows is not None else frame.computed
        self.handle = handle
        self.summary = summary
        self.points = points
        self._frame = frame
        self.crs = frame.crs  #: as :attr:`galpha.Family.crs`
        self.projection = frame.projection  #: as :attr:`galpha.Family.projection`

    async def __aenter__(self) -> "AsyncFamily":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await self.release()

    def _metadata(self) -> List[Any]:
        return self._calls.metadata(self.handle)

    async def _call(self, method: Any, request: Any) -> Any:
        try:
            return await method(request, timeout=self._calls.timeout, metadata=self._metadata())
        except grpc.RpcError as e:
            raise _network.raise_from_rpc(e) from None

    async def _stream(self, method: Any, request: Any) -> List[Any]:
        try:
            return [m async for m in method(request, timeout=self._calls.timeout, metadata=self._metadata())]
        except grpc.RpcError as e:
            raise _network.raise_from_rpc(e) from None

    async def spectrum(self, first_rank: int = 1, count: Optional[int] = None) -> np.ndarray:
        k = self.summary.spectrum_size
        if first_rank < 1 or first_rank > k + 1:
            raise InvalidInput(f"first_rank {first_rank} is outside 1..{k + 1}")
        remaining = k + 1 - first_rank if count is None else count
        pages: List[np.ndarray] = [np.empty(0, dtype=np.float64)]
        rank = first_rank
        while remaining > 0:
            raw = await self._call(
                self._calls.spectrum,
                pb.SpectrumRequest(handle=self.handle, first_rank=rank, page_size=min(remaining, _network.SPECTRUM_PAGE)),
            )
            _, values, next_rank, _ = _wire.decode_spectrum_page(raw)
            pages.append(values)
            remaining -= len(values)
            if next_rank == 0 or len(values) == 0:
                break
            rank = next_rank
        return np.concatenate(pages)

    async def hidden_points(self) -> np.ndarray:
        """As :attr:`galpha.Family.hidden_points`: the input indices (uint32, ascending) of the
        points a weighted family hides; empty for an unweighted one."""
        if self.summary.hidden_points == 0:
            return np.empty(0, dtype=np.uint32)
        firsts: List[np.ndarray] = []
        call = self._calls.classify(
            _network.hidden_points_request(self.handle), timeout=self._calls.timeout, metadata=self._metadata()
        )
        try:
            async for raw in call:
                exterior = _network.exterior_vertices(raw)
                if exterior is None:
                    break
                firsts.append(exterior)
        except grpc.RpcError as e:
            raise _network.raise_from_rpc(e) from None
        finally:
            call.cancel()
        return _network.hidden_with_duplicates(self._rows, firsts, self.summary.hidden_points)

    async def classify(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.GENERAL,
        vertex_rule: Union[str, VertexRule] = VertexRule.REPORT,
        non_exterior_only: bool = False,
        summary_only: bool = False,
    ) -> Classification:
        request = pb.ClassifyRequest(
            handle=self.handle,
            threshold=_network.threshold_message(threshold_from(alpha, alpha_sq, rank, ratio)),
            mode=_network._MODES[_mode(mode)],
            vertex_rule=_network._RULES[_rule(vertex_rule)],
            non_exterior_only=non_exterior_only,
            summary_only=summary_only,
            simplex_encoding=self._calls.simplex_encoding,
        )
        methods = [self._calls.classify] + self._calls.part_classify
        if len(methods) == 1 or summary_only:
            messages = await self._stream(self._calls.classify, request)
        else:
            messages = await self._classify_in_parts(methods, request)
        assembler = _network.ClassifyAssembler()
        for raw in messages:
            assembler.add(raw)
        return assembler.result()

    async def _classify_in_parts(self, methods: List[Any], request: pb.ClassifyRequest) -> List[bytes]:
        """The parts of one Classify answer at once, a connection each, merged in order. The first
        failure cancels the others; so does a server that answers every part whole."""
        metadata = self._metadata()
        calls = [
            m(r, timeout=self._calls.timeout, metadata=metadata)
            for m, r in zip(methods, _network.part_requests(request, len(methods)))
        ]
        older_server = False

        async def read(part: int) -> List[bytes]:
            nonlocal older_server
            messages: List[bytes] = []
            try:
                async for raw in calls[part]:
                    if part > 0 and not messages and _wire.split_oneof(raw)[0] == 1:
                        older_server = True  # a summary outside part 0: part 0 is the whole answer
                        for call in calls[1:]:
                            call.cancel()
                        return messages
                    messages.append(raw)
            except (grpc.RpcError, asyncio.CancelledError):
                if part > 0 and older_server:
                    return messages  # cancelled here
                raise
            return messages

        tasks = [asyncio.ensure_future(read(part)) for part in range(len(calls))]
        try:
            done, _ = await asyncio.wait(tasks, return_when=asyncio.FIRST_EXCEPTION)
            failed = [t.exception() for t in tasks if t.done() and not t.cancelled() and t.exception() is not None]
            if failed:
                raise failed[0]
            parts = await asyncio.gather(*tasks)
        except grpc.RpcError as e:
            raise _network.raise_from_rpc(e) from None
        finally:
            if not all(t.done() for t in tasks):  # a failure, or the caller cancelled: the calls end
                for call in calls:
                    call.cancel()
                for task in tasks:
                    task.cancel()
                await asyncio.gather(*tasks, return_exceptions=True)
        return parts[0] if older_server else _network.merge_parts(parts)

    async def shape_rings(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.REGULARIZED,
        min_hole_area: float = 0.0,
    ) -> ShapeRings:
        threshold = threshold_from(alpha, alpha_sq, rank, ratio)
        m = _mode(mode)
        request = _network.shape_request(
            self.handle, threshold, m, area_argument("min_hole_area", min_hole_area, "keep every hole")
        )
        return _network.shape_rings_from(await self._stream(self._calls.shape, request))

    async def shape(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        mode: Union[str, Mode] = Mode.REGULARIZED,
        min_hole_area: float = 0.0,
    ) -> Any:
        m = _mode(mode)
        rings = await self.shape_rings(
            alpha=alpha, alpha_sq=alpha_sq, rank=rank, ratio=ratio, mode=m, min_hole_area=min_hole_area
        )
        return rings_to_shapely(rings, self.points, m)

    async def holes(
        self,
        *,
        alpha: Optional[float] = None,
        alpha_sq: Optional[float] = None,
        rank: Optional[int] = None,
        ratio: Optional[float] = None,
        min_area: float = 0.0,
        as_geodataframe: bool = False,
    ) -> Any:
        """The holes of the regularized shape at one threshold, as :meth:`galpha.Family.holes`
        (the rings from the server, their exact areas computed here from ``points``)."""
        threshold = threshold_from(alpha, alpha_sq, rank, ratio)
        minimum = area_argument("min_area", min_area, "every hole")
        request = _network.shape_request(self.handle, threshold, Mode.REGULARIZED, 0.0)
        rings = _network.shape_rings_from(await self._stream(self._calls.shape, request))
        holes = holes_from_rings(rings, self._frame.computed, minimum)
        return holes_geodataframe(holes, self.points, self.crs) if as_geodataframe else holes

    async def master_list(self, rank: int, last_rank: Optional[int] = None) -> MasterList:
        request = pb.MasterListRequest(
            handle=self.handle, first_rank=int(rank), last_rank=int(rank if last_rank is None else last_rank)
        )
        return _network.master_list_from(await self._stream(self._calls.master_list, request))

    async def components(self, first_level: int = 0, last_level: Optional[int] = None) -> ComponentCurve:
        k = self.summary.spectrum_size
        last = k if last_level is None else int(last_level)
        if not 0 <= first_level <= last <= k:
            raise InvalidInput(f"levels {first_level}..{last} are not within 0..{k}")
        comps: List[np.ndarray] = []
        solid: List[np.ndarray] = []
        level = first_level
        while level <= last:
            end = min(last, level + _network.COMPONENTS_PAGE - 1)
            answer = await self._call(
                self._calls.components, pb.ComponentsRequest(handle=self.handle, ranks=pb.RankRange(first=level, last=end))
            )
            comps.append(np.array(answer.components, dtype=np.uint32))
            solid.append(np.array(answer.solid_components, dtype=np.uint32))
            level = end + 1
        return ComponentCurve(first_level, np.concatenate(comps), np.concatenate(solid))

    async def betti(self, first_rank: int = 0, last_rank: Optional[int] = None) -> BettiCurves:
        first, last = level_range(first_rank, last_rank, self.summary.spectrum_size)
        answers = [
            await self._call(self._calls.betti, pb.BettiRequest(handle=self.handle, ranks=pb.RankRange(first=a, last=b)))
            for a, b in _network.level_pages(first, last)
        ]
        return _network.betti_from(first, answers)

    async def persistence(
        self, dimensions: Union[int, Iterable[int]] = (0, 1), min_persistence: float = 0.0
    ) -> PersistenceDiagram:
        dims, minimum = persistence_arguments(dimensions, min_persistence)
        request = _network.persistence_request(self.handle, dims, minimum)
        return _network.persistence_from(await self._stream(self._calls.persistence, request))

    async def optimal(self, components: int = 1, holes: Optional[int] = None) -> Optimal:
        max_components, max_holes = optimal_bounds(components, holes)
        answer = await self._call(self._calls.optimal, _network.optimal_request(self.handle, max_components, max_holes))
        return _network.optimal_from(answer)

    async def release(self) -> bool:
        return (await self._call(self._calls.release, pb.ReleaseRequest(handle=self.handle))).released


async def _upload_messages(
    name: str,
    points: np.ndarray,
    progress: Optional[Callable[[int], None]],
    encoding: str,
    counter: _network.UploadCounter,
) -> AsyncIterator[bytes]:
    """_network.upload_messages for grpc.aio: grpc.aio iterates a plain iterator on the event loop,
    so the chunks are encoded in the loop's executor instead, the next while one is sent."""
    loop = asyncio.get_running_loop()
    yield _network.header_message(name, points)
    bounds = _network.chunk_bounds(points)

    def encode(i: int) -> "asyncio.Future[bytes]":
        begin, end = bounds[i]
        return loop.run_in_executor(None, _network.chunk_message, points[begin:end], encoding)

    upcoming = encode(0) if bounds else None
    try:
        for i, (_, end) in enumerate(bounds):
            message = await upcoming  # type: ignore[misc]
            upcoming = encode(i + 1) if i + 1 < len(bounds) else None
            counter.bytes += len(message)
            yield message
            if progress is not None:
                progress(end)
    finally:
        if upcoming is not None:
            upcoming.cancel()


class AsyncClient:
    """A grpc.aio connection to a galpha server (``galpha.aio.connect``)."""

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
        self.target = target
        # Checked before the channels: nothing to close.
        encoding = _network.answer_encoding_number(answer_encoding)
        parts = _network.classify_parts_count(classify_parts)
        self._channel = _aio_channel(target, tls_ca)
        self._part_channels = [_aio_channel(target, tls_ca) for _ in range(parts - 1)]
        self._calls = _network.Calls(self._channel, token, timeout, encoding, self._part_channels)

    async def __aenter__(self) -> "AsyncClient":
        return self

    async def __aexit__(self, *exc: Any) -> None:
        await self.close()

    async def close(self) -> None:
        await self._channel.close()
        for channel in self._part_channels:
            await channel.close()

    async def build_batch(
        self,
        sets: Any,
        *,
        encoding: str = "auto",
        crs: Any = None,
        return_exceptions: bool = False,
    ) -> List[Any]:
        """Many point sets in one call, as :meth:`galpha.NetworkClient.build_batch` takes and
        answers them (a list of AsyncFamily, or errors with ``return_exceptions``); the chunks are
        encoded off the event loop. Cancelling the task cancels the call."""
        encoding = check_encoding(encoding)
        prepared = batch_sets(sets, crs)
        if not prepared:
            return []
        _network.check_batch_size(len(prepared))
        answers = _network.BatchAnswers([_network.UploadCounter() for _ in prepared])

        async def messages() -> AsyncIterator[bytes]:
            for (name, _, frame), counter in zip(prepared, answers.counters):
                async for message in _upload_messages(name, frame.computed, None, encoding, counter):
                    yield message

        call = self._calls.build_batch(messages(), timeout=self._calls.timeout, metadata=self._calls.metadata())
        try:
            async for page in call:
                answers.add(page)
        except grpc.RpcError as e:
            raise _network.raise_from_rpc(e) from None
        except BaseException:
            call.cancel()
            raise
        return batch_results(
            prepared,
            answers.result(),
            lambda answer, array, frame: AsyncFamily(self._calls, answer[0], answer[1], array, frame, frame.computed),
            return_exceptions,
        )

    async def build(
        self,
        points: Any,
        *,
        name: str = "",
        progress: Progress = None,
        encoding: str = "auto",
        crs: Any = None,
        weights: Any = None,
    ) -> AsyncFamily:
        """Uploads the points (unless the server holds them) and awaits the build. Cancelling the
        task cancels the upload; the server then drops what it had received. ``encoding``: "auto"
        or "raw", and ``crs``, as :meth:`galpha.NetworkClient.build` takes them (chunks are encoded
        off the event loop, in its default executor), and ``weights`` as
        :meth:`galpha.NetworkClient.build` takes it."""
        encoding = check_encoding(encoding)
        array, data_crs = as_points(points)
        frame = frame_of(array, crs, data_crs)
        upload = weighted_rows(frame.computed, checked_weights(weights, array, frame))
        callback, close = progress_callback(progress, len(array))
        total = max(len(array), 1)
        sent: Optional[Callable[[int], None]] = None if callback is None else (lambda n: callback("upload", n / total))
        try:
            # Hashing 1M points takes ~10 ms; off the event loop for larger sets.
            handle = await asyncio.get_running_loop().run_in_executor(None, point_set_handle, upload)
            metadata = self._calls.metadata(handle)
            try:
                answer = await self._calls.describe(
                    pb.DescribeRequest(handle=handle), timeout=self._calls.timeout, metadata=metadata
                )
                return AsyncFamily(self._calls, handle, _network.summary_from(answer.summary, True), array, frame, upload)
            except grpc.RpcError as e:
                if e.code() != grpc.StatusCode.NOT_FOUND:
                    raise _network.raise_from_rpc(e) from None
            counter = _network.UploadCounter()
            try:
                answer = await self._calls.build(
                    _upload_messages(name, upload, sent, encoding, counter), timeout=self._calls.timeout, metadata=metadata
                )
            except grpc.RpcError as e:
                raise _network.raise_from_rpc(e) from None
        finally:
            if close is not None:
                close()
        summary = dataclasses.replace(_network.summary_from(answer.summary, answer.cached), upload_bytes=counter.bytes)
        return AsyncFamily(self._calls, answer.handle, summary, array, frame, upload)


def connect(
    target: str,
    *,
    token: Optional[str] = None,
    tls_ca: Optional[str] = None,
    timeout: Optional[float] = None,
    answer_encoding: str = "auto",
    classify_parts: int = 0,
) -> AsyncClient:
    """The asyncio counterpart of :func:`galpha.connect` (create it inside a running event loop)."""
    return AsyncClient(
        target, token=token, tls_ca=tls_ca, timeout=timeout, answer_encoding=answer_encoding, classify_parts=classify_parts
    )


