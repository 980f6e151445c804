"""Type stubs of the Rust core (the ``specvar`` package wraps these in dataclasses)."""

from typing import Any, Callable, Optional, Union

import numpy as np

__version__: str

def set_budget(memory_gib: Optional[float] = None, seconds: Optional[float] = None) -> tuple[float, float]: ...
def samplers() -> list[dict[str, Any]]: ...
def sample(
    sampler: str,
    n: int,
    realizations: int = 1,
    dimension: int = 2,
    seed: int = 0,
    start: int = 0,
    homogenized: bool = False,
    cache: bool = True,
) -> np.ndarray: ...
def periodogram(
    points: np.ndarray, kmax: int, engine: str = "auto", tolerance: Optional[float] = None
) -> np.ndarray: ...
def spectrum(
    sampler: Optional[str] = None,
    points: Optional[np.ndarray] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    realizations: int = 16,
    kmax: int = 64,
    seed: int = 0,
    engine: str = "auto",
    tolerance: Optional[float] = None,
    bin_width: float = 1.0,
    cache: bool = True,
) -> dict[str, Any]: ...
def predict(
    integrand: Union[str, np.ndarray],
    sampler: Optional[str] = None,
    points: Optional[np.ndarray] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    spectrum: str = "auto",
    form: str = "auto",
    realizations: Optional[int] = None,
    reference_n: Optional[int] = None,
    kmax: Optional[int] = None,
    seed: int = 0,
    randomization: str = "native",
    cells: Optional[str] = None,
    cache: bool = True,
) -> dict[str, Any]: ...
def predict_image(
    pixels: np.ndarray,
    sampler: str,
    n: int,
    randomization: str = "native",
    seed: int = 0,
    cache: bool = True,
) -> dict[str, Any]: ...
def plan(
    integrand: Optional[Union[str, np.ndarray]],
    rmse: float,
    relative: bool = False,
    samplers: Optional[list[str]] = None,
    dimension: int = 2,
    randomization: str = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
    pixels: Optional[np.ndarray] = None,
) -> list[dict[str, Any]]: ...
def plan_pilot(
    renders: np.ndarray,
    n: int,
    sampler: str,
    rmse: float,
    relative: bool = False,
    model: str = "padded",
    randomization: str = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
) -> dict[str, Any]: ...
def predict_padded(
    values: np.ndarray,
    sampler: str,
    n: int,
    second: Optional[str] = None,
    randomization: str = "native",
    mc: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
) -> dict[str, Any]: ...
def plan_padded(
    values: np.ndarray,
    sampler: str,
    rmse: float,
    relative: bool = False,
    second: Optional[str] = None,
    randomization: str = "native",
    max_n: Optional[int] = None,
    seed: int = 0,
    cache: bool = True,
) -> dict[str, Any]: ...
def monte_carlo(
    integrand: Union[str, np.ndarray, Callable[[np.ndarray], np.ndarray]],
    sampler: Optional[str] = None,
    points: Optional[np.ndarray] = None,
    n: Optional[int] = None,
    dimension: int = 2,
    trials: int = 10000,
    shifts: Optional[int] = None,
    seed: int = 0,
    randomization: str = "native",
    integral: Optional[float] = None,
    cache: bool = True,
) -> dict[str, Any]: ...
def integrand_facts(integrand: Union[str, np.ndarray], dimension: int = 2) -> dict[str, Any]: ...
def evaluate(integrand: Union[str, np.ndarray], points: np.ndarray) -> np.ndarray: ...
def read_points(path: str) -> Union[np.ndarray, list[np.ndarray]]: ...
def write_points(path: str, points: np.ndarray, format: str = "text") -> None: ...
def run_study(described: str) -> dict[str, Any]: ...
def study_blocks(described: str, patterns_per_block: int) -> list[tuple[str, int, int, int]]: ...
def study_block(described: str, block: tuple[str, int, int, int]) -> np.ndarray: ...
def finish_study(
    described: str, blocks: list[tuple[str, int, int, int]], errors: list[np.ndarray]
) -> dict[str, Any]: ...
