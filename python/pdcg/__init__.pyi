# Type stub of the pdcg Python module (docs/python.md). Arrays are numpy.ndarray; those a
# Body or Atoms hands out are read-only views of pdcg's memory unless stated otherwise.
from dataclasses import dataclass
from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

class Error(RuntimeError): ...
class InputError(Error, ValueError): ...
class NumericalError(Error): ...

def version() -> str: ...
def set_log_level(level: str) -> None: ...

class Atoms:
    def __init__(self, ids: Any, types: Any, positions: Any, lo: Sequence[float],
                 hi: Sequence[float], tilt: Sequence[float] = ..., periodic: Sequence[bool] = ...,
                 type_mass: Optional[Sequence[float]] = ..., masses: Optional[Sequence[float]] = ...,
                 source: str = ...) -> None: ...
    @property
    def ids(self) -> np.ndarray: ...            # (N,) int64, sorted
    @property
    def types(self) -> Optional[np.ndarray]: ...  # (N,) int32, 1-based
    @property
    def positions(self) -> np.ndarray: ...      # (N, 3), unwrapped when image flags were given
    @property
    def velocities(self) -> Optional[np.ndarray]: ...
    @property
    def forces(self) -> Optional[np.ndarray]: ...
    @property
    def type_mass(self) -> Optional[np.ndarray]: ...
    @property
    def box(self) -> Dict[str, Any]: ...        # lo, hi, tilt, periodic, h
    @property
    def timestep(self) -> int: ...
    @property
    def ntypes(self) -> int: ...
    @property
    def source(self) -> str: ...
    @property
    def units(self) -> str: ...
    @property
    def columns(self) -> List[str]: ...
    def column(self, name: str) -> np.ndarray: ...
    def __len__(self) -> int: ...

class Body:
    kind: str
    units: str
    dimension: int
    ids: np.ndarray
    types: np.ndarray
    positions: np.ndarray
    masses: np.ndarray
    box: Dict[str, Any]
    horizon: float
    epsilon: float
    reference_volume: float
    bonds: int
    family_offsets: np.ndarray
    family_neighbors: np.ndarray
    potential_style: str
    potential_commands: List[str]
    provenance: List[str]
    points: Optional[np.ndarray]
    point_volumes: Optional[np.ndarray]
    point_masses: Optional[np.ndarray]
    def forces(self, positions: Any = ..., h: Any = ...) -> np.ndarray: ...  # (N, 3), a copy
    def energy(self, positions: Any = ..., h: Any = ...) -> float: ...
    def per_atom_energy(self, positions: Any = ..., h: Any = ...) -> np.ndarray: ...
    def point_energies(self, positions: Any = ..., h: Any = ...) -> np.ndarray: ...
    def to_ase(self) -> Any: ...
    def write(self, path: str) -> None: ...
    def stress(self, F: Optional[Sequence[float]] = ...) -> np.ndarray: ...
    def __len__(self) -> int: ...

def read_atoms(path: str, frame: int = ...) -> Atoms: ...
def read_frames(path: str, frames: str) -> List[Atoms]: ...
def read_body(path: str) -> Body: ...

Commands = Union[None, str, Sequence[str]]

def delta_body(atoms: Atoms, potential: Optional[str] = ..., *, commands: Commands = ...,
               dimension: int = ..., family_cutoff: Optional[float] = ...,
               boundary: Optional[str] = ...) -> Body: ...
def statistical_body(frames: Union[Atoms, Sequence[Atoms]], potential: Optional[str] = ..., *,
                     commands: Commands = ..., statistics: str = ...,
                     width: Optional[float] = ..., order: Optional[int] = ...,
                     samples: Optional[int] = ..., dimension: int = ...,
                     family_cutoff: Optional[float] = ..., boundary: Optional[str] = ...,
                     temperature: Optional[float] = ...) -> Body: ...
def from_lammps(lmp: Any, potential: Optional[str] = ..., *, commands: Commands = ...,
                dimension: Optional[int] = ..., family_cutoff: Optional[float] = ...,
                check_forces: bool = ..., tolerance: float = ...) -> Body: ...
def from_ase(atoms: Any, potential: Optional[str] = ..., *, commands: Commands = ...,
             species: Optional[Sequence[str]] = ..., types: Any = ..., dimension: int = ...,
             family_cutoff: Optional[float] = ...) -> Body: ...

def homogenize(body: Body, kernel: str, width: float, spacing: Optional[float] = ...,
               points: Any = ..., axes: Any = ..., shift: Optional[Sequence[float]] = ...) -> Body: ...
homogenise = homogenize
def rescale(body: Body, factor: Optional[float] = ..., horizon: Optional[float] = ...) -> Body: ...

@dataclass
class Elastic:
    F: np.ndarray
    W: float
    P: np.ndarray
    S: np.ndarray
    A: np.ndarray
    C_voigt: np.ndarray  # (6, 6) in `unit`
    units: str
    unit: str
    to_GPa: float
    bulk_voigt: float
    shear_voigt: float
    bulk_reuss: float
    shear_reuss: float
    lattice: str
    note: str
    @property
    def C_GPa(self) -> np.ndarray: ...

def elastic(body: Body, F: Any = ...) -> Elastic: ...

@dataclass
class Dispersion:
    kappa: np.ndarray
    kvec: np.ndarray
    omega: np.ndarray
    labels: List[Tuple[float, str]]
    lattice: str
    a: float
    description: str
    units: str
    kappa_unit: str
    omega_unit: str
    def plot(self, filename: Optional[str] = ..., ax: Any = ..., title: Optional[str] = ...) -> Any: ...

def dispersion(body: Body, path: Optional[str] = ..., *, direction: Optional[Sequence[float]] = ...,
               nk: int = ..., kmax: Optional[float] = ..., lattice: Optional[str] = ...,
               a: Optional[float] = ..., point: Optional[int] = ..., cell: bool = ...) -> Dispersion: ...

@dataclass
class RunResult:
    directory: str
    resolved_yaml: str
    reactions: Dict[str, np.ndarray]
    units_line: str
    def steps(self) -> List[str]: ...
    def fields(self, step: int = ...) -> Dict[str, np.ndarray]: ...

def run(scene: Union[str, PathLike, Dict[str, Any]], *, output: Optional[str] = ...,
        restart: Optional[str] = ..., base_dir: Optional[str] = ...,
        progress: Optional[Callable[[str, int, int], None]] = ...) -> RunResult: ...
