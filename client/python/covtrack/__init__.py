"""covtrack: tracked poses with honest 6x6 covariances, and the screen error they cause.

Live streams (covtrack.Subscriber), transform graphs and scenes with their screen error
regions (covtrack.TransformGraph, covtrack.Scene, covtrack.object_regions) and LCM logs
as NumPy arrays (covtrack.read_log). The compiled part is covtrack._covtrack; see
README.md in the source tree (client/python/) for the whole API.
"""
from ._covtrack import (  # noqa: F401
    Camera,
    Device,
    Log,
    LogDamage,
    LogStream,
    ObjectRegions,
    Pose,
    Scene,
    Status,
    Stream,
    Subscriber,
    TransformGraph,
    UncertainPose,
    __version__,
    object_regions,
    read_log,
)

__all__ = [
    "Camera", "Device", "Log", "LogDamage", "LogStream", "ObjectRegions", "Pose", "Scene",
    "Status", "Stream", "Subscriber", "TransformGraph", "UncertainPose", "object_regions",
    "read_log",
]
