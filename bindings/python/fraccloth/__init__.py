"""fraccloth: underwater cloth without simulating the water (ctypes bindings).

Units are SI: metres, kilograms, seconds. Positions and velocities cross as float32
arrays of shape (N, 3). Every failing call raises :class:`Error`; the cloth is then
exactly as it was before the call.
"""

from __future__ import annotations

import ctypes
import os
from pathlib import Path
from typing import Iterable, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _abi

__all__ = [
    "Error",
    "Cloth",
    "Cache",
    "default_desc",
    "preset_desc",
    "library",
    "version",
    "FcClothDesc",
    "SolverStats",
    "StepStats",
    "CollisionStats",
    "StepLimitStats",
    "MAX_SUBSTEP_AUTO",
    "PRESET_FRACTIONAL_PAPER",
    "PRESET_REGULAR_VISCOUS_NORMAL",
    "PRESET_REGULAR_VISCOUS",
    "PRESET_REGULAR_NORMAL",
    "PRESET_UNDERWATER",
    "HISTORY_OFF",
    "HISTORY_TRUNCATED",
    "HISTORY_FULL",
    "HISTORY_SOE",
    "INTEGRATOR_EXPLICIT_EULER",
    "INTEGRATOR_SYMPLECTIC_EULER",
    "INTEGRATOR_IMPLICIT_EULER",
    "INTEGRATOR_EXTRAPOLATED_SYMPLECTIC",
    "INTEGRATOR_EXTRAPOLATED_IMPLICIT",
    "INTEGRATOR_XPBD",
    "SPRING_DAMPING_NONE",
    "SPRING_DAMPING_VELOCITY",
    "SPRING_DAMPING_FRACTIONAL",
    "SPRING_DAMPING_FRACTIONAL_STRAIN",
    "CACHE_PC2",
    "CACHE_MDD",
    "CACHE_OBJ_SEQUENCE",
]

_HERE = Path(__file__).resolve().parent
_LIB_DIR = _HERE / "_lib"


def _library_path() -> Path:
    given = os.environ.get("FRACCLOTH_LIBRARY")
    if given:
        return Path(given)
    for name in ("libfraccloth.so", "libfraccloth.dylib", "fraccloth.dll"):
        if (_LIB_DIR / name).exists():
            return _LIB_DIR / name
    raise ImportError(
        f"fraccloth: no shared library in {_LIB_DIR}; install with `pip install ./bindings/python` "
        "from the repository, or set FRACCLOTH_LIBRARY"
    )


def _desc_doc() -> str:
    lines = [
        "Description of a cloth: the C struct FcClothDesc (SI units: m, kg, s, N).",
        "",
        "Start from default_desc() or preset_desc() and change fields; a misspelt field raises",
        "AttributeError. Fields:",
        "",
    ]
    for name, _, doc in _abi.DESC_FIELDS:
        lines.append(f"{name}: {doc}")
    return "\n".join(lines)


# No instance dictionary: assigning a field the struct does not have (a typo such as
# `desc.sping_damping = 0.5`) raises AttributeError instead of being silently kept aside.
class FcClothDesc(ctypes.Structure):
    __slots__ = ()
    _fields_ = [(name, ctype) for name, ctype, _ in _abi.DESC_FIELDS]

    def __repr__(self) -> str:
        """Every field and its value, one per line (`print(desc)`)."""
        def show(value):
            return "(" + ", ".join(repr(v) for v in value) + ")" if isinstance(value, ctypes.Array) else repr(value)

        return "FcClothDesc(\n" + "".join(f"    {name}={show(getattr(self, name))},\n" for name, _, _ in _abi.DESC_FIELDS) + ")"


FcClothDesc.__doc__ = _desc_doc()
_ENUMS = _abi.ENUMS

