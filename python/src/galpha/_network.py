"""The network backend: galpha.v1.AlphaShapes over gRPC, with the bulk arrays of the Build upload
and of Classify, MasterList, Spectrum and Persistence answers encoded and decoded by hand (``_wire.py``), and
every failure raised as a :mod:`galpha` exception carrying the server's code and message.
"""

from __future__ import annotations

import collections
import concurrent.futures
import dataclasses
import os
import threading
import time
from typing import Any, Callable, Iterator, List, Optional, Sequence, Tuple

import grpc
import numpy as np

from . import _encoding, _wire
from ._errors import GalphaError, InvalidInput, error_for_code
from ._family import holes_from_rings
from ._handle import point_set_handle
from ._types import (
    BettiCurves,
    BuildSummary,
    ClassCounts,
    Classification,
    ComponentCurve,
    Hole,
    MasterList,
    Mode,
    Optimal,
    OptimalLevel,
    PersistenceDiagram,
    PersistencePairs,
    ShapePolygon,
    ShapeRings,
    Threshold,
    VertexRule,
)
from .v1 import alpha_shapes_pb2 as pb

SERVICE = "/galpha.v1.AlphaShapes/"
#: Points per Build chunk: 1 MiB of doubles, as the C++ client sends.
POINTS_PER_CHUNK = 65536
#: Threads that encode chunks ahead of the one being sent (numpy and zstd release the GIL).
ENCODE_THREADS = max(1, min(4, os.cpu_count() or 1))
#: The request header a gRPC-aware load balancer hashes on (deploy/k8s/envoy.yaml).
HANDLE_HEADER = "x-galpha-handle"
#: Receive limit: answers are paged well below it; generous for shape text of large sets.
MAX_RECEIVE_BYTES = 256 << 20
#: Spectrum values per page (the server's cap).
SPECTRUM_PAGE = 262144
#: Levels per Components and Betti call (the server's cap).
COMPONENTS_PAGE = 262144

_MODES = {Mode.GENERAL: pb.CLASSIFY_MODE_GENERAL, Mode.REGULARIZED: pb.CLASSIFY_MODE_REGULARIZED}
_RULES = {VertexRule.REPORT: pb.VERTEX_RULE_REPORT, VertexRule.CGAL: pb.VERTEX_RULE_CGAL}


def raise_from_rpc(error: grpc.RpcError) -> GalphaError:
    """The galpha exception for a failed call (to be raised ``from None``)."""
    code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
    details = error.details() if hasattr(error, "details") else str(error)
    return error_for_code(code.value[0], details or code.name)


#: The most parts a Classify answer is read in (the server refuses a part_count above it), and the
#: most connect()'s default picks.
MAX_CLASSIFY_PARTS = 64
MAX_DEFAULT_CLASSIFY_PARTS = 8

#: Each channel a connection of its own: gRPC otherwise shares one connection among a process's
#: channels to one server, and the parts of a Classify answer would share its single stream's pace.
CHANNEL_OPTIONS = [("grpc.max_receive_message_length", MAX_RECEIVE_BYTES), ("grpc.use_local_subchannel_pool", 1)]


