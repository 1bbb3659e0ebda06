"""galpha: the exact family of 2D alpha shapes of a point set, from Python.

Two clients with the same calls: ``galpha.connect("host:port")`` talks to a galpha server over
gRPC; ``galpha.local()`` runs the engine in this process. ``client.build(points)`` returns a
:class:`Family`, which answers every query (classify, shape, spectrum, master list, components,
optimal alpha, Betti numbers, persistence, holes) for every alpha at once::

    import galpha
    family = galpha.local().build(points)          # (N, 2) array, shapely points, GeoDataFrame
    polygon = family.shape(alpha=2.5)              # shapely MultiPolygon, holes included
"""

# The compiled parts (the engine extension and the gRPC stubs) are built into the CMake build
# tree's python/galpha directory; with it on sys.path too, both directories form this package.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)  # noqa: F821

from ._client import Client, LocalClient, NetworkClient, connect, local  # noqa: E402
from ._errors import (  # noqa: E402
    Cancelled,
    DeadlineExceeded,
    FailedPrecondition,
    GalphaError,
    Internal,
    InvalidInput,
    NotFound,
    OutOfRange,
    PermissionDenied,
    ResourceExhausted,
    Unauthenticated,
    Unavailable,
)
from ._family import Family, radius_from_alphashape  # noqa: E402
from ._files import PointFile, read_points  # noqa: E402
from ._groups import shapes_by_group  # noqa: E402
from ._handle import point_set_handle  # noqa: E402
from ._types import (  # noqa: E402
    BettiCurves,
    BuildSummary,
    ClassCounts,
    Classification,
    ComponentCurve,
    Endpoint,
    Hole,
    MasterList,
    Mode,
    Optimal,
    OptimalLevel,
    PersistenceDiagram,
    PersistencePairs,
    ShapePolygon,
    ShapeRings,
    SimplexClass,
    SimplexKind,
    VertexRule,
)


def connect_async(target, *, token=None, tls_ca=None, timeout=None):  # noqa: ANN001, ANN201
    """The asyncio (grpc.aio) variant of :func:`connect`; see :mod:`galpha.aio`."""
    from .aio import connect as _connect

    return _connect(target, token=token, tls_ca=tls_ca, timeout=timeout)


__all__ = [
    "connect",
    "connect_async",
    "local",
    "Client",
    "NetworkClient",
    "LocalClient",
    "Family",
    "radius_from_alphashape",
    "read_points",
    "shapes_by_group",
    "PointFile",
    "point_set_handle",
    "GalphaError",
    "InvalidInput",
    "NotFound",
    "ResourceExhausted",
    "DeadlineExceeded",
    "Cancelled",
    "Unauthenticated",
    "PermissionDenied",
    "Unavailable",
    "OutOfRange",
    "FailedPrecondition",
    "Internal",
    "BettiCurves",
    "BuildSummary",
    "ClassCounts",
    "Classification",
    "ComponentCurve",
    "Endpoint",
    "Hole",
    "MasterList",
    "Mode",
    "Optimal",
    "OptimalLevel",
    "PersistenceDiagram",
    "PersistencePairs",
    "ShapePolygon",
    "ShapeRings",
    "SimplexClass",
    "SimplexKind",
    "VertexRule",
]