PRESET_FRACTIONAL_PAPER: int = _ENUMS["FC_PRESET_FRACTIONAL_PAPER"]
PRESET_REGULAR_VISCOUS_NORMAL: int = _ENUMS["FC_PRESET_REGULAR_VISCOUS_NORMAL"]
PRESET_REGULAR_VISCOUS: int = _ENUMS["FC_PRESET_REGULAR_VISCOUS"]
PRESET_REGULAR_NORMAL: int = _ENUMS["FC_PRESET_REGULAR_NORMAL"]
PRESET_UNDERWATER: int = _ENUMS["FC_PRESET_UNDERWATER"]
HISTORY_OFF: int = _ENUMS["FC_HISTORY_OFF"]
HISTORY_TRUNCATED: int = _ENUMS["FC_HISTORY_TRUNCATED"]
HISTORY_FULL: int = _ENUMS["FC_HISTORY_FULL"]
HISTORY_SOE: int = _ENUMS["FC_HISTORY_SOE"]
#: ``FcClothDesc.max_substep`` for the automatic step (``FC_MAX_SUBSTEP_AUTO``): ``step(dt)``
#: splits ``dt`` into as few substeps as the cloth needs and retries a refused one with twice as
#: many. The underwater preset uses it.
MAX_SUBSTEP_AUTO: float = -1.0
INTEGRATOR_EXPLICIT_EULER: int = _ENUMS["FC_INTEGRATOR_EXPLICIT_EULER"]
INTEGRATOR_SYMPLECTIC_EULER: int = _ENUMS["FC_INTEGRATOR_SYMPLECTIC_EULER"]
INTEGRATOR_IMPLICIT_EULER: int = _ENUMS["FC_INTEGRATOR_IMPLICIT_EULER"]
INTEGRATOR_EXTRAPOLATED_SYMPLECTIC: int = _ENUMS["FC_INTEGRATOR_EXTRAPOLATED_SYMPLECTIC"]
INTEGRATOR_EXTRAPOLATED_IMPLICIT: int = _ENUMS["FC_INTEGRATOR_EXTRAPOLATED_IMPLICIT"]
INTEGRATOR_XPBD: int = _ENUMS["FC_INTEGRATOR_XPBD"]
SPRING_DAMPING_NONE: int = _ENUMS["FC_SPRING_DAMPING_NONE"]
SPRING_DAMPING_VELOCITY: int = _ENUMS["FC_SPRING_DAMPING_VELOCITY"]
SPRING_DAMPING_FRACTIONAL: int = _ENUMS["FC_SPRING_DAMPING_FRACTIONAL"]
SPRING_DAMPING_FRACTIONAL_STRAIN: int = _ENUMS["FC_SPRING_DAMPING_FRACTIONAL_STRAIN"]
CACHE_PC2: int = _ENUMS["FC_CACHE_PC2"]
CACHE_MDD: int = _ENUMS["FC_CACHE_MDD"]
CACHE_OBJ_SEQUENCE: int = _ENUMS["FC_CACHE_OBJ_SEQUENCE"]

library = ctypes.CDLL(str(_library_path()))