def classify_parts_count(classify_parts: int) -> int:
    """The number of parts connect()'s ``classify_parts`` reads a Classify answer in: as given
    (1..64), or for 0 half this machine's cores, at least 1 and at most 8."""
    if isinstance(classify_parts, bool) or not isinstance(classify_parts, int) or not 0 <= classify_parts <= MAX_CLASSIFY_PARTS:
        raise InvalidInput(
            f"classify_parts is a number of parts from 1 to {MAX_CLASSIFY_PARTS}, or 0 for half this machine's "
            f"cores (at most {MAX_DEFAULT_CLASSIFY_PARTS}), not {classify_parts!r}"
        )
    if classify_parts > 0:
        return classify_parts
    return max(1, min(MAX_DEFAULT_CLASSIFY_PARTS, (os.cpu_count() or 1) // 2))


def part_requests(request: pb.ClassifyRequest, parts: int) -> List[pb.ClassifyRequest]:
    """The requests for the ``parts`` parts of one Classify answer (ClassifyRequest.part_count)."""
    out = []
    for index in range(parts):
        part = pb.ClassifyRequest()
        part.CopyFrom(request)
        part.part_index = index
        part.part_count = parts
        out.append(part)
    return out


def merge_parts(parts: Sequence[Sequence[bytes]]) -> List[bytes]:
    """The messages of one Classify answer from its parts, in the order one call sends them: part
    0's summary, then chunk c from part c % P (the server deals them round-robin). A server older
    than part_count answers every part whole (part 1 then starts with a summary): part 0 is the
    answer."""
    count = len(parts)
    data_loss = dict(code="DATA_LOSS", code_number=15)
    if count > 1 and parts[1] and _wire.split_oneof(parts[1][0])[0] == 1:
        return list(parts[0])
    if not parts[0] or _wire.split_oneof(parts[0][0])[0] != 1:
        raise GalphaError("part 0 of the server's Classify answer did not start with the summary", **data_loss)
    merged = [parts[0][0]]
    taken = [1] + [0] * (count - 1)
    chunk = 0
    while True:
        part = chunk % count
        if taken[part] == len(parts[part]):
            break  # chunk `chunk` does not exist: neither does any later one
        merged.append(parts[part][taken[part]])
        taken[part] += 1
        chunk += 1
    for part in range(count):
        if taken[part] != len(parts[part]):
            raise GalphaError(
                f"part {part} of {count} of the server's Classify answer sent chunks past the answer's end", **data_loss
            )
    return merged


def channel_for(target: str, tls_ca: Optional[str]) -> grpc.Channel:
    options = CHANNEL_OPTIONS
    if tls_ca is None:
        return grpc.insecure_channel(target, options=options)
    with open(tls_ca, "rb") as f:
        credentials = grpc.ssl_channel_credentials(root_certificates=f.read())
    return grpc.secure_channel(target, credentials, options=options)


def threshold_message(threshold: Threshold) -> pb.Threshold:
    if threshold.kind == "rank":
        return pb.Threshold(rank=int(threshold.value))
    if threshold.kind == "alpha":
        return pb.Threshold(alpha=float(threshold.value))
    if threshold.kind == "ratio":
        return pb.Threshold(ratio=float(threshold.value))
    return pb.Threshold(alpha_sq=float(threshold.value))


def summary_from(message: pb.BuildSummary, cached: bool) -> BuildSummary:
    return BuildSummary(
        name=message.name,
        points=message.points,
        distinct_points=message.distinct_points,
        duplicates=message.duplicates,
        triangles=message.triangles,
        edges=message.edges,
        spectrum_size=message.spectrum_size,
        backend=message.backend,
        stage_times={s.stage: s.seconds for s in message.stage_times},
        comparisons={
            "filter": message.comparisons.filter,
            "device_exact": message.comparisons.device_exact,
            "cpu_fallback": message.comparisons.cpu_fallback,
        },
        peak_memory_bytes=message.peak_memory_bytes,
        family_bytes=message.family_bytes,
        cached=cached,
        weighted=message.weighted,
        hidden_points=message.hidden_points,
    )


def _counts(c: pb.ClassCounts) -> ClassCounts:
    return ClassCounts(exterior=c.exterior, singular=c.singular, regular=c.regular, interior=c.interior)


#: Threads that decode compact Classify chunks (shared by every call of the process): the C++
#: reader releases the GIL, so chunks decode side by side while the stream is still read.
_DECODE_THREADS = min(4, os.cpu_count() or 1)
_decode_pool: Optional[concurrent.futures.ThreadPoolExecutor] = None
_decode_pool_lock = threading.Lock()
_decode_thread = threading.local()  # each pool thread's reader (one reuses its zstd context)


def _decode_executor() -> concurrent.futures.ThreadPoolExecutor:
    global _decode_pool
    with _decode_pool_lock:
        if _decode_pool is None:
            _decode_pool = concurrent.futures.ThreadPoolExecutor(_DECODE_THREADS, thread_name_prefix="galpha-decode")
        return _decode_pool


def _decode_encoded(payload: memoryview, index: int) -> Tuple[int, np.ndarray, np.ndarray]:
    if not hasattr(_decode_thread, "reader"):
        _decode_thread.reader = _wire.native_section_reader()  # None without the compiled module: NumPy decodes
    return _wire.decode_encoded_simplex_chunk(payload, index, _decode_thread.reader)


class ClassifyAssembler:
    """Collects a Classify stream (one summary, then chunks by kind) into a Classification. Compact
    chunks are decoded on a small shared pool as they arrive, and taken in their order."""

    def __init__(self) -> None:
        self.summary: Optional[pb.ClassifySummary] = None
        self.chunks: List[Any] = []  # (kind, indices, classes), or a Future of one, in stream order

    def add(self, raw: bytes) -> None:
        number, payload = _wire.split_oneof(raw)
        if number == 1:
            self.summary = pb.ClassifySummary.FromString(bytes(payload))
            return
        if number == 2:
            self.chunks.append(_wire.decode_simplex_chunk(payload))
        elif number == 3:
            self.chunks.append(_decode_executor().submit(_decode_encoded, payload, len(self.chunks)))

    def result(self) -> Classification:
        parts: dict = {1: ([], []), 2: ([], []), 3: ([], [])}
        try:
            for chunk in self.chunks:
                kind, indices, classes = chunk.result() if isinstance(chunk, concurrent.futures.Future) else chunk
                if kind in parts:
                    parts[kind][0].append(indices)
                    parts[kind][1].append(classes)
        except _wire.EncodedChunkError as e:
            raise GalphaError(f"the server's Classify answer: {e}", code="DATA_LOSS", code_number=15) from None
        finally:
            for chunk in self.chunks:
                if isinstance(chunk, concurrent.futures.Future):
                    chunk.cancel()
        if self.summary is None:
            raise GalphaError("the server's Classify answer had no summary", code="DATA_LOSS", code_number=15)

        def joined(kind: int, width: int) -> Tuple[np.ndarray, np.ndarray]:
            idx, cls = parts[kind]
            indices = np.concatenate(idx) if idx else np.empty(0, dtype=np.uint32)
            classes = np.concatenate(cls) if cls else np.empty(0, dtype=np.uint8)
            indices = indices.astype(np.uint32, copy=False)
            return (indices if width == 1 else indices.reshape(-1, width)), classes

        vertices, vertex_classes = joined(1, 1)
        edges, edge_classes = joined(2, 2)
        triangles, triangle_classes = joined(3, 3)
        s = self.summary
        return Classification(
            level=s.level,
            alpha_sq=s.alpha_sq,
            vertex_counts=_counts(s.vertices),
            edge_counts=_counts(s.edges),
            triangle_counts=_counts(s.triangles),
            components=s.components,
            solid_components=s.solid_components,
            interior_area=s.interior_area,
            vertices=vertices,
            vertex_classes=vertex_classes,
            edges=edges,
            edge_classes=edge_classes,
            triangles=triangles,
            triangle_classes=triangle_classes,
            holes=s.holes,
            hull_area=s.hull_area,
        )


def shape_request(handle: str, threshold: Threshold, mode: Mode, min_hole_area: float) -> pb.ShapeRequest:
    """A Shape request for the rings (min_hole_area checked by the caller)."""
    return pb.ShapeRequest(
        handle=handle,
        threshold=threshold_message(threshold),
        mode=_MODES[mode],
        format=pb.SHAPE_FORMAT_RINGS,
        min_hole_area=min_hole_area,
    )


def shape_rings_from(pieces: Sequence[pb.ShapeResponse]) -> ShapeRings:
    polygons: List[ShapePolygon] = []
    singular: List[np.ndarray] = []
    isolated: List[np.ndarray] = []
    area = 0.0
    for i, piece in enumerate(pieces):
        rings = piece.rings
        if i == 0:
            area = rings.area
        for polygon in rings.polygons:
            polygons.append(
                ShapePolygon(
                    outer=np.array(polygon.outer, dtype=np.uint32),
                    holes=[np.array(h.vertex_indices, dtype=np.uint32) for h in polygon.holes],
                )
            )
        singular.append(np.array(rings.singular_edges, dtype=np.uint32))
        isolated.append(np.array(rings.isolated_points, dtype=np.uint32))
    return ShapeRings(
        polygons=polygons,
        singular_edges=(np.concatenate(singular) if singular else np.empty(0, np.uint32)).reshape(-1, 2),
        isolated_points=np.concatenate(isolated) if isolated else np.empty(0, np.uint32),
        area=area,
    )


def optimal_from(message: pb.OptimalAlphaResponse) -> Optimal:
    def level(field: str) -> Optional[OptimalLevel]:
        if not message.HasField(field):
            return None
        m = getattr(message, field)
        return OptimalLevel(rank=m.rank, alpha_sq=m.alpha_sq, components=m.components, holes=m.holes)

    return Optimal(regularized=level("regularized"), general=level("general"))


def optimal_request(handle: str, max_components: int, max_holes: Optional[int]) -> pb.OptimalAlphaRequest:
    request = pb.OptimalAlphaRequest(handle=handle, max_components=max_components)
    if max_holes is not None:
        request.max_holes = max_holes
    return request


def betti_from(first_level: int, answers: Sequence[pb.BettiResponse]) -> BettiCurves:
    def joined(field: str) -> np.ndarray:
        parts = [np.array(getattr(a, field), dtype=np.uint32) for a in answers]
        return np.concatenate(parts) if parts else np.empty(0, np.uint32)

    return BettiCurves(
        first_level=first_level,
        components=joined("components"),
        holes=joined("holes"),
        regularized_components=joined("regularized_components"),
        regularized_holes=joined("regularized_holes"),
    )


def level_pages(first_level: int, last_level: int) -> List[Tuple[int, int]]:
    """first..last (inclusive) in pieces of at most COMPONENTS_PAGE levels."""
    return [(b, min(last_level, b + COMPONENTS_PAGE - 1)) for b in range(first_level, last_level + 1, COMPONENTS_PAGE)]


def persistence_request(handle: str, dimensions: Tuple[int, ...], min_persistence: float) -> pb.PersistenceRequest:
    return pb.PersistenceRequest(handle=handle, dimensions=list(dimensions), min_persistence=min_persistence)


def persistence_from(chunks: Sequence[bytes]) -> PersistenceDiagram:
    """The Persistence stream's chunks (each of one dimension, in the diagram's order) as a diagram."""
    parts: dict = {0: [], 1: []}
    for raw in chunks:
        dimension, arrays = _wire.decode_persistence_chunk(raw)
        if dimension not in parts:
            raise GalphaError(f"the server sent persistence pairs of dimension {dimension}", code="DATA_LOSS", code_number=15)
        parts[dimension].append(arrays)

    def pairs(dimension: int) -> PersistencePairs:
        chunks_of = parts[dimension]

        def joined(key: str, dtype: Any) -> np.ndarray:
            arrays = [c[key] for c in chunks_of]
            return np.concatenate(arrays).astype(dtype, copy=False) if arrays else np.empty(0, dtype=dtype)

        return PersistencePairs(
            dimension=dimension,
            birth_rank=joined("birth_rank", np.int64),
            death_rank=joined("death_rank", np.int64),
            birth=joined("birth_alpha_sq", np.float64),
            death=joined("death_alpha_sq", np.float64),
            creator=joined("creator_vertices", np.uint32).reshape(-1, dimension + 1),
            killer=joined("killer_vertices", np.uint32).reshape(-1, dimension + 2),
        )

    return PersistenceDiagram(h0=pairs(0), h1=pairs(1))


def master_list_from(pages: Sequence[bytes]) -> MasterList:
    decoded = [_wire.decode_master_list_page(p) for p in pages]

    def joined(key: str, dtype: Any) -> np.ndarray:
        arrays = [d[key] for d in decoded]
        return np.concatenate(arrays).astype(dtype, copy=False) if arrays else np.empty(0, dtype=dtype)

    return MasterList(
        ranks=joined("ranks", np.int64),
        kinds=joined("kinds", np.uint8),
        endpoints=joined("endpoints", np.uint8),
        vertex_indices=joined("vertex_indices", np.uint32),
    )


class UploadCounter:
    """Bytes of point messages an upload has produced so far (BuildSummary.upload_bytes)."""

    def __init__(self) -> None:
        self.bytes = 0


def header_message(name: str, points: np.ndarray) -> bytes:
    """The Build header of (n, 2) points, or of (n, 3) weighted ones (x, y, w: BuildHeader.weighted)."""
    weighted = points.ndim == 2 and points.shape[1] == 3
    header = pb.BuildHeader(name=name, expected_points=len(points), weighted=weighted)
    return pb.BuildRequest(header=header).SerializeToString()


def chunk_message(chunk: np.ndarray, encoding: str) -> bytes:
    """One chunk's BuildRequest: its smallest encoding ("auto") or packed doubles ("raw")."""
    if encoding == "raw":
        return _wire.encode_point_chunk_request(chunk)
    return _encoding.encode_smallest(chunk)


def chunk_bounds(points: np.ndarray) -> List[Tuple[int, int]]:
    return [(b, min(b + POINTS_PER_CHUNK, len(points))) for b in range(0, len(points), POINTS_PER_CHUNK)]


_encode_pool: Optional[concurrent.futures.ThreadPoolExecutor] = None
_encode_pool_lock = threading.Lock()


def _encoder_pool() -> concurrent.futures.ThreadPoolExecutor:
    """The process's chunk encoders, made on first use and kept: each thread keeps its scratch
    buffers from upload to upload (fresh pages cost more than the encoding on some machines)."""
    global _encode_pool
    with _encode_pool_lock:
        if _encode_pool is None:
            _encode_pool = concurrent.futures.ThreadPoolExecutor(ENCODE_THREADS, thread_name_prefix="galpha-encode")
        return _encode_pool


def _chunk_messages(points: np.ndarray, encoding: str) -> Iterator[bytes]:
    """The chunks' messages in order; "auto" encodes up to ENCODE_THREADS + 1 chunks ahead on a
    pool (the send of one overlaps the encoding of the next); what is still queued when the stream
    ends or is abandoned (a cancelled call) is cancelled."""
    bounds = chunk_bounds(points)
    if encoding == "raw" or len(bounds) <= 1:
        for begin, end in bounds:
            yield chunk_message(points[begin:end], encoding)
        return
    pool = _encoder_pool()
    pending: collections.deque = collections.deque()
    upcoming = iter(bounds)

    def submit_next() -> None:
        for begin, end in upcoming:
            pending.append(pool.submit(chunk_message, points[begin:end], encoding))
            return

    try:
        for _ in range(ENCODE_THREADS + 1):
            submit_next()
        while pending:
            message = pending.popleft().result()
            submit_next()
            yield message
    finally:
        for future in pending:
            future.cancel()


def upload_messages(
    name: str,
    points: np.ndarray,
    progress: Optional[Callable[[int], None]],
    encoding: str = "auto",
    counter: Optional[UploadCounter] = None,
) -> Iterator[bytes]:
    """The Build stream as serialized messages: a header, then 65,536-point chunks in `encoding`
    ("auto": each chunk's smallest form; "raw": packed doubles, 1 MiB a chunk)."""
    yield header_message(name, points)
    sent = 0
    for message in _chunk_messages(points, encoding):
        if counter is not None:
            counter.bytes += len(message)
        yield message
        sent = min(sent + POINTS_PER_CHUNK, len(points))
        if progress is not None:
            progress(sent)


def _identity(b: bytes) -> bytes:
    return b


#: connect()'s answer_encoding values: how Classify's simplices come down (ClassifyRequest.simplex_encoding).
ANSWER_ENCODINGS = {"raw": 1, "delta": 2, "zstd": 3}


def answer_encoding_number(answer_encoding: str) -> int:
    """The SimplexEncoding number of connect()'s ``answer_encoding``: "auto" is "delta" where the
    compiled module decodes it (as fast as the C++ client), else "raw" (the NumPy decoder takes
    4-6x raw's time). InvalidInput for another value and for "zstd" with neither galpha's
    compiled module (which decodes zstd itself) nor the zstandard module (Debian's
    python3-zstandard)."""
    if answer_encoding == "auto":
        return ANSWER_ENCODINGS["delta" if _wire.native_section_reader() is not None else "raw"]
    if answer_encoding not in ANSWER_ENCODINGS:
        raise InvalidInput(f"answer_encoding is 'auto', 'raw', 'delta' or 'zstd', not {answer_encoding!r}")
    if answer_encoding == "zstd" and _wire.native_section_reader() is None:
        try:
            import zstandard  # noqa: F401
        except ImportError:
            raise InvalidInput(
                "answer_encoding='zstd' needs galpha's compiled module (galpha._engine) or the zstandard module "
                "(Debian: python3-zstandard)"
            ) from None
    return ANSWER_ENCODINGS[answer_encoding]


class Calls:
    """The service's methods on one channel, with the token and the routing header attached."""

    def __init__(
        self,
        channel: Any,
        token: Optional[str],
        timeout: Optional[float],
        simplex_encoding: int = 1,
        part_channels: Sequence[Any] = (),
    ) -> None:
        self.channel = channel
        self.token = token
        self.timeout = timeout
        self.simplex_encoding = simplex_encoding  # ClassifyRequest.simplex_encoding (answer_encoding_number)
        # Classify on parts 1.. of a split answer (part 0 takes `classify`): a channel each.
        self.part_classify = [
            c.unary_stream(SERVICE + "Classify", request_serializer=pb.ClassifyRequest.SerializeToString, response_deserializer=_identity)
            for c in part_channels
        ]
        def unary(name: str, request_type: Any, response_type: Any) -> Any:
            return channel.unary_unary(
                SERVICE + name, request_serializer=request_type.SerializeToString, response_deserializer=response_type.FromString
            )

        self.describe = unary("Describe", pb.DescribeRequest, pb.DescribeResponse)
        self.release = unary("Release", pb.ReleaseRequest, pb.ReleaseResponse)
        self.components = unary("Components", pb.ComponentsRequest, pb.ComponentsResponse)
        self.optimal = unary("OptimalAlpha", pb.OptimalAlphaRequest, pb.OptimalAlphaResponse)
        self.betti = unary("Betti", pb.BettiRequest, pb.BettiResponse)
        self.persistence = channel.unary_stream(
            SERVICE + "Persistence", request_serializer=pb.PersistenceRequest.SerializeToString, response_deserializer=_identity
        )
        self.spectrum = channel.unary_unary(
            SERVICE + "Spectrum", request_serializer=pb.SpectrumRequest.SerializeToString, response_deserializer=_identity
        )
        self.build = channel.stream_unary(SERVICE + "Build", request_serializer=_identity, response_deserializer=pb.BuildResponse.FromString)
        self.build_batch = channel.stream_stream(
            SERVICE + "BuildBatch", request_serializer=_identity, response_deserializer=pb.BuildBatchResponse.FromString
        )
        self.classify = channel.unary_stream(
            SERVICE + "Classify", request_serializer=pb.ClassifyRequest.SerializeToString, response_deserializer=_identity
        )
        self.master_list = channel.unary_stream(
            SERVICE + "MasterList", request_serializer=pb.MasterListRequest.SerializeToString, response_deserializer=_identity
        )
        self.shape = channel.unary_stream(
            SERVICE + "Shape", request_serializer=pb.ShapeRequest.SerializeToString, response_deserializer=pb.ShapeResponse.FromString
        )

    def metadata(self, handle: Optional[str] = None) -> List[Tuple[str, str]]:
        out = []
        if self.token:
            out.append(("authorization", f"Bearer {self.token}"))
        if handle:
            out.append((HANDLE_HEADER, handle))
        return out


class NetworkFamilyBackend:
    """A family cached on a galpha server, named by its handle."""

    def __init__(self, calls: Calls, handle: str, summary: BuildSummary) -> None:
        self._calls = calls
        self._handle = handle
        self._summary = summary

    def _call(self, method: Any, request: Any) -> Any:
        try:
            return method(request, timeout=self._calls.timeout, metadata=self._calls.metadata(self._handle))
        except grpc.RpcError as e:
            raise raise_from_rpc(e) from None

    def _stream(self, method: Any, request: Any) -> List[Any]:
        try:
            return list(method(request, timeout=self._calls.timeout, metadata=self._calls.metadata(self._handle)))
        except grpc.RpcError as e:
            raise raise_from_rpc(e) from None

    @property
    def handle(self) -> str:
        return self._handle

    def summary(self) -> BuildSummary:
        return self._summary

    def spectrum(self, first_rank: int, count: int) -> np.ndarray:
        pages: List[np.ndarray] = []
        rank, remaining = first_rank, count
        while remaining > 0:
            size = min(remaining, SPECTRUM_PAGE)
            raw = self._call(self._calls.spectrum, pb.SpectrumRequest(handle=self._handle, first_rank=rank, page_size=size))
            _, values, next_rank, _ = _wire.decode_spectrum_page(raw)
            pages.append(values)
            remaining -= len(values)
            if next_rank == 0 or len(values) == 0:
                break
            rank = next_rank
        return np.concatenate(pages) if len(pages) != 1 else pages[0]

    def rank_lower_bound(self, alpha_sq: float) -> int:
        raw = self._call(self._calls.spectrum, pb.SpectrumRequest(handle=self._handle, at_least_alpha_sq=alpha_sq, page_size=1))
        first_rank, _, _, _ = _wire.decode_spectrum_page(raw)
        return first_rank

    def classify(
        self, threshold: Threshold, mode: Mode, vertex_rule: VertexRule, non_exterior_only: bool, summary_only: bool
    ) -> Classification:
        request = pb.ClassifyRequest(
            handle=self._handle,
            threshold=threshold_message(threshold),
            mode=_MODES[mode],
            vertex_rule=_RULES[vertex_rule],
            non_exterior_only=non_exterior_only,
            summary_only=summary_only,
            simplex_encoding=self._calls.simplex_encoding,
        )
        assembler = ClassifyAssembler()
        for raw in self._classify_messages(request):
            assembler.add(raw)
        return assembler.result()

    def _classify_messages(self, request: pb.ClassifyRequest) -> List[bytes]:
        methods = [self._calls.classify] + self._calls.part_classify
        if len(methods) == 1 or request.summary_only:
            return self._stream(self._calls.classify, request)
        # The parts at once, a thread and a connection each (their waits release the GIL). The
        # first failure cancels the others; so does a server that answers every part whole.
        metadata = self._calls.metadata(self._handle)
        calls = [m(r, timeout=self._calls.timeout, metadata=metadata) for m, r in zip(methods, part_requests(request, len(methods)))]
        older_server = threading.Event()

        def read(part: int) -> List[bytes]:
            messages: List[bytes] = []
            try:
                for raw in calls[part]:
                    if part > 0 and not messages and _wire.split_oneof(raw)[0] == 1:
                        older_server.set()  # a summary outside part 0: part 0 is the whole answer
                        for call in calls[1:]:
                            call.cancel()
                        return messages
                    messages.append(raw)
            except grpc.RpcError:
                if part > 0 and older_server.is_set():
                    return messages  # cancelled here
                raise
            return messages

        with concurrent.futures.ThreadPoolExecutor(len(calls)) as pool:
            futures = [pool.submit(read, part) for part in range(len(calls))]
            try:
                concurrent.futures.wait(futures, return_when=concurrent.futures.FIRST_EXCEPTION)
            except BaseException:  # Ctrl-C: the calls end before the pool is left
                for call in calls:
                    call.cancel()
                raise
            failed = [f.exception() for f in futures if f.done() and f.exception() is not None]
            if failed:
                for call in calls:
                    call.cancel()
        if failed:
            error = failed[0]
            if isinstance(error, grpc.RpcError):
                raise raise_from_rpc(error) from None
            raise error
        parts = [f.result() for f in futures]
        return parts[0] if older_server.is_set() else merge_parts(parts)

    def shape_rings(self, threshold: Threshold, mode: Mode, min_hole_area: float = 0.0) -> ShapeRings:
        request = shape_request(self._handle, threshold, mode, min_hole_area)
        return shape_rings_from(self._stream(self._calls.shape, request))

    def holes(self, threshold: Threshold, min_area: float, points: np.ndarray) -> List[Hole]:
        # The server sends the rings; their exact areas are computed here, as alphactl --server does.
        return holes_from_rings(self.shape_rings(threshold, Mode.REGULARIZED), points, min_area)

    def master_list(self, first_rank: int, last_rank: int) -> MasterList:
        request = pb.MasterListRequest(handle=self._handle, first_rank=first_rank, last_rank=last_rank)
        return master_list_from(self._stream(self._calls.master_list, request))

    def components(self, first_level: int, last_level: int) -> ComponentCurve:
        comps: List[np.ndarray] = []
        solid: List[np.ndarray] = []
        level = first_level
        while level <= last_level:
            last = min(last_level, level + COMPONENTS_PAGE - 1)
            answer = self._call(
                self._calls.components,
                pb.ComponentsRequest(handle=self._handle, ranks=pb.RankRange(first=level, last=last)),
            )
            comps.append(np.array(answer.components, dtype=np.uint32))
            solid.append(np.array(answer.solid_components, dtype=np.uint32))
            level = last + 1
        return ComponentCurve(
            first_level=first_level,
            components=np.concatenate(comps) if comps else np.empty(0, np.uint32),
            solid_components=np.concatenate(solid) if solid else np.empty(0, np.uint32),
        )

    def betti(self, first_level: int, last_level: int) -> BettiCurves:
        answers = [
            self._call(self._calls.betti, pb.BettiRequest(handle=self._handle, ranks=pb.RankRange(first=first, last=last)))
            for first, last in level_pages(first_level, last_level)
        ]
        return betti_from(first_level, answers)

    def optimal(self, max_components: int, max_holes: Optional[int] = None) -> Optimal:
        return optimal_from(self._call(self._calls.optimal, optimal_request(self._handle, max_components, max_holes)))

    def persistence(self, dimensions: Tuple[int, ...], min_persistence: float) -> PersistenceDiagram:
        request = persistence_request(self._handle, dimensions, min_persistence)
        return persistence_from(self._stream(self._calls.persistence, request))

    def hidden_points(self, points: np.ndarray) -> np.ndarray:
        if self._summary.hidden_points == 0:
            return np.empty(0, dtype=np.uint32)
        # The server counts them; Classify at rank 0 reports them as its EXTERIOR vertices (every
        # other vertex is in from rank 0), first occurrences only, vertices first: the stream is
        # cancelled at the first edge chunk.
        firsts: List[np.ndarray] = []
        stream = self._calls.classify(
            hidden_points_request(self._handle), timeout=self._calls.timeout, metadata=self._calls.metadata(self._handle)
        )
        try:
            for raw in stream:
                exterior = exterior_vertices(raw)
                if exterior is None:
                    break
                firsts.append(exterior)
        except grpc.RpcError as e:
            raise raise_from_rpc(e) from None
        finally:
            stream.cancel()
        return hidden_with_duplicates(points, firsts, self._summary.hidden_points)

    def release(self) -> bool:
        return self._call(self._calls.release, pb.ReleaseRequest(handle=self._handle)).released


def hidden_points_request(handle: str) -> pb.ClassifyRequest:
    """The Classify call whose EXTERIOR vertices are a weighted family's hidden points (first
    occurrences): rank 0, where every other vertex is in (proto: BuildSummary.hidden_points)."""
    return pb.ClassifyRequest(handle=handle, threshold=pb.Threshold(rank=0))


def exterior_vertices(raw: bytes) -> Optional[np.ndarray]:
    """The EXTERIOR vertices of one ClassifyResponse (empty for the summary); None once the stream
    is past the vertices (an edge or triangle chunk), where a caller that wants vertices stops."""
    number, payload = _wire.split_oneof(raw)
    if number != 2:
        return np.empty(0, dtype=np.uint32)
    kind, indices, classes = _wire.decode_simplex_chunk(payload)
    if kind != pb.SIMPLEX_KIND_VERTEX:
        return None
    if len(indices) != len(classes):
        raise GalphaError("a Classify chunk's indices and classes disagree in length", code="DATA_LOSS", code_number=15)
    return indices[classes == pb.SIMPLEX_CLASS_EXTERIOR]


def hidden_with_duplicates(rows: np.ndarray, parts: List[np.ndarray], count: int) -> np.ndarray:
    """Every input index whose row (x, y, w) equals one of the rows `parts` name (hidden points and
    their duplicates, as the engine finds duplicates: the same position and weight, compared by
    value, -0.0 equal to 0.0), ascending; DATA_LOSS unless they are the `count` the server
    reported."""
    firsts = np.concatenate(parts) if parts else np.empty(0, dtype=np.uint32)
    if len(firsts) and int(firsts.max()) >= len(rows):
        raise GalphaError(f"the server names point {int(firsts.max())} of {len(rows)}", code="DATA_LOSS", code_number=15)
    # Each distinct row's number (-0.0 + 0.0 is 0.0: equal values, equal bytes).
    _, row_id = np.unique(np.ascontiguousarray(rows, dtype=np.float64) + 0.0, axis=0, return_inverse=True)
    row_id = row_id.reshape(-1)
    hidden = np.flatnonzero(np.isin(row_id, row_id[firsts])).astype(np.uint32)
    if len(hidden) != count:
        raise GalphaError(
            f"the server counts {count} hidden points; Classify at rank 0 gives {len(hidden)}",
            code="DATA_LOSS",
            code_number=15,
        )
    return hidden


def find_cached(calls: Calls, handle: str) -> Optional[BuildSummary]:
    """The summary of the family the server holds under `handle`, or None."""
    try:
        answer = calls.describe(pb.DescribeRequest(handle=handle), timeout=calls.timeout, metadata=calls.metadata(handle))
    except grpc.RpcError as e:
        if e.code() == grpc.StatusCode.NOT_FOUND:
            return None
        raise raise_from_rpc(e) from None
    return summary_from(answer.summary, cached=True)


class _UploadProgress:
    """Runs the caller's progress callback inside gRPC's request thread and carries an exception
    it raises (Ctrl-C included) back to the calling thread, holding the stream open meanwhile:
    the caller then cancels the call rather than ending the stream short."""

    def __init__(self, callback: Optional[Callable[[int], None]]) -> None:
        self.callback = callback
        self.failure: Optional[BaseException] = None
        self.released = threading.Event()
        self.sent = 0  # points streamed so far

    def __call__(self, sent: int) -> None:
        self.sent = sent
        if self.callback is None or self.failure is not None:
            return
        try:
            self.callback(sent)
        except BaseException as e:  # noqa: B902 -- a KeyboardInterrupt must reach the caller too
            self.failure = e
            self.released.wait()


def build_on_server(
    calls: Calls,
    points: np.ndarray,
    name: str,
    progress: Optional[Callable[[int], None]],
    encoding: str = "auto",
    building: Optional[Callable[[bool], None]] = None,
) -> NetworkFamilyBackend:
    """Uploads `points` unless the server already holds their handle, and waits for the build.

    The upload runs as a future polled from this thread, so that Ctrl-C (KeyboardInterrupt)
    arrives here at once: the call is then cancelled, and the server drops the partial upload and
    its reservation (nothing is left behind), before the interrupt propagates. An exception raised
    by the progress callback is handled the same way. `encoding`: "auto" or "raw" (checked by the
    caller), as :func:`upload_messages` takes it; the chunks are encoded on other threads.
    `building(done)` is called from this thread about twice a second once every point is sent
    (the server builds; the Build answer carries no progress) and once with True at the end, so
    that a progress bar shows the wait.
    """
    handle = point_set_handle(points)
    cached = find_cached(calls, handle)
    if cached is not None:
        # The server keeps no name with a family (a name is the caller's label for its call).
        cached = dataclasses.replace(cached, name=name)
        if progress is not None:
            progress(len(points))
        return NetworkFamilyBackend(calls, handle, cached)
    reporter = _UploadProgress(progress)
    counter = UploadCounter()
    future = calls.build.future(
        upload_messages(name, points, reporter, encoding, counter), timeout=calls.timeout, metadata=calls.metadata(handle)
    )
    last_report = 0.0
    try:
        while True:
            if reporter.failure is not None:
                raise reporter.failure
            if building is not None and reporter.sent == len(points) and time.monotonic() - last_report >= 0.5:
                last_report = time.monotonic()
                building(False)
            try:
                answer = future.result(timeout=0.05)
                break
            except grpc.FutureTimeoutError:
                continue
    except grpc.RpcError as e:
        raise raise_from_rpc(e) from None
    except BaseException:
        future.cancel()
        raise
    finally:
        reporter.released.set()
    if answer.handle != handle:
        raise InvalidInput(f"the server named the family {answer.handle}, the client computed {handle}")
    if building is not None:
        building(True)
    summary = dataclasses.replace(summary_from(answer.summary, cached=answer.cached), upload_bytes=counter.bytes)
    return NetworkFamilyBackend(calls, answer.handle, summary)


#: Most sets one BuildBatch call carries (the server's limit, server/build_batch_reactor.hpp).
MAX_BATCH_SETS = 100_000


class BatchAnswers:
    """Collects BuildBatch's answer pages: per set (handle, BuildSummary) or its GalphaError, in
    the stream's order; `counters` hold each set's upload bytes."""

    def __init__(self, counters: List[UploadCounter]) -> None:
        self.counters = counters
        self.sets: List[Any] = []

    def add(self, page: pb.BuildBatchResponse) -> None:
        count = len(self.counters)
        if page.first_set != len(self.sets) or page.set_count != count or len(self.sets) + len(page.sets) > count:
            raise GalphaError("the server's BuildBatch answer is out of order", code="DATA_LOSS", code_number=15)
        for answer in page.sets:
            if answer.code != 0:
                self.sets.append(error_for_code(answer.code, answer.message))
                continue
            if not answer.result.handle:
                raise GalphaError(
                    f"the server's BuildBatch answer has set {len(self.sets)} built without a handle",
                    code="DATA_LOSS",
                    code_number=15,
                )
            summary = summary_from(answer.result.summary, cached=answer.result.cached)
            summary = dataclasses.replace(summary, upload_bytes=self.counters[len(self.sets)].bytes)
            self.sets.append((answer.result.handle, summary))

    def result(self) -> List[Any]:
        if len(self.sets) != len(self.counters):
            raise GalphaError(
                f"the server's BuildBatch answer ended after {len(self.sets)} of {len(self.counters)} sets",
                code="DATA_LOSS",
                code_number=15,
            )
        return self.sets


def build_batch_on_server(calls: Calls, sets: List[Tuple[str, np.ndarray]], encoding: str = "auto") -> List[Any]:
    """Uploads every set in one BuildBatch stream (each as a Build stream carries it, its chunks
    encoded on other threads) and returns, in their order, a NetworkFamilyBackend per set or the
    GalphaError of a set whose build alone failed. A stream the server refuses raises, naming the
    set; so does a KeyboardInterrupt, after cancelling the call."""
    check_batch_size(len(sets))
    if not sets:
        return []
    answers = BatchAnswers([UploadCounter() for _ in sets])

    def messages() -> Iterator[bytes]:
        for (name, points), counter in zip(sets, answers.counters):
            yield from upload_messages(name, points, None, encoding, counter)

    call = calls.build_batch(messages(), timeout=calls.timeout, metadata=calls.metadata())
    try:
        for page in call:
            answers.add(page)
    except grpc.RpcError as e:
        raise raise_from_rpc(e) from None
    except BaseException:
        call.cancel()
        raise
    return [a if isinstance(a, GalphaError) else NetworkFamilyBackend(calls, a[0], a[1]) for a in answers.result()]


def check_batch_size(count: int) -> None:
    if count > MAX_BATCH_SETS:
        raise InvalidInput(f"{count} sets; a batch carries at most {MAX_BATCH_SETS:,}: split them")


def wait_for_server(calls: Calls, deadline_s: float) -> None:
    """Blocks until the channel is ready (used by tests and examples that start a server)."""
    end = time.monotonic() + deadline_s
    grpc.channel_ready_future(calls.channel).result(timeout=max(0.0, end - time.monotonic()))
