"""The network client against real galpha_server processes: every error class with the server's
code and message, the upload skipped for a set the server holds, Ctrl-C during an upload leaving
nothing behind, and the asyncio client giving the blocking client's answers."""

from __future__ import annotations

import asyncio
import os
import re
import signal
import socket

import threading

import numpy as np
import pytest
from conftest import DATA_SETS, read_bin

import galpha
import galpha.aio


def square_with_center() -> np.ndarray:
    return np.array([[0, 0], [2, 0], [2, 2], [0, 2], [1, 1]], dtype=np.float64)


def test_invalid_input_names_the_point(client) -> None:
    with pytest.raises(galpha.InvalidInput) as e:
        client.build(np.array([[0, 0], [1, 0], [0, np.nan]]))
    assert e.value.code == "INVALID_ARGUMENT" and e.value.code_number == 3
    assert "point 2" in e.value.message
    # Outside the input domain: refused by the engine, named by the server's answer.
    with pytest.raises(galpha.InvalidInput, match=r"point 3 .*2\^500"):
        client.build(np.array([[0, 0], [1, 0], [0, 1], [1e308, 1e308]]))
    family = client.build(square_with_center())
    with pytest.raises(galpha.InvalidInput, match="rank 9 is outside 0..2"):
        family.classify(rank=9)
    with pytest.raises(galpha.InvalidInput, match="exactly one of"):
        family.classify(rank=1, alpha=2.0)
    with pytest.raises(galpha.InvalidInput, match="unknown mode"):
        family.classify(rank=1, mode="solid")
    with pytest.raises(galpha.InvalidInput, match=r"shape \(N, 2\)"):
        client.build(np.zeros((4, 3)))


def test_not_found_after_release(client) -> None:
    family = client.build(square_with_center() + 10.0)
    assert family.release() is True
    assert family.release() is False  # idempotent
    with pytest.raises(galpha.NotFound) as e:
        family.classify(rank=1)
    assert e.value.code == "NOT_FOUND"
    assert isinstance(e.value, KeyError) and isinstance(e.value, galpha.GalphaError)


def test_resource_exhausted_names_the_limit(start_server) -> None:
    server = start_server("--max_points_per_build=100")
    with galpha.connect(server.address, timeout=60) as c:
        with pytest.raises(galpha.ResourceExhausted, match="100"):
            c.build(np.random.default_rng(1).random((150, 2)))
        assert c.build(np.random.default_rng(1).random((100, 2))).summary.points == 100


def test_unauthenticated_without_the_token(start_server, tmp_path) -> None:
    tokens = tmp_path / "tokens"
    tokens.write_text("s3cret team-a\n")
    server = start_server(f"--token_file={tokens}")
    with galpha.connect(server.address, timeout=60) as c:
        with pytest.raises(galpha.Unauthenticated):
            c.build(square_with_center())
    with galpha.connect(server.address, token="wrong", timeout=60) as c:
        with pytest.raises(galpha.Unauthenticated):
            c.build(square_with_center())
    with galpha.connect(server.address, token="s3cret", timeout=60) as c:
        assert c.build(square_with_center()).spectrum().tolist() == [0.5, 1.0]


def test_unavailable_when_nobody_listens() -> None:
    with socket.socket() as s:  # a port that was free a moment ago, now closed
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with galpha.connect(f"127.0.0.1:{port}", timeout=5) as c:
        with pytest.raises(galpha.Unavailable):
            c.build(square_with_center())


def test_deadline_exceeded(server) -> None:
    points = np.random.default_rng(7).random((400_000, 2))
    with galpha.connect(server.address, timeout=0.001) as c:
        with pytest.raises(galpha.DeadlineExceeded):
            c.build(points)