_c = ctypes
_P = ctypes.c_void_p
_F3 = ctypes.POINTER(ctypes.c_float)
_U32P = ctypes.POINTER(ctypes.c_uint32)
_U64P = ctypes.POINTER(ctypes.c_uint64)
_D3 = ctypes.POINTER(ctypes.c_double)
_SIGNATURES = {
    "fc_last_error_message": (_c.c_char_p, []),
    "fc_status_string": (_c.c_char_p, [_c.c_int32]),
    "fc_version": (_c.c_uint32, []),
    "fc_cloth_desc_init": (_c.c_int, [_c.POINTER(FcClothDesc), _c.c_size_t]),
    "fc_cloth_desc_preset_sized": (_c.c_int, [_c.c_uint32, _c.POINTER(FcClothDesc), _c.c_size_t]),
    "fc_cloth_create_grid": (_c.c_int, [_c.POINTER(FcClothDesc), _c.POINTER(_P)]),
    "fc_cloth_create_mesh": (
        _c.c_int,
        [_c.POINTER(FcClothDesc), _F3, _c.c_size_t, _U32P, _c.c_size_t, _c.c_uint32, _c.POINTER(_P)],
    ),
    "fc_cloth_destroy": (None, [_P]),
    "fc_cloth_vertex_count": (_c.c_size_t, [_P]),
    "fc_cloth_triangle_count": (_c.c_size_t, [_P]),
    "fc_cloth_time": (_c.c_double, [_P]),
    "fc_cloth_set_pinned": (_c.c_int, [_P, _U32P, _c.c_size_t]),
    "fc_cloth_set_pin_weights": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_pin_group": (_c.c_int, [_P, _U32P, _c.c_size_t, _c.c_float]),
    "fc_cloth_set_pin_targets": (_c.c_int, [_P, _U32P, _F3, _c.c_size_t]),
    "fc_cloth_set_positions": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_get_positions": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_get_velocities": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_set_velocities": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_get_triangles": (_c.c_int, [_P, _U32P, _c.c_size_t]),
    "fc_cloth_get_desc_sized": (_c.c_int, [_P, _c.POINTER(FcClothDesc), _c.c_size_t]),
    "fc_cloth_set_desc": (_c.c_int, [_P, _c.POINTER(FcClothDesc)]),
    "fc_cloth_get_normals": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cloth_get_positions_f64": (_c.c_int, [_P, _D3, _c.c_size_t]),
    "fc_cloth_set_positions_f64": (_c.c_int, [_P, _D3, _c.c_size_t]),
    "fc_cloth_get_velocities_f64": (_c.c_int, [_P, _D3, _c.c_size_t]),
    "fc_cloth_set_velocities_f64": (_c.c_int, [_P, _D3, _c.c_size_t]),
    "fc_cloth_set_current": (_c.c_int, [_P, _F3]),
    "fc_cloth_set_current_f64": (_c.c_int, [_P, _D3]),
    "fc_cloth_set_threads": (_c.c_int, [_P, _c.c_uint32]),
    "fc_cloth_get_threads": (_c.c_uint32, [_P]),
    "fc_cloth_set_solver": (_c.c_int, [_P, _c.c_double, _c.c_uint32]),
    "fc_cloth_get_solver_stats": (_c.c_int, [_P, _U32P, _D3]),
    "fc_cloth_get_step_stats": (_c.c_int, [_P, _U32P, _U32P, _D3]),
    "fc_cloth_get_collision_stats": (_c.c_int, [_P, _U64P, _U64P, _U64P, _U64P, _U64P]),
    "fc_cloth_get_step_limit_stats": (_c.c_int, [_P, _U64P, _U64P, _U64P]),
    "fc_cloth_set_solver_accept_unconverged": (_c.c_int, [_P, _c.c_int32]),
    "fc_cloth_snapshot_size": (_c.c_size_t, [_P]),
    "fc_cloth_save_snapshot": (_c.c_int, [_P, _P, _c.c_size_t, _c.POINTER(_c.c_size_t)]),
    "fc_cloth_load_snapshot": (_c.c_int, [_P, _P, _c.c_size_t]),
    "fc_cloth_step": (_c.c_int, [_P, _c.c_double]),
    "fc_cloth_step_substeps": (_c.c_int, [_P, _c.c_double, _c.c_uint32]),
    "fc_cloth_history_mode_count": (_c.c_uint32, [_P]),
    "fc_cloth_history_bytes_per_particle": (_c.c_size_t, [_P]),
    "fc_cloth_add_sphere": (_c.c_int, [_P, _F3, _c.c_float, _F3, _U32P]),
    "fc_cloth_add_mesh_collider": (_c.c_int, [_P, _F3, _c.c_size_t, _U32P, _c.c_size_t, _F3, _U32P]),
    "fc_cloth_set_mesh_collider": (_c.c_int, [_P, _c.c_uint32, _F3, _c.c_size_t, _F3]),
    "fc_cloth_get_mesh_collider": (_c.c_int, [_P, _c.c_uint32, _c.POINTER(_c.c_size_t), _c.POINTER(_c.c_size_t)]),
    "fc_cloth_set_sphere": (_c.c_int, [_P, _c.c_uint32, _F3, _c.c_float, _F3]),
    "fc_cloth_add_plane": (_c.c_int, [_P, _F3, _F3, _F3, _U32P]),
    "fc_cloth_set_plane": (_c.c_int, [_P, _c.c_uint32, _F3, _F3, _F3]),
    "fc_cloth_add_capsule": (_c.c_int, [_P, _F3, _F3, _c.c_float, _F3, _U32P]),
    "fc_cloth_set_capsule": (_c.c_int, [_P, _c.c_uint32, _F3, _F3, _c.c_float, _F3]),
    "fc_cloth_set_collider_friction": (_c.c_int, [_P, _c.c_uint32, _c.c_float]),
    "fc_cloth_set_collider_margin": (_c.c_int, [_P, _c.c_uint32, _c.c_float]),
    "fc_cloth_get_collider_margin": (_c.c_int, [_P, _c.c_uint32, _c.POINTER(_c.c_float)]),
    "fc_cloth_remove_collider": (_c.c_int, [_P, _c.c_uint32]),
    "fc_cloth_get_sphere": (_c.c_int, [_P, _c.c_uint32, _F3, _c.POINTER(_c.c_float)]),
    "fc_cloth_get_plane": (_c.c_int, [_P, _c.c_uint32, _F3, _F3, _F3]),
    "fc_cloth_get_capsule": (_c.c_int, [_P, _c.c_uint32, _F3, _F3, _c.POINTER(_c.c_float), _F3]),
    "fc_cloth_write_obj": (_c.c_int, [_P, _c.c_char_p]),
    "fc_cache_open": (
        _c.c_int,
        [_c.c_char_p, _c.c_uint32, _P, _c.c_double, _c.c_double, _c.c_uint32, _c.POINTER(_P)],
    ),
    "fc_cache_write_frame": (_c.c_int, [_P, _P]),
    "fc_cache_write_positions": (_c.c_int, [_P, _F3, _c.c_size_t]),
    "fc_cache_close": (_c.c_int, [_P]),
}
for _name, (_res, _args) in _SIGNATURES.items():
    try:
        _fn = getattr(library, _name)
    except AttributeError:
        raise ImportError(
            f"fraccloth: {library._name} has no {_name}: the library is older than this package"
        ) from None
    _fn.restype = _res
    _fn.argtypes = _args


def _typed(fn, name):
    """`fn` with ctypes' conversion errors (`ctypes.ArgumentError`, which names neither the call
    nor the value) raised as a `TypeError` that names the call."""

    def call(*args):
        try:
            return fn(*args)
        except ctypes.ArgumentError as e:
            raise TypeError(f"fraccloth: {name} got an argument it cannot take ({e}): "
                            "numbers where the documentation says a number, arrays where it says an array") from None

    call.__name__ = name
    return call


