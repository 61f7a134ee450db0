"""grasp-sim from Python: plan enveloping grasps for a three-fingered hand and check them in a
rapier3d physics scene (docs/PYTHON.md).

The Rust library is the one implementation: this package converts arguments into the scenario
the command line would read, runs it in Rust (the GIL released) and turns the JSON report into
objects with numpy arrays. Units are the library's: millimetres and degrees for geometry and
joint angles, SI for the physics check's figures.

    import grasp_sim as gs
    cup = gs.Object.from_file("assets/objects/cup.stl", frame="file")
    plan = gs.plan(cup)                       # thesis hand, thesis planner defaults
    print(plan.status, plan.grasp.joint_angles_deg)
    print(gs.check(cup, plan).verdict)        # hold / slip / drop

Errors are exceptions under :class:`GraspSimError` carrying the command line's one-line message.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from typing import Any, Callable, Dict, Iterable, Iterator, List, Mapping, Optional, Tuple, Union

import numpy as np

from . import _native
from ._native import BadHandError, BadInputError, BadScenarioError, GraspSimError

__all__ = [
    "GraspSimError",
    "BadInputError",
    "BadScenarioError",
    "BadHandError",
    "Hand",
    "Object",
    "Grasp",
    "Plan",
    "Check",
    "plan",
    "check",
    "check_many",
    "run_scenario",
    "batch",
    "__version__",
]

__version__: str = _native.VERSION

PathLike = Union[str, "os.PathLike[str]"]
"""A file path, as a string or a path object."""

Progress = Callable[[int, int, str], Any]
"""A progress callback: ``(done, total, message)``, the message as the CLI's batch shows it."""


class Hand:
    """A hand model: a bundled one (``"thesis"``, ``"bh8"``) or a hand TOML file.

    ``params`` holds its parameters as the hand file has them, overrides applied and validated
    (millimetres and degrees): ``hand.params["phalanx_1"]["length_mm"]``.
    """

    name: str
    """The hand's ``name``."""
    file: str
    """What a scenario's ``[hand] file`` names it by: the bundled name, or the absolute path."""
    overrides: Dict[str, float]
    """The overrides applied (dotted keys of the hand file, as ``[hand] overrides``)."""
    params: Dict[str, Any]
    """Every parameter, as the hand file's tables: ``palm``, ``joints``, ``fingers``,
    ``phalanx_1``, ``phalanx_2`` and the ``finger`` list."""

    def __init__(self, name: str, file: str, overrides: Dict[str, float], params: Dict[str, Any]):
        self.name, self.file, self.overrides, self.params = name, file, overrides, params

    @classmethod
    def load(cls, spec: PathLike = "thesis", overrides: Optional[Mapping[str, float]] = None) -> "Hand":
        """Loads a bundled hand by name, or a hand TOML file, applying ``overrides``
        (``{"phalanx_2.length_mm": 18.0}``) as a scenario's ``[hand] overrides`` would.

        A name is a bundled hand unless a file of that name exists, as in ``[hand] file``.

        Raises:
            BadHandError: unreadable file, bad TOML, unknown key, a value out of range.
        """
        ov = {str(k): float(v) for k, v in (overrides or {}).items()}
        name, file, params = _native.load_hand(os.fspath(spec), list(ov.items()))
        return cls(name, file, ov, json.loads(params))

    @property
    def finger_names(self) -> List[str]:
        """The fingers, in the thesis's order (finger_1, the thumb finger_2, finger_3)."""
        return [f["name"] for f in self.params["finger"]]

    def _table(self) -> Dict[str, Any]:
        t: Dict[str, Any] = {"file": self.file}
        if self.overrides:
            t["overrides"] = dict(self.overrides)
        return t

    def __repr__(self) -> str:
        return f"Hand({self.name!r}, file={self.file!r}, overrides={self.overrides!r})"


def _to_hand(hand: Union[None, str, "os.PathLike[str]", Hand]) -> Hand:
    if hand is None:
        return Hand.load("thesis")
    if isinstance(hand, Hand):
        return hand
    return Hand.load(hand)