def test_every_code_has_its_class() -> None:
    for number, cls in [
        (1, galpha.Cancelled),
        (3, galpha.InvalidInput),
        (4, galpha.DeadlineExceeded),
        (5, galpha.NotFound),
        (7, galpha.PermissionDenied),
        (8, galpha.ResourceExhausted),
        (9, galpha.FailedPrecondition),
        (11, galpha.OutOfRange),
        (13, galpha.Internal),
        (14, galpha.Unavailable),
        (16, galpha.Unauthenticated),
    ]:
        error = galpha._errors.error_for_code(number, "why")
        assert type(error) is cls and error.code_number == number and error.message == "why"
    unknown = galpha._errors.error_for_code(12, "no")
    assert type(unknown) is galpha.GalphaError and unknown.code == "UNIMPLEMENTED"


def test_a_set_the_server_holds_is_not_uploaded_again(client) -> None:
    points = np.random.default_rng(3).random((70_000, 2))
    first = client.build(points, name="first")
    assert first.summary.cached is False and first.summary.name == "first"
    stages = []
    second = client.build(points.copy(), name="second", progress=lambda stage, f: stages.append(stage))
    assert second.handle == first.handle == galpha.point_set_handle(points)
    assert second.summary.cached is True and second.summary.name == "second"
    assert "upload" in stages and len(stages) == 1  # one report: nothing was streamed


def test_progress_covers_the_upload_and_the_build(client) -> None:
    points = np.random.default_rng(21).random((300_000, 2))
    reports = []
    client.build(points, progress=lambda stage, fraction: reports.append((stage, fraction)))
    stages = [stage for stage, _ in reports]
    assert stages[0] == "upload" and ("upload", 1.0) in reports
    first_build = stages.index("build")
    assert set(stages[first_build:]) == {"build"}, "the build's reports follow the whole upload"
    assert reports[-1] == ("build", 1.0)
    fractions = [f for s, f in reports if s == "upload"]
    assert fractions == sorted(fractions)


def test_ctrl_c_during_an_upload_leaves_nothing_behind(start_server) -> None:
    # Room for one 200K-point set (3.2 MB) in flight, not two: a leaked reservation would refuse
    # the second upload.
    server = start_server("--max_in_flight_bytes=4000000", "--max_tenant_in_flight_bytes=0")
    rng = np.random.default_rng(11)
    interrupted = rng.random((200_000, 2))

    def interrupt(stage: str, fraction: float) -> None:
        # A real Ctrl-C: SIGINT to this process, delivered to the main thread mid-upload.
        if fraction > 0.3 and not sent[0]:
            sent[0] = True
            os.kill(os.getpid(), signal.SIGINT)

    sent = [False]

    with galpha.connect(server.address, timeout=60) as c:
        with pytest.raises(KeyboardInterrupt):
            c.build(interrupted, progress=interrupt)
        with pytest.raises(galpha.NotFound):
            c.family(galpha.point_set_handle(interrupted), interrupted)
        other = c.build(rng.random((200_000, 2)))
        assert other.summary.points == 200_000
    assert re.search(r'galpha_rpcs_total\{code="CANCELLED",method="Build"\} 1', server.metrics())


def test_a_raising_progress_callback_cancels_the_upload(server) -> None:
    points = np.random.default_rng(12).random((300_000, 2))

    def fail(stage: str, fraction: float) -> None:
        raise RuntimeError("stop here")

    with galpha.connect(server.address, timeout=60) as c:
        with pytest.raises(RuntimeError, match="stop here"):
            c.build(points, progress=fail)
        with pytest.raises(galpha.NotFound):
            c.family(galpha.point_set_handle(points), points)