for _name in _SIGNATURES:
    setattr(library, _name, _typed(getattr(library, _name), _name))


def _check_layout() -> None:
    """The description struct as this package lays it out against the loaded library: the
    library accepts its size (the struct_size rule) and fills the fields at both ends where
    this package expects them."""
    d = FcClothDesc()
    status = library.fc_cloth_desc_init(ctypes.byref(d), ctypes.sizeof(FcClothDesc))
    if status != 0:
        raise ImportError(
            "fraccloth: the library refuses this package's FcClothDesc "
            f"({ctypes.sizeof(FcClothDesc)} bytes): {library.fc_last_error_message().decode()}"
        )
    got = (d.struct_size, d.width, d.height, round(d.spacing, 6), d.max_speed)
    want = (ctypes.sizeof(FcClothDesc), 61, 41, 0.01, 100.0)
    if got != want:
        raise ImportError(f"fraccloth: FcClothDesc layout mismatch with {library._name}: {got} != {want}")


_check_layout()


class Error(RuntimeError):
    """A failed call: `status` (an FcStatus value) and the library's message."""

    def __init__(self, status: int, message: str):
        name = library.fc_status_string(status).decode()
        super().__init__(f"{name}: {message}")
        self.status = status
        self.message = message


def _check(status: int) -> None:
    if status != 0:
        raise Error(status, library.fc_last_error_message().decode(errors="replace"))


def _floats(values, shape_last: Optional[int] = 3) -> np.ndarray:
    a = np.ascontiguousarray(values, dtype=np.float32)
    if shape_last is not None and a.size % shape_last != 0:
        raise ValueError(f"expected a multiple of {shape_last} floats, got {a.size}")
    return a


def _doubles(values) -> np.ndarray:
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.size % 3 != 0:
        raise ValueError(f"expected a multiple of 3 values, got {a.size}")
    return a


def _u32(values) -> np.ndarray:
    a = np.asarray(values)
    if a.size and (a.min() < 0 or a.max() > 0xFFFFFFFF):
        raise ValueError("indices must be in 0 .. 2^32 - 1")
    return np.ascontiguousarray(a, dtype=np.uint32)


def _fp(a: np.ndarray):
    return a.ctypes.data_as(_F3)


def _dp(a: np.ndarray):
    return a.ctypes.data_as(_D3)


def _up(a: np.ndarray):
    return a.ctypes.data_as(_U32P)


def _vec3(v) -> np.ndarray:
    a = _floats(v)
    if a.size != 3:
        raise ValueError(f"expected 3 floats, got {a.size}")
    return a


def _vel(v):
    return None if v is None else _fp(_vec3(v))


def default_desc() -> FcClothDesc:
    """The library's default description: a 61 x 41 grid of 1 cm spacing (0.6 m x 0.4 m,
    0.24 kg), the paper's fractional forces, the accurate SOE history and explicit Euler.
    ``help(fraccloth.FcClothDesc)`` lists every field with its unit."""
    d = FcClothDesc()
    _check(library.fc_cloth_desc_init(ctypes.byref(d), ctypes.sizeof(d)))
    return d


def preset_desc(preset: int) -> FcClothDesc:
    """A preset's description on the default grid: PRESET_UNDERWATER (the underwater towel),
    PRESET_FRACTIONAL_PAPER (the paper exactly), PRESET_REGULAR_*."""
    d = FcClothDesc()
    _check(library.fc_cloth_desc_preset_sized(preset, ctypes.byref(d), ctypes.sizeof(d)))
    return d


Vec3 = Union[Sequence[float], np.ndarray]
"""Three numbers (x, y, z): a sequence or a numpy array."""


class StepStats(NamedTuple):
    """What the last ``step`` did: the ``substeps`` it took, the automatic step's ``retries``
    (attempts retried with twice the substeps) and its substep ``estimate`` in seconds (0 with a
    fixed step)."""

    substeps: int
    retries: int
    estimate: float


class CollisionStats(NamedTuple):
    """What the continuous collision check did since the cloth was made: ``zone_steps`` (steps
    in which a self-collision pair would have passed through another), ``passages`` found,
    ``zone_moved`` (free vertices moved with an impact zone, summed over steps), ``unresolved``
    (passages left: 0 means the cloth never went through itself where its pairs were listed) and
    ``mesh_carried`` (cloth vertices a mesh collider carried rather than let through)."""

    zone_steps: int
    passages: int
    zone_moved: int
    unresolved: int
    mesh_carried: int


class StepLimitStats(NamedTuple):
    """What self-collision's step limit (no free vertex moves more than half the thickness in a
    substep) did since the cloth was made: ``split_substeps`` (substeps taken in pieces instead),
    ``pieces`` (how many), ``slowed`` (free vertices slowed to the limit, summed over steps: the
    last resort, in a substep split as far as it goes; not 0 means some motion was held back)."""

    split_substeps: int
    pieces: int
    slowed: int