class Object:
    """An object to grasp: a validated triangle mesh, read as the command line reads it.

    ``vertices`` (N × 3, millimetres) and ``faces`` (M × 3, zero-based) are the mesh as the
    planner sees it: welded, degenerate triangles dropped, small holes closed, wound outwards,
    in the file's own frame (the frame every pose is given in).
    """

    name: str
    """The scenario name the runs get (the file's stem, or ``"object"`` for arrays)."""
    path: str
    """The mesh file the runs read (for arrays: a binary STL of them in a temporary folder)."""
    units: str
    """The unit of the file's or the arrays' coordinates."""
    vertices: np.ndarray
    """Vertex positions ``[mm]``, N × 3 float64."""
    faces: np.ndarray
    """Triangles as vertex indices, M × 3 int64."""
    info: Dict[str, Any]
    """What loading found: ``triangles_read``, ``degenerate_dropped``, ``holes_filled``,
    ``was_inverted``, ``volume_mm3``, edge counts and ``warnings``."""
    object_params: Dict[str, Any]
    """Further ``[object]`` keys the runs get (``frame``, ``friction``, ``density_kg_m3``,
    ``mass_kg``)."""

    def __init__(self) -> None:  # use from_file, from_arrays or from_trimesh
        self._tmp: Optional[tempfile.TemporaryDirectory[str]] = None

    @classmethod
    def from_file(
        cls,
        path: PathLike,
        units: str = "mm",
        *,
        name: Optional[str] = None,
        **object_params: Any,
    ) -> "Object":
        """Reads and validates a mesh file (STL, OBJ, PLY, or the object a URDF describes).

        Args:
            path: the file.
            units: ``"mm"``, ``"cm"``, ``"inch"`` or ``"m"``.
            name: the runs' scenario name (default: the file's stem).
            **object_params: further ``[object]`` keys: ``frame`` (``"file"`` keeps the file's
                frame as the object's, docs/FRAMES.md), ``friction``, ``density_kg_m3``,
                ``mass_kg``.

        Raises:
            BadInputError: the file cannot be read or fails validation (the CLI's message).
        """
        o = cls()
        o.path = os.path.abspath(os.fspath(path))
        o.units = units
        o.name = name if name is not None else os.path.splitext(os.path.basename(o.path))[0]
        v, f, info = _native.load_mesh_file(o.path, units)
        o.vertices, o.faces, o.info = v, f, json.loads(info)
        o.object_params = dict(object_params)
        return o

    @classmethod
    def from_arrays(
        cls,
        vertices: Any,
        faces: Any = None,
        units: str = "mm",
        *,
        name: str = "object",
        **object_params: Any,
    ) -> "Object":
        """A mesh from arrays: ``vertices`` (N × 3, in ``units``) and ``faces`` (M × 3,
        zero-based indices), validated as a mesh file is; a ``trimesh.Trimesh`` may stand for
        both.

        The arrays give exactly the plan a file holding them gives: like every format they are
        read as float32 triangles, then welded and repaired by the same loader.

        Raises:
            BadInputError: wrong shapes, NaN or infinite coordinates, a face index out of range
                (faces are numbered from 1 in the message, as in files), no triangles.
        """
        if faces is None and hasattr(vertices, "vertices") and hasattr(vertices, "faces"):
            vertices, faces = vertices.vertices, vertices.faces
        if faces is None:
            raise BadInputError("Object.from_arrays: faces missing (or give a trimesh.Trimesh)")
        # Bounded before anything is copied: 10^8 vertices took the interpreter down.
        for what, arr, most in (("vertices", vertices, MAX_ARRAY_VERTICES), ("faces", faces, MAX_ARRAY_FACES)):
            n = int(np.shape(arr)[0]) if np.ndim(arr) >= 1 else 0
            if n > most:
                raise BadInputError(
                    f"<arrays>: {n} {what}, more than the {most} a mesh may have "
                    "(the faces of a 256 MiB binary STL)"
                )
        v = np.ascontiguousarray(np.asarray(vertices, dtype=np.float64))
        f = np.asarray(faces)
        if f.size and not np.issubdtype(f.dtype, np.integer):
            raise BadInputError(f"<arrays>: faces must be integer indices, got dtype {f.dtype}")
        f = np.ascontiguousarray(f.astype(np.int64, copy=False))
        if v.ndim != 2 or f.ndim != 2:
            raise BadInputError(
                f"<arrays>: vertices must be (N, 3) and faces (M, 3), got {v.shape} and {f.shape}"
            )
        stl, (mv, mf, info) = _native.mesh_from_arrays(v, f, units, "<arrays>")
        o = cls()
        o._tmp = tempfile.TemporaryDirectory(prefix="grasp_sim_")
        o.path = os.path.join(o._tmp.name, f"{name}.stl")
        with open(o.path, "wb") as fh:
            fh.write(stl)
        o.units, o.name = units, name
        o.vertices, o.faces, o.info = mv, mf, json.loads(info)
        o.object_params = dict(object_params)
        return o

    @classmethod
    def from_trimesh(cls, mesh: Any, units: str = "mm", **kwargs: Any) -> "Object":
        """A ``trimesh.Trimesh`` (trimesh is optional: only its ``vertices`` and ``faces`` are
        read)."""
        return cls.from_arrays(mesh.vertices, mesh.faces, units, **kwargs)

    def _table(self) -> Dict[str, Any]:
        t: Dict[str, Any] = {"mesh": self.path, "units": self.units}
        t.update({k: v for k, v in self.object_params.items() if v is not None})
        return t

    def __repr__(self) -> str:
        return f"Object({self.name!r}, {len(self.vertices)} vertices, {len(self.faces)} faces)"


