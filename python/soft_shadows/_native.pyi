"""Type stubs of the extension module (built from python/src by maturin)."""

from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Vec3 = Union[Sequence[float], npt.NDArray[np.floating[Any]]]
FloatArray = npt.ArrayLike  # float32 or float64, any order
IntArray = npt.ArrayLike  # any integer dtype

class Scene:
    """A triangle scene: the occluders and the surfaces receivers lie on."""

    @staticmethod
    def from_arrays(
        vertices: FloatArray,
        indices: IntArray,
        opacity: Optional[FloatArray] = None,
        albedo: Optional[FloatArray] = None,
        drop_degenerate: bool = False,
    ) -> Scene:
        """One mesh: vertices (N, 3), indices (M, 3), opacity () or (M,), albedo (3,) or (M, 3)."""
    @staticmethod
    def from_meshes(meshes: list[tuple[Any, ...]], drop_degenerate: bool = False) -> Scene:
        """Several meshes, each (vertices, indices[, opacity[, albedo]])."""
    @property
    def triangle_count(self) -> int: ...
    @property
    def dropped_degenerate(self) -> int: ...
    @property
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]: ...
    @property
    def has_semi_opaque(self) -> bool: ...

class Camera:
    """A pinhole camera for the built-in rasterizer."""

    @staticmethod
    def look_at(eye: Vec3, target: Vec3, up: Optional[Vec3] = None, fov_y: float = 0.9) -> Camera:
        """A camera at eye looking at target; fov_y is the vertical field of view in radians."""
    @property
    def position(self) -> list[float]: ...
    @property
    def forward(self) -> list[float]: ...
    @property
    def fov_y(self) -> float: ...

class Light:
    """An area light; a planar light emits from the side its normal points to."""

    @staticmethod
    def rectangle(
        center: Vec3, half_u: Vec3, half_v: Vec3, radiance: Union[float, Vec3, None] = None,
        texture: Optional[FloatArray] = None,
    ) -> Light: ...
    @staticmethod
    def rectangle_facing(
        center: Vec3, normal: Vec3, width: float, height: float,
        radiance: Union[float, Vec3, None] = None, texture: Optional[FloatArray] = None,
    ) -> Light: ...
    @staticmethod
    def disk(
        center: Vec3, normal: Vec3, radius: float, radiance: Union[float, Vec3, None] = None,
        texture: Optional[FloatArray] = None,
    ) -> Light: ...
    @staticmethod
    def polygon(
        vertices: FloatArray, radiance: Union[float, Vec3, None] = None,
        texture: Optional[FloatArray] = None,
    ) -> Light: ...
    @staticmethod
    def sphere(
        center: Vec3, radius: float, radiance: Union[float, Vec3, None] = None,
        texture: Optional[FloatArray] = None,
    ) -> Light: ...
    @property
    def kind(self) -> str:
        """rectangle, disk, polygon, sphere, point or mesh."""
    @property
    def area(self) -> float: ...
    @property
    def center(self) -> list[float]: ...
    @property
    def textured(self) -> bool: ...

class Setup:
    """A built-in or loaded scene with its lights, camera and the loader's notes."""

    @property
    def name(self) -> str: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def lights(self) -> list[Light]: ...
    @property
    def camera(self) -> Optional[Camera]: ...
    @property
    def aspect(self) -> Optional[float]: ...
    @property
    def warnings(self) -> list[str]: ...
    def camera_or_default(self) -> Camera: ...

class Receivers:
    """Points V is estimated at; results come back in their shape."""

    @staticmethod
    def from_points(
        scene: Scene, points: FloatArray, normals: FloatArray, tolerance: Optional[float] = None
    ) -> Receivers: ...
    @staticmethod
    def from_camera(scene: Scene, camera: Camera, width: int, height: int) -> Receivers: ...
    @staticmethod
    def from_gbuffer(
        scene: Scene,
        positions: FloatArray,
        normals: FloatArray,
        valid: Optional[npt.NDArray[np.bool_]] = None,
        camera: Optional[Camera] = None,
        shading_normals: Optional[FloatArray] = None,
        albedo: Optional[FloatArray] = None,
        tolerance: Optional[float] = None,
    ) -> Receivers: ...
    @property
    def shape(self) -> list[int]: ...
    @property
    def valid_count(self) -> int: ...
    @property
    def unmatched(self) -> int: ...
    @property
    def has_camera(self) -> bool: ...
    def arrays(self) -> dict[str, npt.NDArray[Any]]:
        """position, geometric_normal, shading_normal, depth, triangle (-1: none), valid."""
    def __len__(self) -> int: ...

class LightResult:
    """One light's V with what was asked for."""

    index: int
    technique: str
    fallback_reason: Optional[str]
    skipped: bool
    visibility: npt.NDArray[np.float32]
    per_sample: Optional[npt.NDArray[np.bool_]]
    direct: Optional[npt.NDArray[np.float32]]
    stats: dict[str, Any]
    decision: Optional[dict[str, Any]]

class Frame:
    """Every light's V, the summed direct light and the statistics."""

    lights: list[LightResult]
    direct: Optional[npt.NDArray[np.float32]]
    stats: dict[str, Any]
    preparation: dict[str, Any]
    valid: npt.NDArray[np.bool_]
    technique: str
    @property
    def visibility(self) -> npt.NDArray[np.float32]:
        """V of the only light (an error with several: read lights[k].visibility)."""

def builtin_scenes() -> list[str]: ...
def builtin(name: str) -> Setup: ...
def load(path: Union[str, PathLike[str]], emissive_as_geometry: bool = False) -> Setup: ...
def techniques() -> list[dict[str, Any]]: ...
def estimate(
    technique: str,
    scene: Scene,
    lights: Union[Light, Sequence[Light]],
    receivers: Receivers,
    *,
    samples: Optional[int] = None,
    seed: int = 1,
    per_sample: bool = False,
    direct: bool = False,
    fallback: Optional[str] = None,
    progress: Optional[Callable[[int, int], None]] = None,
) -> Frame: ...
def sample_points(
    technique: str,
    light: Light,
    receivers: Receivers,
    *,
    samples: Optional[int] = None,
    seed: int = 1,
) -> npt.NDArray[np.float32]: ...
