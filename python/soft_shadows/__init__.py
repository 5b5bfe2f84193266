"""Soft shadows from area lights: numpy in, visibility out.

Every technique of the soft-shadow workspace (ray-traced reference, depth complexity sampling,
soft shadow mapping, alias-free shadow maps, the ``auto`` chooser) behind one call::

    import numpy as np
    import soft_shadows as ss

    scene = ss.Scene.from_arrays(vertices, indices)           # (N, 3) floats, (M, 3) ints
    light = ss.Light.rectangle_facing((0, 2, 0), (0, -1, 0), 0.5, 0.5)
    receivers = ss.Receivers.from_points(scene, points, normals)
    frame = ss.estimate("dcs-64", scene, light, receivers)
    v = frame.visibility                                      # (n,) float32 in [0, 1]

The package converts arrays and calls the Rust crates; results are the Rust call's, bit for
bit. Errors are :class:`ShadowError` subclasses carrying the typed reason.
"""

from . import errors
from ._native import (
    Camera,
    Frame,
    Light,
    LightResult,
    Receivers,
    Scene,
    Setup,
    builtin,
    builtin_scenes,
    estimate,
    load,
    sample_points,
    techniques,
)
from .errors import DeviceError, InvalidInputError, LimitError, ShadowError, UnsupportedError

__all__ = [
    "Camera",
    "DeviceError",
    "Frame",
    "InvalidInputError",
    "Light",
    "LightResult",
    "LimitError",
    "Receivers",
    "Scene",
    "Setup",
    "ShadowError",
    "UnsupportedError",
    "builtin",
    "builtin_scenes",
    "errors",
    "estimate",
    "load",
    "sample_points",
    "techniques",
]