class SolverStats(NamedTuple):
    """What the last implicit solve did: CG ``iterations`` and the final relative ``residual``."""

    iterations: int
    residual: float


class Cloth:
    """One simulated cloth. Free it with ``close()`` or a ``with`` block (or let it be
    collected). Positions are in m, velocities in m/s, times in s. Every failing call raises
    :class:`Error` and leaves the cloth exactly as it was."""

    def __init__(self, handle: Optional[int]):
        self._h = ctypes.c_void_p(handle)

    @classmethod
    def grid(cls, desc: Optional[FcClothDesc] = None) -> "Cloth":
        """A grid cloth of ``desc.width`` x ``desc.height`` vertices ``desc.spacing`` m apart,
        in the plane z = 0, centred on x = 0, its top row on y = 0 (default: default_desc())."""
        desc = default_desc() if desc is None else desc
        h = ctypes.c_void_p()
        _check(library.fc_cloth_create_grid(ctypes.byref(desc), ctypes.byref(h)))
        return cls(h.value)

    @classmethod
    def mesh(cls, desc: Optional[FcClothDesc], positions, faces) -> "Cloth":
        """A cloth from a mesh: positions (N, 3) in m, faces (M, 3) triangles or (M, 4) quads
        (vertex indices). The grid fields of ``desc`` are not used."""
        desc = default_desc() if desc is None else desc
        x = _floats(positions)
        f = _u32(faces)
        if f.ndim != 2 or f.shape[1] not in (3, 4):
            raise ValueError("faces must have shape (M, 3) or (M, 4)")
        h = ctypes.c_void_p()
        _check(
            library.fc_cloth_create_mesh(
                ctypes.byref(desc), _fp(x), x.size // 3, _up(f), f.size, f.shape[1], ctypes.byref(h)
            )
        )
        return cls(h.value)

    def close(self) -> None:
        """Frees the cloth; further calls on it raise. Safe to call twice."""
        if self._h:
            library.fc_cloth_destroy(self._h)
            self._h = ctypes.c_void_p()

    def __enter__(self) -> "Cloth":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutdown
            pass

    @property
    def handle(self) -> ctypes.c_void_p:
        """The C handle (``FcCloth*``), for calls this package does not wrap."""
        return self._h

    @property
    def vertex_count(self) -> int:
        """Number of vertices (particles)."""
        return library.fc_cloth_vertex_count(self._h)

    @property
    def triangle_count(self) -> int:
        """Number of triangles of the index buffer (see :meth:`triangles`)."""
        return library.fc_cloth_triangle_count(self._h)

    @property
    def time(self) -> float:
        """Simulated time, s."""
        return library.fc_cloth_time(self._h)

    @property
    def history_mode_count(self) -> int:
        """Exponential modes of the SOE history per particle (0 for other schemes)."""
        return library.fc_cloth_history_mode_count(self._h)

    @property
    def history_bytes_per_particle(self) -> int:
        """Bytes of fractional history kept per particle now."""
        return library.fc_cloth_history_bytes_per_particle(self._h)

    @property
    def positions(self) -> np.ndarray:
        """Positions, m: float32, shape (n, 3). Assign an (n, 3) array to move every vertex
        (velocities and history are kept)."""
        out = np.empty((self.vertex_count, 3), dtype=np.float32)
        _check(library.fc_cloth_get_positions(self._h, _fp(out), out.size))
        return out

    @positions.setter
    def positions(self, xyz) -> None:
        a = _floats(xyz)
        _check(library.fc_cloth_set_positions(self._h, _fp(a), a.size))

    @property
    def velocities(self) -> np.ndarray:
        """Velocities, m/s: float32, shape (n, 3). Assigning sets them exactly (float64)."""
        out = np.empty((self.vertex_count, 3), dtype=np.float32)
        _check(library.fc_cloth_get_velocities(self._h, _fp(out), out.size))
        return out

    @velocities.setter
    def velocities(self, xyz) -> None:
        a = _doubles(xyz)
        _check(library.fc_cloth_set_velocities_f64(self._h, _dp(a), a.size))

    @property
    def desc(self) -> FcClothDesc:
        """The cloth's description now (coefficients, history, integrator, solver; the grid as
        built). Assign an edited one to change coefficients between steps (the history cannot
        change; the grid fields are not read)."""
        d = FcClothDesc()
        _check(library.fc_cloth_get_desc_sized(self._h, ctypes.byref(d), ctypes.sizeof(d)))
        return d

    @desc.setter
    def desc(self, d: FcClothDesc) -> None:
        _check(library.fc_cloth_set_desc(self._h, ctypes.byref(d)))

    def triangles(self) -> np.ndarray:
        """The index buffer: (t, 3) uint32 vertex indices, counter-clockwise seen from the side
        the normals point to. Fixed for the cloth's life."""
        out = np.empty((self.triangle_count, 3), dtype=np.uint32)
        _check(library.fc_cloth_get_triangles(self._h, _up(out), out.size))
        return out

    @property
    def normals(self) -> np.ndarray:
        """Unit vertex normals at the current positions, float32, shape (n, 3)."""
        out = np.empty((self.vertex_count, 3), dtype=np.float32)
        _check(library.fc_cloth_get_normals(self._h, _fp(out), out.size))
        return out

    def positions_f64(self) -> np.ndarray:
        """Positions (m), exactly: float64, shape (n, 3)."""
        out = np.empty((self.vertex_count, 3), dtype=np.float64)
        _check(library.fc_cloth_get_positions_f64(self._h, _dp(out), out.size))
        return out

    def set_positions_f64(self, xyz) -> None:
        """Sets every position (m) exactly; velocities and history are kept."""
        a = _doubles(xyz)
        _check(library.fc_cloth_set_positions_f64(self._h, _dp(a), a.size))

    def velocities_f64(self) -> np.ndarray:
        """Velocities (m/s), exactly: float64, shape (n, 3)."""
        out = np.empty((self.vertex_count, 3), dtype=np.float64)
        _check(library.fc_cloth_get_velocities_f64(self._h, _dp(out), out.size))
        return out

    def set_pinned(self, indices: Iterable[int]) -> None:
        """Pins exactly these vertices (weight 1) where they are now; an empty list unpins all."""
        a = _u32(list(indices) if not isinstance(indices, np.ndarray) else indices)
        _check(library.fc_cloth_set_pinned(self._h, _up(a), a.size))

    def set_pin_weights(self, weights) -> None:
        """One weight in [0, 1] per vertex: 0 free, 1 pinned, between: pulled to its target."""
        a = _floats(weights, None)
        _check(library.fc_cloth_set_pin_weights(self._h, _fp(a), a.size))

    def pin_group(self, indices, weight: float = 1.0) -> None:
        """Gives these vertices a pin weight in [0, 1] (others keep theirs)."""
        a = _u32(indices)
        _check(library.fc_cloth_pin_group(self._h, _up(a), a.size, weight))

    def set_pin_targets(self, indices, targets) -> None:
        """Moves pinned vertices to targets (m, one (x, y, z) per index) over the next step."""
        i = _u32(indices)
        t = _floats(targets)
        if t.size != 3 * i.size:
            raise ValueError("need one (x, y, z) target per index")
        _check(library.fc_cloth_set_pin_targets(self._h, _up(i), _fp(t), i.size))

    def set_current(self, current: Vec3) -> None:
        """The uniform water current, m/s, from the next step (exactly, in double precision)."""
        c = _doubles(current)
        if c.size != 3:
            raise ValueError(f"expected 3 values, got {c.size}")
        _check(library.fc_cloth_set_current_f64(self._h, _dp(c)))

    def step(self, dt: float) -> None:
        """Advances ``dt`` seconds (split into ``max_substep`` substeps if set). Atomic."""
        _check(library.fc_cloth_step(self._h, dt))

    def step_substeps(self, dt: float, substeps: int) -> None:
        """Advances ``dt`` seconds in ``substeps`` equal substeps. Atomic over the whole call."""
        _check(library.fc_cloth_step_substeps(self._h, dt, substeps))

    @property
    def threads(self) -> int:
        """Where steps run: 0 the shared pool (default), 1 the calling thread only, n >= 2 a
        pool of the cloth's own. The result is bit for bit the same for each."""
        return library.fc_cloth_get_threads(self._h)

    @threads.setter
    def threads(self, count: int) -> None:
        _check(library.fc_cloth_set_threads(self._h, count))

    def set_solver(self, tolerance: float, max_iterations: int) -> None:
        """The implicit solver's CG tolerance (relative residual, > 0) and iteration cap (>= 1)."""
        _check(library.fc_cloth_set_solver(self._h, tolerance, max_iterations))

    def solver_stats(self) -> SolverStats:
        """What the last implicit solve did (zeros before the first, and for explicit steps)."""
        it, res = ctypes.c_uint32(), ctypes.c_double()
        _check(library.fc_cloth_get_solver_stats(self._h, ctypes.byref(it), ctypes.byref(res)))
        return SolverStats(it.value, res.value)

    def step_stats(self) -> StepStats:
        """What the last ``step`` or ``step_substeps`` did (substeps, and the automatic step's
        retries and estimate)."""
        n, r, e = ctypes.c_uint32(), ctypes.c_uint32(), ctypes.c_double()
        _check(library.fc_cloth_get_step_stats(self._h, ctypes.byref(n), ctypes.byref(r), ctypes.byref(e)))
        return StepStats(n.value, r.value, e.value)

    def collision_stats(self) -> CollisionStats:
        """What the continuous collision check did since the cloth was made."""
        out = [ctypes.c_uint64() for _ in range(5)]
        _check(library.fc_cloth_get_collision_stats(self._h, *(ctypes.byref(o) for o in out)))
        return CollisionStats(*(o.value for o in out))

    def step_limit_stats(self) -> StepLimitStats:
        """What self-collision's step limit did since the cloth was made."""
        out = [ctypes.c_uint64() for _ in range(3)]
        _check(library.fc_cloth_get_step_limit_stats(self._h, *(ctypes.byref(o) for o in out)))
        return StepLimitStats(*(o.value for o in out))

    def set_solver_accept_unconverged(self, accept: bool) -> None:
        """Accept (True) or refuse (False, the default) implicit steps that stop at the
        iteration cap above the tolerance."""
        _check(library.fc_cloth_set_solver_accept_unconverged(self._h, 1 if accept else 0))

    def save_snapshot(self) -> bytes:
        """The cloth's whole state (positions, velocities, pins, colliders, history, time) as a
        checked binary snapshot."""
        buf = ctypes.create_string_buffer(library.fc_cloth_snapshot_size(self._h))
        written = ctypes.c_size_t()
        _check(library.fc_cloth_save_snapshot(self._h, buf, len(buf), ctypes.byref(written)))
        return buf.raw[: written.value]

    def load_snapshot(self, data: bytes) -> None:
        """Restores a snapshot saved from a cloth of the same mesh and history settings; stepping
        on gives the same bits as the saved cloth would have."""
        data = bytes(data)
        _check(library.fc_cloth_load_snapshot(self._h, data, len(data)))

    def _add(self, fn, *args) -> int:
        out = ctypes.c_uint32()
        _check(fn(self._h, *args, ctypes.byref(out)))
        return out.value

    def add_sphere(self, center: Vec3, radius: float, velocity: Optional[Vec3] = None) -> int:
        """Adds a sphere collider (centre m, radius m, velocity m/s); returns its id."""
        return self._add(library.fc_cloth_add_sphere, _fp(_vec3(center)), radius, _vel(velocity))

    def set_sphere(self, id: int, center: Vec3, radius: float, velocity: Optional[Vec3] = None) -> None:
        """Moves sphere ``id``."""
        _check(library.fc_cloth_set_sphere(self._h, id, _fp(_vec3(center)), radius, _vel(velocity)))

    def add_plane(self, point: Vec3, normal: Vec3, velocity: Optional[Vec3] = None) -> int:
        """Adds a plane collider (a point m, its normal, velocity m/s); returns its id."""
        return self._add(library.fc_cloth_add_plane, _fp(_vec3(point)), _fp(_vec3(normal)), _vel(velocity))

    def set_plane(self, id: int, point: Vec3, normal: Vec3, velocity: Optional[Vec3] = None) -> None:
        """Moves plane ``id``."""
        _check(library.fc_cloth_set_plane(self._h, id, _fp(_vec3(point)), _fp(_vec3(normal)), _vel(velocity)))

    def add_capsule(self, a: Vec3, b: Vec3, radius: float, velocity: Optional[Vec3] = None) -> int:
        """Adds a capsule collider (segment ends m, radius m, velocity m/s); returns its id."""
        return self._add(library.fc_cloth_add_capsule, _fp(_vec3(a)), _fp(_vec3(b)), radius, _vel(velocity))

    def set_capsule(self, id: int, a: Vec3, b: Vec3, radius: float, velocity: Optional[Vec3] = None) -> None:
        """Moves capsule ``id``."""
        _check(library.fc_cloth_set_capsule(self._h, id, _fp(_vec3(a)), _fp(_vec3(b)), radius, _vel(velocity)))

    def sphere(self, id: int) -> Tuple[np.ndarray, float]:
        """Sphere ``id`` as (centre (3,), radius), m."""
        c, r = np.empty(3, dtype=np.float32), ctypes.c_float()
        _check(library.fc_cloth_get_sphere(self._h, id, _fp(c), ctypes.byref(r)))
        return c, r.value

    def plane(self, id: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Plane ``id`` as (point, unit normal, velocity), each (3,): m, -, m/s."""
        p, n, v = (np.empty(3, dtype=np.float32) for _ in range(3))
        _check(library.fc_cloth_get_plane(self._h, id, _fp(p), _fp(n), _fp(v)))
        return p, n, v

    def capsule(self, id: int) -> Tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        """Capsule ``id`` as (a, b, radius, velocity): segment ends (3,) m, radius m, velocity m/s."""
        a, b, v = (np.empty(3, dtype=np.float32) for _ in range(3))
        r = ctypes.c_float()
        _check(library.fc_cloth_get_capsule(self._h, id, _fp(a), _fp(b), ctypes.byref(r), _fp(v)))
        return a, b, r.value, v

    def add_mesh_collider(self, positions, triangles, velocities=None) -> int:
        """Adds a triangle-mesh collider: ``positions`` (m) shape (n, 3), ``triangles`` vertex
        indices shape (m, 3) (counter-clockwise seen from outside on a closed mesh),
        ``velocities`` (m/s) shape (n, 3) or None (from its motion between steps). Returns its
        id (shared with the other colliders). A closed mesh pushes out a vertex that ends up
        inside it; an open one is a two-sided shell."""
        x = _floats(positions)
        t = _u32(triangles)
        v = None if velocities is None else _floats(velocities)
        if v is not None and v.size != x.size:
            raise ValueError(f"expected {x.size // 3} velocities, got {v.size // 3}")
        out = ctypes.c_uint32()
        _check(library.fc_cloth_add_mesh_collider(self._h, _fp(x), x.size // 3, t.ctypes.data_as(_U32P), t.size,
                                                  None if v is None else _fp(v), ctypes.byref(out)))
        return out.value

    def set_mesh_collider(self, id: int, positions, velocities=None) -> None:
        """Moves or deforms mesh collider ``id``: new positions (m) of the same vertices, where
        it is at the end of the next step (it travels there over the step)."""
        x = _floats(positions)
        v = None if velocities is None else _floats(velocities)
        if v is not None and v.size != x.size:
            raise ValueError(f"expected {x.size // 3} velocities, got {v.size // 3}")
        _check(library.fc_cloth_set_mesh_collider(self._h, id, _fp(x), x.size // 3, None if v is None else _fp(v)))

    def mesh_collider_size(self, id: int) -> Tuple[int, int]:
        """(vertex count, triangle count) of mesh collider ``id``."""
        nv, nt = ctypes.c_size_t(), ctypes.c_size_t()
        _check(library.fc_cloth_get_mesh_collider(self._h, id, ctypes.byref(nv), ctypes.byref(nt)))
        return nv.value, nt.value

    def set_collider_friction(self, id: int, friction: float) -> None:
        """Coulomb friction coefficient (>= 0) of collider ``id``."""
        _check(library.fc_cloth_set_collider_friction(self._h, id, friction))

    def set_collider_margin(self, id: int, margin: float) -> None:
        """Collider ``id``'s own margin, m (>= 0; any kind, meshes too): the distance from it at
        which the cloth is pushed away, instead of the description's ``collision_margin``."""
        _check(library.fc_cloth_set_collider_margin(self._h, id, margin))

    def collider_margin(self, id: int) -> float:
        """Collider ``id``'s margin, m: its own, or the description's ``collision_margin``."""
        m = ctypes.c_float()
        _check(library.fc_cloth_get_collider_margin(self._h, id, ctypes.byref(m)))
        return m.value

    def remove_collider(self, id: int) -> None:
        """Removes collider ``id`` (any kind, meshes too); its id may be reused by a later add."""
        _check(library.fc_cloth_remove_collider(self._h, id))

    def write_obj(self, path: Union[str, os.PathLike]) -> None:
        """Writes the cloth as it is now to a Wavefront OBJ file (positions m, normals, faces)."""
        _check(library.fc_cloth_write_obj(self._h, os.fsencode(str(path))))


class Cache:
    """A point cache written frame by frame (`CACHE_PC2`, `CACHE_MDD`, `CACHE_OBJ_SEQUENCE`)."""

    def __init__(self, path: Union[str, os.PathLike], format: int, cloth: Cloth, start_frame: float = 1.0,
                 frames_per_second: float = 24.0, expected_frames: int = 0):
        """Opens ``path`` for ``cloth``'s vertices: ``start_frame`` is the host frame of the
        first sample, ``frames_per_second`` the rate, ``expected_frames`` the count (MDD)."""
        self._h = ctypes.c_void_p()
        _check(
            library.fc_cache_open(
                os.fsencode(str(path)), format, cloth.handle, start_frame, frames_per_second,
                expected_frames, ctypes.byref(self._h),
            )
        )

    def write_frame(self, cloth: Cloth) -> None:
        """Appends the cloth's current positions as the next frame."""
        _check(library.fc_cache_write_frame(self._h, cloth.handle))

    def write_positions(self, xyz) -> None:
        """Appends a frame of positions given by the caller (m; shape (n, 3)), e.g. the cloth
        in another frame of reference than the one it was simulated in."""
        a = _floats(xyz)
        _check(library.fc_cache_write_positions(self._h, _fp(a), a.size))

    def close(self) -> None:
        """Completes the file (headers count the frames written); raises if that fails."""
        h, self._h = self._h, ctypes.c_void_p()
        if h:
            _check(library.fc_cache_close(h))

    def __enter__(self) -> "Cache":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass


def version() -> str:
    """The library's version, "major.minor.patch"."""
    v = library.fc_version()
    return f"{v // 1000000}.{v // 1000 % 1000}.{v % 1000}"
