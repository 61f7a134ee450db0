"""Type stub of grasp_sim._native, the compiled module (python/src/lib.rs).

The public API is grasp_sim's (``grasp_sim/__init__.py``); these are the calls it makes. Every
call releases the GIL while Rust works and turns a panic into :class:`GraspSimError`.
"""

from typing import Iterator, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

VERSION: str
DEBUG_BUILD: bool

class GraspSimError(Exception):
    """Any error of grasp-sim: its message is the one line the command line prints."""

class BadInputError(GraspSimError):
    """A bad object (mesh file or arrays) or a bad argument."""

class BadScenarioError(GraspSimError):
    """A bad scenario: unknown key, wrong type or value out of range."""

class BadHandError(GraspSimError):
    """A bad hand file, or an override out of range."""

def load_hand(spec: str, overrides: List[Tuple[str, float]] = ...) -> Tuple[str, str, str]:
    """``(name, file, params_json)`` of a bundled hand or a hand file."""

def load_mesh_file(
    path: str, units: str
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], str]:
    """``(vertices [mm], faces, info_json)`` of a mesh file, validated as the CLI does."""

def mesh_from_arrays(
    vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64], units: str, label: str
) -> Tuple[bytes, Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], str]]:
    """``(binary STL, (vertices [mm], faces, info_json))`` of arrays, validated by the loader."""

def run_table(
    scenario_json: str,
    label: str,
    no_sim: bool = False,
    payload: bool = False,
    quality: bool = False,
    candidates: int = 1,
    max_checked: Optional[int] = None,
    given: Optional[Tuple[List[float], List[float], List[List[float]], Optional[str]]] = None,
) -> str:
    """Runs a scenario given as JSON tables (parsed as its TOML); returns the ``--json`` line.
    ``given`` (position, quaternion wxyz, angles per finger, axis name): check that grasp."""

def run_file(
    path: str,
    units: str = "mm",
    gravity: Optional[str] = None,
    no_sim: bool = False,
    payload: bool = False,
    quality: bool = False,
    candidates: int = 1,
) -> str:
    """Runs a scenario file or a bare mesh as ``grasp-sim --json PATH``; returns its line."""

class Batch:
    """A batch running on a Rust thread; yields ``(done, total, message, line)``."""

    def __init__(
        self,
        inputs: List[str],
        jobs: Optional[int] = None,
        out: Optional[str] = None,
        resume: bool = False,
        no_sim: bool = False,
        payload: bool = False,
        quality: bool = False,
        units: Optional[str] = None,
        template: Optional[str] = None,
    ) -> None: ...
    @property
    def total(self) -> int: ...
    def __iter__(self) -> Iterator[Tuple[int, int, str, str]]: ...
    def __next__(self) -> Tuple[int, int, str, str]: ...
