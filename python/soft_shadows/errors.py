"""The exceptions of soft_shadows: every one is a ``ShadowError``."""


class ShadowError(Exception):
    """Base of every error the package raises."""

    #: The light the error concerns (its index in the list given), when several were given.
    light_index = None


class InvalidInputError(ShadowError, ValueError):
    """Bad input: an array's shape, dtype or values, a light, a scene, a camera, a file."""


class UnsupportedError(ShadowError):
    """A technique's refusal of an input it cannot handle.

    ``technique`` names the technique; ``reason`` is the refusal's kind, one of ``light``,
    ``semi_opaque``, ``textured_light``, ``open_meshes``, ``view`` (receivers without the camera
    the technique works in), ``no_adapter``, ``device_limit``, ``configuration``; ``detail`` is
    the reason in words.
    """

    technique = None
    reason = None
    detail = None


class LimitError(ShadowError):
    """Input over a documented limit (receivers, file or buffer sizes)."""


class DeviceError(ShadowError):
    """A GPU device or resource failure."""