def _to_object(obj: Any) -> Object:
    if isinstance(obj, Object):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        return Object.from_file(obj)
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        return Object.from_arrays(obj.vertices, obj.faces)
    raise BadInputError(f"not an object: {type(obj).__name__} (give an Object, a path or a trimesh.Trimesh)")


def _pose_matrix(pose: Mapping[str, Any]) -> np.ndarray:
    """The 4 × 4 homogeneous matrix of a report's ``{position_mm, quaternion_wxyz}``."""
    w, x, y, z = pose["quaternion_wxyz"]
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = pose["position_mm"]
    return m


def _pose_of_matrix(m: Any) -> Dict[str, Any]:
    """``{position_mm, quaternion_wxyz}`` of a 4 × 4 rigid transform (refused otherwise)."""
    try:
        a = np.asarray(m, dtype=float)
    except (TypeError, ValueError):
        raise BadInputError("palm_pose: not a 4 × 4 array of numbers") from None
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise BadInputError(f"palm_pose: a 4 × 4 array of finite numbers is needed, not shape {a.shape}")
    r = a[:3, :3]
    if np.abs(r.T @ r - np.eye(3)).max() > 1e-6 or np.linalg.det(r) < 0:
        raise BadInputError("palm_pose: its 3 × 3 block is not a rotation (orthonormal, determinant +1)")
    # Shepperd's method: divide by the largest of the four squared components.
    t = np.trace(r)
    k = int(np.argmax([t, r[0, 0], r[1, 1], r[2, 2]]))
    if k == 0:
        s = 2 * np.sqrt(1 + t)
        q = [s / 4, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    else:
        i, j, l = [(0, 1, 2), (1, 2, 0), (2, 0, 1)][k - 1]
        s = 2 * np.sqrt(1 + r[i, i] - r[j, j] - r[l, l])
        q = [0.0] * 4
        q[0] = (r[l, j] - r[j, l]) / s
        q[1 + i] = s / 4
        q[1 + j] = (r[j, i] + r[i, j]) / s
        q[1 + l] = (r[l, i] + r[i, l]) / s
    return {"position_mm": a[:3, 3].tolist(), "quaternion_wxyz": [float(v) for v in q]}


class Grasp:
    """One planned grasp (the report's ``plan.grasp`` or an entry of ``plan.grasps``)."""

    palm_pose: np.ndarray
    """The palm frame in the object's (the mesh file's) frame, 4 × 4, millimetres: the palm
    centre on its contact surface; x away from the object, y towards finger_1 and finger_3, z up
    along the finger joint axes."""
    palm_pose_aligned: np.ndarray
    """The same in the planner's aligned frame."""
    joint_angles_deg: np.ndarray
    """``[θ1, θ2]`` per finger (3 × 2), interior angles: 180° straight, smaller more closed."""
    axis: np.ndarray
    """The principal axis the grasp wraps, in the object's frame."""
    axis_name: str
    rules: str
    """The rule set that found it (``thesis``, ``extended``, ``pinch``)."""
    relaxations: List[Any]
    approach_angle_deg: float
    palm_pitch_deg: float
    elevation_index: int
    elevation_mm: float
    index: int
    """Its place in the plan's ``candidates`` (0: the grasp reported)."""
    raw: Dict[str, Any]
    """The report's JSON object for this grasp."""

    def __init__(self, raw: Dict[str, Any], index: int = 0, plan: Optional["Plan"] = None):
        self.raw, self.index, self._plan = raw, index, plan
        self.palm_pose = _pose_matrix(raw["palm_pose"])
        self.palm_pose_aligned = _pose_matrix(raw["palm_pose_aligned"])
        self.joint_angles_deg = np.array([[f["theta1_deg"], f["theta2_deg"]] for f in raw["fingers"]])
        self.axis = np.array(raw.get("axis", [0.0, 0.0, 1.0]), dtype=float)
        self.axis_name = raw.get("axis_name", "")
        self.rules = raw.get("rules", "")
        self.relaxations = list(raw.get("relaxations", []))
        self.approach_angle_deg = raw["approach_angle_deg"]
        self.palm_pitch_deg = raw["palm_pitch_deg"]
        self.elevation_index = raw["elevation_index"]
        self.elevation_mm = raw["elevation_mm"]

    @classmethod
    def from_pose(cls, palm_pose: Any, joint_angles_deg: Any, axis_name: Optional[str] = None) -> "Grasp":
        """A grasp from outside the planner (a learned model's, a hand-made one), to give to
        :func:`check`: the palm frame in the object's file frame (4 × 4, millimetres, as
        :attr:`palm_pose`) and ``[θ1, θ2]`` per finger (interior angles, degrees).

        Args:
            axis_name: the principal axis whose aligned frame ``gravity="down"`` and the six
                directions refer to (a plan's :attr:`axis_name`); default: the thesis axis.

        Raises:
            BadInputError: a palm pose that is not a rigid transform, or angles not of shape
                (fingers, 2).
        """
        pose = _pose_of_matrix(palm_pose)
        try:
            angles = np.asarray(joint_angles_deg, dtype=float)
        except (TypeError, ValueError):
            raise BadInputError("joint_angles_deg: not an array of numbers") from None
        if angles.ndim != 2 or angles.shape[1] != 2:
            raise BadInputError(f"joint_angles_deg: shape (fingers, 2) is needed, not {angles.shape}")
        raw: Dict[str, Any] = {
            "palm_pose": pose,
            "palm_pose_aligned": pose,
            "fingers": [{"name": f"finger_{i + 1}", "theta1_deg": float(t1), "theta2_deg": float(t2)}
                        for i, (t1, t2) in enumerate(angles)],
            "axis_name": axis_name or "",
            "approach_angle_deg": float("nan"),
            "palm_pitch_deg": float("nan"),
            "elevation_index": -1,
            "elevation_mm": float("nan"),
        }
        g = cls(raw, index=-1)
        g.palm_pose = np.asarray(palm_pose, dtype=float).copy()
        g.palm_pose_aligned = np.full((4, 4), np.nan)
        return g

    def _given(self) -> Tuple[List[float], List[float], List[List[float]], Optional[str]]:
        """The native check's ``given``: position, quaternion, angles, axis name."""
        p = self.raw["palm_pose"]
        return (list(p["position_mm"]), list(p["quaternion_wxyz"]),
                self.joint_angles_deg.tolist(), self.axis_name or None)

    @property
    def finger_names(self) -> List[str]:
        return [f["name"] for f in self.raw["fingers"]]

    def __repr__(self) -> str:
        a = np.round(self.joint_angles_deg, 1).tolist()
        return (f"Grasp(index {self.elevation_index}, approach {self.approach_angle_deg:g}°, "
                f"pitch {self.palm_pitch_deg:.1f}°, angles {a}, rules {self.rules!r})")


class Plan:
    """What the planner found (``plan(...)``): the report's ``plan`` section, typed."""

    status: str
    """``"feasible"`` or ``"ungraspable"``."""
    reason: Optional[str]
    """Why ungraspable (``None`` when feasible)."""
    grasp: Optional[Grasp]
    """The grasp reported (``None`` when ungraspable)."""
    candidates: List[Grasp]
    """Every grasp collected, in search order (``candidates=N`` collects up to N); the first
    is ``grasp``."""
    candidates_tried: int
    """Candidates the search tried."""
    warnings: List[str]
    report: Dict[str, Any]
    """The whole run report, as the CLI's ``--json`` prints it."""

    def __init__(self, report: Dict[str, Any], obj: Object, hand: Hand, planner_params: Dict[str, Any]):
        self.report, self.object, self.hand, self.planner_params = report, obj, hand, planner_params
        p = report["plan"]
        self.status = p["status"]
        self.reason = p.get("reason")
        self.candidates_tried = p.get("candidates_tried", 0)
        self.warnings = list(report.get("warnings", []))
        self.grasp = Grasp(p["grasp"], 0, self) if p.get("grasp") else None
        grasps = p.get("grasps") or ([p["grasp"]] if p.get("grasp") else [])
        self.candidates = [Grasp(g, i, self) for i, g in enumerate(grasps)]
        if self.grasp is not None and self.candidates:
            self.candidates[0] = self.grasp

    @property
    def is_feasible(self) -> bool:
        """True if and only if the planner found a grasp."""
        return self.status == "feasible"

    def __repr__(self) -> str:
        return f"Plan({self.status!r}, {self.grasp if self.grasp else self.reason})"


class Check:
    """The physics check's result (``check(...)``): the report's ``sim`` section, typed."""

    verdict: str
    """``"hold"``, ``"slip"``, ``"drop"`` or ``"not_run"``: what gravity did."""
    fidelity: Optional[Dict[str, Any]]
    """Whether the grasp the closing made is the one planned: ``as_planned``, ``shift_mm``,
    ``turn_deg``, ``phalanges_on_plan``, ``phalanges``, ``worst_joint_error_deg``,
    ``penetration_mm``, ``reasons`` (the report's ``sim.fidelity``; ``None`` when not run)."""
    reason: Optional[str]
    translation_mm: Optional[float]
    """The object's largest translation relative to the palm during the hold."""
    rotation_deg: Optional[float]
    directions: List[Dict[str, Any]]
    """Per gravity direction: its verdict, translation and rotation (``gravity="six"`` gives
    six)."""
    payload_margin: Optional[float]
    """With ``payload=True``: the largest payload multiplier that still holds."""
    closing: Optional[Dict[str, Any]]
    """What the closing did to the planned grasp (docs/SIM.md)."""
    robust: Optional[Dict[str, Any]]
    """With ``samples`` above 1: the report's ``sim.robust`` (``hold_probability``, ``interval``
    [lo, hi], ``counts``, per direction, the first failing sample's perturbation)."""
    hold_probability: Optional[float]
    """``robust["hold_probability"]`` (``None`` with one sample)."""
    as_planned_probability: Optional[float]
    """``robust["as_planned_probability"]``: the samples that held as planned (``None`` with
    one sample)."""
    grasp: Optional[Grasp]
    """The grasp checked."""
    sim: Dict[str, Any]
    """The report's ``sim`` object."""
    report: Dict[str, Any]
    """The whole run report, as the CLI's ``--json`` prints it."""

    def __init__(self, report: Dict[str, Any]):
        self.report = report
        s = self.sim = report["sim"]
        self.verdict = s["verdict"]
        self.fidelity = s.get("fidelity")
        self.reason = s.get("reason")
        self.translation_mm = s.get("translation_mm")
        self.rotation_deg = s.get("rotation_deg")
        self.directions = list(s.get("directions", []))
        self.payload_margin = s.get("payload_margin")
        self.closing = s.get("closing")
        self.robust = s.get("robust")
        self.hold_probability = self.robust["hold_probability"] if self.robust else None
        self.as_planned_probability = (self.robust.get("as_planned_probability")
                                       if self.robust else None)
        g = report["plan"].get("grasp")
        self.grasp = Grasp(g) if g else None

    @property
    def is_hold(self) -> bool:
        """True if and only if the verdict is ``hold``."""
        return self.verdict == "hold"

    @property
    def as_planned(self) -> Optional[bool]:
        """True if and only if the closing kept the planned grasp (``None`` when not run)."""
        return self.fidelity["as_planned"] if self.fidelity else None

    def __repr__(self) -> str:
        planned = "" if self.as_planned in (None, True) else ", not as planned"
        return (f"Check({self.verdict!r}{planned}, translation {self.translation_mm} mm, "
                f"rotation {self.rotation_deg}°)")


def _scenario(obj: Object, hand: Hand, planner: Mapping[str, Any], sim: Mapping[str, Any]) -> Dict[str, Any]:
    s: Dict[str, Any] = {"name": obj.name, "object": obj._table(), "hand": hand._table()}
    if planner:
        s["planner"] = dict(planner)
    if sim:
        s["sim"] = dict(sim)
    return s


def _plain(value: Any) -> Any:
    """numpy scalars and arrays as the Python numbers and lists a scenario table holds."""
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not a scenario value (a number, string, bool or list)")


#: The most grasps ``candidates=`` may collect, and the most ``samples=`` (the CLI's caps).
MAX_CANDIDATES = 1000
MAX_SAMPLES = 1000
#: The most vertices and faces :meth:`Object.from_arrays` takes: the faces of the largest mesh
#: file read (a binary STL of 256 MiB), and three vertices each.
MAX_ARRAY_FACES = ((256 << 20) - 84) // 50
MAX_ARRAY_VERTICES = 3 * MAX_ARRAY_FACES


def _count(label: str, key: str, value: Any, high: int) -> int:
    """``value`` as a whole number in 1..=``high``, else a BadScenarioError naming ``key``
    (``candidates=-1`` raised a bare OverflowError from the native call)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise BadScenarioError(f"{label}: `{key}` must be a whole number in 1..={high}, got {value!r}")
    if not 1 <= int(value) <= high:
        raise BadScenarioError(f"{label}: `{key}` must be in 1..={high}, got {int(value)}")
    return int(value)


def _finite(label: str, table: Mapping[str, Any], section: str) -> None:
    """Every number of ``table`` (a ``[planner]``, ``[sim]`` or ``[object]`` table, lists
    included) finite, else a BadScenarioError naming the key (json.dumps said only "Out of
    range float values are not JSON compliant")."""

    def bad(v: Any) -> bool:
        if isinstance(v, (list, tuple)):
            return any(bad(x) for x in v)
        if isinstance(v, np.ndarray):
            return v.dtype.kind in "fc" and not bool(np.all(np.isfinite(v)))
        if isinstance(v, (float, np.floating)):
            return not np.isfinite(v)
        return False

    for key, v in table.items():
        if bad(v):
            raise BadScenarioError(f"{label}: `{section}.{key}` must be a finite number, got {v!r}")


def _run(label: str, scenario: Dict[str, Any], **flags: Any) -> Dict[str, Any]:
    for section in ("object", "planner", "sim"):
        _finite(label, scenario.get(section, {}), section)
    if "candidates" in flags:
        flags["candidates"] = _count(label, "candidates", flags["candidates"], MAX_CANDIDATES)
    if flags.get("max_checked") is not None:
        flags["max_checked"] = _count(label, "max_checked", flags["max_checked"], 100)
    try:
        text = json.dumps(scenario, allow_nan=False, default=_plain)
    except (TypeError, ValueError) as e:
        raise BadScenarioError(f"{label}: {e}") from None
    report: Dict[str, Any] = json.loads(_native.run_table(text, label, **flags))
    return report


def plan(obj: Any, hand: Union[None, str, "os.PathLike[str]", Hand] = None, *, candidates: int = 1,
         **planner_params: Any) -> Plan:
    """Plans a grasp with the thesis method (kinematic only: no physics check).

    Args:
        obj: an :class:`Object` (or a mesh path, or a ``trimesh.Trimesh``).
        hand: a :class:`Hand`, a bundled hand's name or a hand file (default: the thesis hand).
        candidates: collect up to this many feasible grasps in search order (``--candidates``).
        **planner_params: ``[planner]`` keys of a scenario (docs/SCENARIO.md), e.g.
            ``height_step_mm=2.5``, ``sf_c=0.6``, ``angular_step_deg=10.0``.

    Raises:
        BadScenarioError: an unknown key or a value out of range (the CLI's message).
        BadHandError, BadInputError: a bad hand or mesh.
    """
    o, h = _to_object(obj), _to_hand(hand)
    report = _run("grasp_sim.plan", _scenario(o, h, planner_params, {}), no_sim=True, candidates=candidates)
    return Plan(report, o, h, dict(planner_params))


def check(obj: Any, plan_or_grasp: Union[None, Plan, Grasp] = None,
          hand: Union[None, str, "os.PathLike[str]", Hand] = None, gravity: str = "down",
          samples: int = 1, *, payload: bool = False, quality: bool = False,
          planner_params: Optional[Mapping[str, Any]] = None, **sim_params: Any) -> Check:
    """Checks a grasp in the rapier3d physics scene (docs/SIM.md).

    Args:
        obj: the object the grasp is on.
        plan_or_grasp: a :class:`Plan` (its grasp is checked), any of its grasps
            (``plan.candidates[k]``), or a :meth:`Grasp.from_pose` grasp from elsewhere;
            ``None`` plans and checks as the CLI does (candidates in search order until one
            holds), or checks ``override_angles=[[θ1, θ2], ...]`` given in ``sim_params``.
        hand: default: the plan's hand (else the thesis hand).
        gravity: ``"down"`` (−Z of the aligned frame) or ``"six"`` (±X, ±Y, ±Z in turn).
        samples: perturbed checks of the grasp (``[sim] samples``, docs/SIM.md "Hold
            probability"): above 1, :attr:`Check.robust` gives the hold probability and its
            95 % interval; the ranges and ``seed`` are ``sim_params``.
        payload: also find the payload margin (several more physics runs).
        quality: also compute the grasp's Ferrari–Canny quality (``report["quality"]``).
        planner_params: default: the plan's.
        **sim_params: ``[sim]`` keys of a scenario, e.g. ``torque_limit_nm=0.5``,
            ``duration_s=2.0``, ``protocol="full"``.

    A plan's first grasp is checked exactly as the CLI checks it. Any other grasp is checked
    as given (``report["sim"]["grasp_source"] == "given"``): its palm pose in the object's
    frame and its joint angles, with the planner's report beside it unchanged.

    Raises:
        BadInputError: a given grasp that cannot be posed (wrong
            finger count, a non-finite number, an axis the planner did not search).
        BadScenarioError, BadHandError: as :func:`plan`.
    """
    o = _to_object(obj)
    source: Optional[Plan] = None
    given: Optional[Grasp] = None
    if isinstance(plan_or_grasp, Grasp):
        if plan_or_grasp._plan is not None and plan_or_grasp.index == 0:
            source = plan_or_grasp._plan
        else:
            given = plan_or_grasp
            source = plan_or_grasp._plan
    elif isinstance(plan_or_grasp, Plan):
        source = plan_or_grasp
    elif plan_or_grasp is not None:
        raise BadInputError(f"check: not a Plan or Grasp: {type(plan_or_grasp).__name__}")
    if given is None and source is not None and source.grasp is None:
        raise BadInputError(f"check: the plan has no grasp ({source.reason})")
    h = _to_hand(hand if hand is not None else (source.hand if source else None))
    pp = dict(planner_params if planner_params is not None else (source.planner_params if source else {}))
    sim = dict(sim_params)
    sim["gravity"] = gravity
    if samples != 1:
        sim["samples"] = _count("grasp_sim.check", "samples", samples, MAX_SAMPLES)
    flags: Dict[str, Any] = {"payload": payload, "quality": quality}
    if given is not None:
        flags["given"] = given._given()
        report = _run("grasp_sim.check", _scenario(o, h, pp, sim), **flags)
        result = Check(report)
        result.grasp = given
        return result
    if source is not None:
        # The planner is deterministic: the same object, hand and parameters give the same
        # first grasp, and checking only it (max_checked 1, and no closings' order, which would
        # check another candidate where its closing leaves the plan) checks the plan's grasp.
        flags["max_checked"] = 1
        sim["order_by_closing"] = 0
    report = _run("grasp_sim.check", _scenario(o, h, pp, sim), **flags)
    result = Check(report)
    if source is not None and source.grasp is not None:
        got, want = report["plan"].get("grasp") or {}, source.grasp.raw
        same = all(got.get(k) == want.get(k) for k in ("palm_pose", "fingers", "elevation_index"))
        if not same:
            raise GraspSimError("check: the grasp checked is not the plan's (the object, hand or planner parameters differ)")
    return result


def _grasp_line(g: Any, k: int) -> str:
    """A grasp as a line of ``grasp-sim check --grasps``: a :class:`Grasp`, or a mapping with
    ``palm_pose`` (4 × 4) and ``joint_angles_deg`` (a label line is one)."""
    if isinstance(g, Grasp):
        # The report's pose (position and quaternion) as written, not the matrix made of it.
        line: Dict[str, Any] = {"palm_pose": g.raw["palm_pose"],
                                "joint_angles_deg": np.asarray(g.joint_angles_deg, dtype=float).tolist()}
        if g.axis_name:
            line["axis_name"] = g.axis_name
    elif isinstance(g, Mapping):
        line = dict(g)
    else:
        raise BadInputError(f"check_many: grasp {k}: not a Grasp or a mapping: {type(g).__name__}")
    try:
        return json.dumps(line, allow_nan=True, default=_plain)
    except (TypeError, ValueError) as e:
        raise BadInputError(f"check_many: grasp {k}: {e}") from None


def check_many(obj: Any, grasps: Iterable[Any], samples: int = 8,
               hand: Union[None, str, "os.PathLike[str]", Hand] = None, gravity: str = "down",
               **sim_params: Any) -> List[Dict[str, Any]]:
    """Checks many grasps of one object in-process, as ``grasp-sim check --grasps`` does:
    the object loaded, aligned and its collider made once, every check spread over the cores.

    Args:
        obj: the object the grasps are on.
        grasps: :class:`Grasp` objects (``plan.candidates``, :meth:`Grasp.from_pose`) or
            mappings with ``palm_pose`` (4 × 4, mm, the object file's frame),
            ``joint_angles_deg`` (``[θ1, θ2]`` per finger) and optionally ``axis_name`` (a
            ``grasp-sim label`` line is one).
        samples: perturbed checks per grasp.
        hand: default: the thesis hand.
        gravity: ``"down"`` or ``"six"``.
        **sim_params: ``[sim]`` keys of a scenario.

    Returns:
        One record per grasp, in order (docs/OUTPUT.md "Label lines"): ``verdict``,
        ``fidelity``, ``hold_probability``, ``interval``, ``as_planned_probability``, ...; a
        grasp that cannot be checked (a pose that is not rigid, a NaN, the wrong shape) gets a
        record with ``error`` and the others are still checked.

    Raises:
        BadScenarioError, BadHandError, BadInputError: as :func:`check`.
    """
    if isinstance(samples, bool) or not isinstance(samples, int) or not 1 <= samples <= 1000:
        raise BadInputError(f"check_many: samples = {samples!r} is not a whole number from 1 to 1000")
    o, h = _to_object(obj), _to_hand(hand)
    lines = [_grasp_line(g, k) for k, g in enumerate(grasps)]
    sim = dict(sim_params)
    sim["gravity"] = gravity
    scenario = _scenario(o, h, {}, sim)
    try:
        text = json.dumps(scenario, allow_nan=False, default=_plain)
    except (TypeError, ValueError) as e:
        raise BadScenarioError(f"grasp_sim.check_many: {e}") from None
    out = _native.check_lines_table(text, "grasp_sim.check_many", lines, samples)
    return [json.loads(line) for line in out]


def run_scenario(path: PathLike, *, units: str = "mm", gravity: Optional[str] = None,
                 no_sim: bool = False, payload: bool = False, quality: bool = False,
                 candidates: int = 1) -> Dict[str, Any]:
    """Runs a scenario file (or a bare mesh with the built-in template) and returns exactly the
    JSON object ``grasp-sim --json PATH`` prints (docs/OUTPUT.md).

    The keyword arguments are the CLI's flags: ``--units`` (bare meshes), ``--gravity``,
    ``--no-sim``, ``--payload``, ``--quality``, ``--candidates``.

    Raises:
        GraspSimError (a subclass): the line the CLI prints after ``grasp-sim: error:``.
    """
    candidates = _count("grasp_sim.run_scenario", "candidates", candidates, MAX_CANDIDATES)
    line = _native.run_file(os.fspath(path), units, gravity, no_sim, payload, quality, candidates)
    report: Dict[str, Any] = json.loads(line)
    return report


def _stderr_bar(done: int, total: int, message: str) -> None:
    width = 30
    filled = width * done // max(total, 1)
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} {message[-60:]:<60}")
    if done == total:
        sys.stderr.write("\n")
    sys.stderr.flush()


def batch(inputs: Union[PathLike, Iterable[PathLike]], jobs: Optional[int] = None,
          out: Optional[PathLike] = None, resume: bool = False,
          progress: Union[None, bool, Progress] = None, *, no_sim: bool = False,
          payload: bool = False, quality: bool = False, units: Optional[str] = None,
          template: Optional[PathLike] = None) -> Iterator[Dict[str, Any]]:
    """Runs many objects (``grasp-sim batch --in-process``) and yields each one's JSON line, as
    a dict, as it finishes (completion order; ``line["batch"]["input"]`` says which).

    Args:
        inputs: scenario files, meshes or folders (as ``grasp-sim batch``).
        jobs: objects run at once (default: every core).
        out: also write the results file (JSON Lines, input order) when the batch ends.
        resume: continue the run in ``out``: its lines for current inputs are yielded first and
            not run again.
        progress: ``progress(done, total, message)`` after each object, or ``True`` for a bar
            on stderr.
        no_sim, payload, quality, units, template: the batch's flags.

    The objects run on Rust threads with the GIL released; a bad input is a line with an
    ``error`` (as in the CLI), not an exception. An object that cannot start (no such input,
    a bad template or results file) raises at the call.
    """
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    paths = [os.fspath(p) for p in inputs]
    native = _native.Batch(
        paths, jobs, None if out is None else os.fspath(out), resume, no_sim, payload, quality,
        units, None if template is None else os.fspath(template),
    )
    callback: Optional[Progress] = _stderr_bar if progress is True else (progress or None)

    def results() -> Iterator[Dict[str, Any]]:
        for done, total, message, line in native:
            if callback is not None:
                callback(done, total, message)
            yield json.loads(line)

    return results()