def test_asyncio_client_gives_the_same_answers(server) -> None:
    points = read_bin(DATA_SETS[0])

    async def run() -> tuple:
        async with galpha.aio.connect(server.address, timeout=60) as c:
            family = await c.build(points)
            k = family.summary.spectrum_size
            return (
                family.handle,
                await family.spectrum(),
                await family.classify(rank=k // 2),
                await family.shape(rank=k // 2),
                await family.master_list(k // 3),
                await family.components(),
                await family.optimal(2),
            )

    handle, spectrum, classes, shape, master, curve, optimal = asyncio.run(run())
    with galpha.connect(server.address, timeout=60) as c:
        family = c.build(points)
        k = family.spectrum_size
        assert handle == family.handle
        np.testing.assert_array_equal(spectrum, family.spectrum())
        sync = family.classify(rank=k // 2)
        for field in ("vertices", "vertex_classes", "edges", "edge_classes", "triangles", "triangle_classes"):
            np.testing.assert_array_equal(getattr(classes, field), getattr(sync, field))
        assert shape.equals(family.shape(rank=k // 2))
        np.testing.assert_array_equal(master.vertex_indices, family.master_list(k // 3).vertex_indices)
        np.testing.assert_array_equal(curve.components, family.components().components)
        assert optimal == family.optimal(2)


def test_every_answer_encoding_gives_the_raw_answer(server, monkeypatch) -> None:
    # Shuffled points with more than one chunk (131,072 simplices) of edges and of triangles, and a
    # data set in its own order; both modes, and the non-exterior part. The compact encodings are
    # decoded by the compiled module (on the pool) and by the NumPy decoder (the module hidden).
    from galpha import _network, _wire

    sets = [np.random.default_rng(5).random((60000, 2)), read_bin(DATA_SETS[0])]
    for points in sets:
        answers = {}
        for encoding, decoder in (("raw", ""), ("delta", ""), ("zstd", ""), ("delta", "numpy"), ("zstd", "numpy")):
            with monkeypatch.context() as patch:
                if decoder == "numpy":
                    patch.setattr(_wire, "native_section_reader", lambda: None)
                    patch.setattr(_network, "_decode_thread", threading.local())
                with galpha.connect(server.address, timeout=60, answer_encoding=encoding) as c:
                    family = c.build(points)
                    k = family.spectrum_size
                    answers[encoding + decoder] = [
                        family.classify(rank=k // 2),
                        family.classify(rank=k // 3, mode="regularized"),
                        family.classify(rank=k // 2, non_exterior_only=True),
                    ]
            monkeypatch.setattr(_network, "_decode_thread", threading.local())  # readers of the module again
        for encoding in ("delta", "zstd", "deltanumpy", "zstdnumpy"):
            for got, want in zip(answers[encoding], answers["raw"]):
                for field in ("vertices", "vertex_classes", "edges", "edge_classes", "triangles", "triangle_classes"):
                    np.testing.assert_array_equal(getattr(got, field), getattr(want, field), err_msg=f"{encoding} {field}")
                    assert getattr(got, field).dtype == getattr(want, field).dtype


def test_auto_asks_for_delta_where_the_compiled_module_decodes_it(monkeypatch) -> None:
    from galpha import _network, _wire

    with galpha.connect("localhost:1") as c:
        assert c._calls.simplex_encoding == _network.ANSWER_ENCODINGS["delta"]
    monkeypatch.setattr(_wire, "native_section_reader", lambda: None)
    with galpha.connect("localhost:1") as c:
        assert c._calls.simplex_encoding == _network.ANSWER_ENCODINGS["raw"]


def test_an_unknown_answer_encoding_is_refused() -> None:
    with pytest.raises(galpha.InvalidInput, match="answer_encoding is 'auto', 'raw', 'delta' or 'zstd', not 'gzip'"):
        galpha.connect("localhost:1", answer_encoding="gzip")
    with pytest.raises(galpha.InvalidInput, match="answer_encoding"):
        galpha.aio.connect("localhost:1", answer_encoding="lz4")


def test_classify_read_in_parts_is_the_one_call_answer(server, monkeypatch) -> None:
    from galpha import _network

    # Shuffled points with several chunks of every kind (131,072 simplices a chunk), in parts dealt
    # round-robin by the server and merged back by the client, sync and asyncio, raw and delta.
    points = np.random.default_rng(7).random((160000, 2))
    fields = ("vertices", "vertex_classes", "edges", "edge_classes", "triangles", "triangle_classes")

    def answers(c) -> list:
        family = c.build(points)
        k = family.spectrum_size
        return [family.classify(rank=k // 2), family.classify(rank=k // 3, non_exterior_only=True)]

    async def answers_aio(parts: int, encoding: str) -> list:
        async with galpha.aio.connect(server.address, timeout=60, classify_parts=parts, answer_encoding=encoding) as c:
            family = await c.build(points)
            k = family.summary.spectrum_size
            return [await family.classify(rank=k // 2), await family.classify(rank=k // 3, non_exterior_only=True)]

    with galpha.connect(server.address, timeout=60, classify_parts=1, answer_encoding="raw") as c:
        want = answers(c)
    # Every split answer goes through merge_parts: none was read whole from each part.
    merged = []
    real_merge = _network.merge_parts
    monkeypatch.setattr(_network, "merge_parts", lambda parts: merged.append(len(parts)) or real_merge(parts))
    for parts in (2, 5, 64, 0):
        for encoding in ("raw", "delta"):
            with galpha.connect(server.address, timeout=60, classify_parts=parts, answer_encoding=encoding) as c:
                got = answers(c)
            got_aio = asyncio.run(answers_aio(parts, encoding))
            for g, a, w in zip(got, got_aio, want):
                assert (g.level, g.interior_area, g.components) == (w.level, w.interior_area, w.components)
                for field in fields:
                    np.testing.assert_array_equal(getattr(g, field), getattr(w, field), err_msg=f"{parts} parts {field}")
                    np.testing.assert_array_equal(getattr(a, field), getattr(w, field), err_msg=f"aio {parts} {field}")
    # Two answers, sync and asyncio, two encodings: 8 merges a part count (0 on 2 cores is one call).
    assert len(merged) == sum(8 for parts in (2, 5, 64, 0) if _network.classify_parts_count(parts) > 1)


def test_classify_in_parts_from_a_server_that_does_not_split(server, monkeypatch) -> None:
    # A server older than part_count answers every part whole (simulated: the requests go without
    # the part fields). The client keeps part 0's answer and cancels the others.
    from galpha import _network

    points = np.random.default_rng(8).random((60000, 2))
    with galpha.connect(server.address, timeout=60, classify_parts=1) as c:
        family = c.build(points)
        k = family.spectrum_size
        want = family.classify(rank=k // 2)
    monkeypatch.setattr(_network, "part_requests", lambda request, parts: [request] * parts)
    monkeypatch.setattr(_network, "merge_parts", lambda parts: pytest.fail("the whole answers were merged"))

    async def aio_answer():
        async with galpha.aio.connect(server.address, timeout=60, classify_parts=4) as c:
            return await (await c.build(points)).classify(rank=k // 2)

    with galpha.connect(server.address, timeout=60, classify_parts=4) as c:
        got = c.build(points).classify(rank=k // 2)
    got_aio = asyncio.run(aio_answer())
    for field in ("vertices", "vertex_classes", "edges", "edge_classes", "triangles", "triangle_classes"):
        np.testing.assert_array_equal(getattr(got, field), getattr(want, field), err_msg=field)
        np.testing.assert_array_equal(getattr(got_aio, field), getattr(want, field), err_msg=field)


def test_merge_parts_deals_chunks_back_and_refuses_what_does_not_fit() -> None:
    from galpha import _network
    from galpha.v1 import alpha_shapes_pb2 as pb

    summary = pb.ClassifyResponse(summary=pb.ClassifySummary(level=3)).SerializeToString()
    chunks = [
        pb.ClassifyResponse(chunk=pb.SimplexChunk(kind=pb.SIMPLEX_KIND_VERTEX, vertex_indices=[c], classes=b"\x01")).SerializeToString()
        for c in range(7)
    ]
    whole = [summary] + chunks
    for count in (2, 3, 8):
        parts = [([summary] if p == 0 else []) + chunks[p::count] for p in range(count)]
        assert _network.merge_parts(parts) == whole
    # A server that ignores part_count answers every part whole: part 0 is the answer.
    assert _network.merge_parts([whole, whole, whole]) == whole
    assert _network.merge_parts([[summary], [summary]]) == [summary]
    with pytest.raises(galpha.GalphaError, match="part 1 of 2 of the server's Classify answer sent chunks past"):
        _network.merge_parts([[summary, chunks[0]], [chunks[1], chunks[3]]])
    with pytest.raises(galpha.GalphaError, match="did not start with the summary"):
        _network.merge_parts([[chunks[0]], [chunks[1]]])


def test_classify_parts_out_of_range_are_refused() -> None:
    for bad in (-1, 65, "4", True, 2.0):
        with pytest.raises(galpha.InvalidInput, match="classify_parts is a number of parts from 1 to 64"):
            galpha.connect("localhost:1", classify_parts=bad)
        with pytest.raises(galpha.InvalidInput, match="classify_parts"):
            galpha.aio.connect("localhost:1", classify_parts=bad)


def test_build_batch_gives_each_set_its_own_family(server) -> None:
    # Sets of a layer's kind, an empty one and a repeated one among them; the oracle is each set
    # built alone, in this process.
    rng = np.random.default_rng(31)
    sets = {
        "uniform": rng.random((800, 2)),
        "grid": np.array([[i, j] for i in range(20) for j in range(15)], dtype=np.float64),
        "line": np.column_stack([np.arange(50.0), np.zeros(50)]),
        "empty": np.empty((0, 2)),
    }
    sets["again"] = sets["uniform"].copy()
    with galpha.connect(server.address, timeout=60) as c:
        families = c.build_batch(sets)
        assert [f.summary.name for f in families] == list(sets)
        for (name, points), family in zip(sets.items(), families):
            local = galpha.local("cpu").build(points)
            assert family.handle == galpha.point_set_handle(points), name
            assert family.spectrum_size == local.spectrum_size, name
            assert family.summary.triangles == local.summary.triangles, name
            if family.spectrum_size:
                k = family.spectrum_size // 2
                got, want = family.classify(rank=k), local.classify(rank=k)
                np.testing.assert_array_equal(got.triangles, want.triangles)
                np.testing.assert_array_equal(got.triangle_classes, want.triangle_classes)
        assert families[-1].summary.cached  # the repeat of "uniform"
        # Pairs work too, and a second call finds every family.
        again = c.build_batch(list(sets.items())[:2], encoding="raw")
        assert [f.handle for f in again] == [f.handle for f in families[:2]]
        assert all(f.summary.cached for f in again)


def test_build_batch_errors_name_the_set(start_server) -> None:
    # A cache too small for the large set: its build alone fails; the small ones are built.
    s = start_server("--cache_bytes", "200000")
    small, large = np.random.default_rng(1).random((40, 2)), np.random.default_rng(2).random((20000, 2))
    with galpha.connect(s.address, timeout=60) as c:
        with pytest.raises(galpha.ResourceExhausted, match="set 'large': .*cache"):
            c.build_batch([("small", small), ("large", large)])
        results = c.build_batch([("small", small), ("large", large)], return_exceptions=True)
        assert isinstance(results[0], galpha.Family) and results[0].summary.cached
        assert isinstance(results[1], galpha.ResourceExhausted)
        assert c.build_batch({}) == []
        with pytest.raises(galpha.InvalidInput, match="a mapping of name to points"):
            c.build_batch([small])
        # A set with a NaN fails the whole call, naming the set by its index and name.
        bad = small.copy()
        bad[3, 0] = np.nan
        with pytest.raises(galpha.InvalidInput, match="set 1 \\('bad'\\)"):
            c.build_batch([("fine", small), ("bad", bad)], encoding="raw")


def test_asyncio_build_batch_gives_the_families_of_the_sync_one(server) -> None:
    sets = [("a", np.random.default_rng(41).random((300, 2))), ("b", np.random.default_rng(42).random((500, 2)))]

    async def run() -> list:
        async with galpha.aio.connect(server.address, timeout=60) as c:
            families = await c.build_batch(sets)
            return [(f.handle, f.summary.name, (await f.classify(rank=f.summary.spectrum_size // 2)).triangles) for f in families]

    got = asyncio.run(run())
    with galpha.connect(server.address, timeout=60) as c:
        for (handle, name, triangles), family, (set_name, _) in zip(got, c.build_batch(sets), sets):
            assert handle == family.handle and name == set_name
            np.testing.assert_array_equal(triangles, family.classify(rank=family.spectrum_size // 2).triangles)
