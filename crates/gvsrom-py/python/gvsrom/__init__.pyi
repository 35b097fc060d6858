"""Type stubs of gvsrom (kept by hand; checked by `python -m mypy.stubtest gvsrom`)."""

import os
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence, Union, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

__all__ = [
    "ConvergenceError",
    "Dataset",
    "GvsromError",
    "IntegrationError",
    "Model",
    "Reconstruction",
    "Robot",
    "Scenario",
    "Statics",
    "StaticsBatch",
    "Stepper",
    "__version__",
    "compare",
    "dataset",
    "load_dataset",
    "load_model",
    "plot",
    "pod",
    "presets",
    "reproduce",
    "train",
]

_F = NDArray[np.float64]
_Path = Union[str, os.PathLike[str]]
_Specs = Union[str, Sequence[str], Mapping[str, tuple[float, float]]]

class GvsromError(ValueError):
    """Bad input to gvsrom: the message names the field and what is accepted, as the command line prints it."""

class ConvergenceError(GvsromError):
    """A statics solve that did not converge; `iterations`, `residual_norm` and `load_factor` say how far it got."""

    iterations: int
    residual_norm: float
    load_factor: float

class IntegrationError(GvsromError):
    """A simulation that stopped early: its integrator failed, or a callable `input` or `controller` returned a value refused after the start; `trajectory` holds the samples computed before, as `simulate` returns them. When the run itself failed, `trajectory["reason"]` says why, as the `reason` of a written run's `meta.json`: "the integration failed", "the reduced model left its training region" or "the run left the rod's elastic range"."""

    trajectory: dict[str, Any]

def presets() -> dict[str, str]:
    """The built-in presets: `{name: summary}` (`gvsrom presets`)."""

@final
class Scenario:
    """A scenario: a rod, its discretization and strain basis, tendons, loads, solver and output
    options (the TOML format of `docs/scenario-format.md`).

    Create one with :meth:`Scenario.preset` or :meth:`Scenario.from_toml`, change values with
    :meth:`set` (the paths of ``gvsrom --set``) and build the model with :meth:`build`.
    """

    @staticmethod
    def preset(name: str) -> Scenario:
        """A built-in preset (see :func:`gvsrom.presets`).

        Parameters
        ----------
        name : str
            Preset name, e.g. ``"single-tendon"``.

        Raises
        ------
        GvsromError
            For an unknown name, listing the presets.
        """
    @staticmethod
    def from_toml(text_or_path: Union[str, os.PathLike[str]]) -> Scenario:
        """A scenario from TOML text, or from a file given as a path.

        Parameters
        ----------
        text_or_path : str or os.PathLike
            A ``pathlib.Path`` (or other path-like) is read as a file; so is a ``str`` of one line
            that names an existing file or ends in ``.toml``. Any other ``str`` is TOML text.

        Raises
        ------
        GvsromError
            For a syntax error (with line and column), an unknown key or a value of the wrong type
            (naming its path), or a missing file.
        """
    def set(self, path: str, value: Union[float, int, bool, str, Sequence[Any], ArrayLike]) -> Scenario:
        """Sets one value by its TOML path, as ``gvsrom … --set PATH=VALUE`` does.

        Parameters
        ----------
        path : str
            Dotted key path with 0-based list indices, e.g. ``"tendons.0.tension"``,
            ``"divisions.0.basis.order"``, ``"loads.gravity"``.
        value : float, int, bool, str or sequence
            Numbers, booleans and lists are written as TOML; a ``str`` is read as TOML text like a
            ``--set`` value (a bare word is a string).

        Returns
        -------
        Scenario
            ``self``, changed (for chaining).

        Raises
        ------
        GvsromError
            If the path is unknown or the value of the wrong type; the scenario is then left
            unchanged. Ranges and the agreement between fields (a basis order and its quadrature,
            a division's length and its tendons) are checked by :meth:`build`, as the command line
            checks all its ``--set`` values together: a change that takes several values can be
            made one ``set`` at a time.
        """
    def to_toml(self) -> str:
        """The resolved scenario as TOML: every field, defaults filled in, overrides applied
        (``gvsrom show`` prints a preset's source instead). Parsing it back gives the same scenario.
        """
    @property
    def name(self) -> str:
        """The scenario's name (the preset name or file stem unless it sets one)."""
    @property
    def overrides(self) -> list[str]:
        """The overrides applied so far, as ``path=value`` strings."""
    @property
    def tensions(self) -> list[float]:
        """The tendon tensions [N], in tendon order."""
    def build(self) -> Robot:
        """Validates the scenario and builds the engine's model: a :class:`Robot`.

        Raises
        ------
        GvsromError
            Naming the field, its value and the accepted range.
        """
    def copy(self) -> Scenario:
        """A copy that later changes do not affect."""
    def __copy__(self) -> Scenario: ...
    def __deepcopy__(self, memo: Any) -> Scenario:
        """A copy (a `Scenario` holds no shared state; `memo` is not needed)."""
    def __reduce__(self) -> tuple[Any, tuple[str, str, str, bool, list[str]]]:
        """Pickling: the source text (a file's as it was read, not the file again), its origin and
        the overrides, loaded again as `set` loads them.
        """
    @staticmethod
    def _restore(origin: str, default_name: str, text: str, preset: bool, overrides: list[str]) -> Scenario:
        """The scenario `__reduce__` describes (for `pickle`; not part of the API)."""

@final
class Statics:
    """A static equilibrium (the fields of ``gvsrom statics --json``).

    Attributes
    ----------
    scenario : str
        The scenario's name.
    u : numpy.ndarray, shape (n_actuators,)
        Tendon tensions [N]: those given, and those found for tendons driven by displacement.
    slack : numpy.ndarray of bool, shape (n_actuators,)
        Which tendons driven by displacement are slack (``u = 0``, their path shorter than the
        tendon paid out); all ``False`` when every tendon is driven by tension.
    drive_iterations : int
        Tension updates of a displacement-driven solve (0 without displacement drives).
    q : numpy.ndarray, shape (n_dof,)
        Generalized coordinates at equilibrium.
    tip_position : numpy.ndarray, shape (3,)
        Tip position in the world frame [m].
    tip_rotation : numpy.ndarray, shape (3, 3)
        Tip rotation matrix, section frame → world.
    centerline_x : numpy.ndarray, shape (c,)
        Abscissae of the centreline samples [m].
    centerline : numpy.ndarray, shape (c, 3)
        Centreline positions [m].
    strain_x : numpy.ndarray, shape (p,)
        Abscissae of the computational points [m].
    strain : numpy.ndarray, shape (p, 6)
        ξ at the points, ``[torsion, bend-y, bend-z, elongation, shear-y, shear-z]``.
    strain_reference : numpy.ndarray, shape (p, 6)
        The reference strain ξ* at the points (the unloaded rod's; ``[0, 0, 0, 1, 0, 0]`` straight).
    tendon_paths : tuple of numpy.ndarray, each shape (m_k, 3)
        Each tendon's thread ``r + R d(X)`` in the world frame [m], from its start to its end (at
        its ends and at the ``centerline_x`` between them): tendons of different spans have
        different ``m_k``. A trajectory's ``tendon_paths`` (:meth:`Robot.simulate`) is one array
        (k, n_actuators, c, 3) at every ``centerline_x`` instead, clamped to each span (a short
        tendon's last point repeated).
    tendon_lengths : numpy.ndarray, shape (n_actuators,)
        Each tendon's length [m] along its thread, ``∫ ‖t_u‖ dX`` over its span: what an encoder on
        its actuator reads, up to a constant.
    tendon_rest_lengths : numpy.ndarray, shape (n_actuators,)
        The same at rest: ``tendon_rest_lengths - tendon_lengths`` is how far each is pulled in.
    body_positions : numpy.ndarray, shape (n_bodies, 2, 3)
        Each rigid body's section (``[:, 0]``) and centre of mass (``[:, 1]``) in the world frame
        [m] (``[[bodies]]``; empty without).
    iterations, load_stages, residual_evaluations, jacobian_evaluations : int
        Solver statistics.
    residual_norm : float
        ``‖R(q)‖∞`` at the solution.
    divergence : float or None
        ``ω²`` [1/s²], the real eigenvalue ``< 0`` of ``M⁻¹ K_T``, if the equilibrium is unstable
        (no stable one connected to the straight rod was found; a ``UserWarning`` says so too);
        ``None`` for a stable one.
    buckled : float or None
        ``ω²`` [1/s²] of the equilibrium on the path from the straight rod, if that one diverged
        (a bifurcation: a column compressed past buckling) and the rod, released along its
        divergent mode, settled on this stable one instead; ``None`` otherwise.
    continued : bool
        Whether the equilibrium was reached by arc-length continuation from the straight rod (the
        load ramp stalled, or its equilibrium diverged).
    solve_time_s : float
        Wall-clock time of the solve [s].
    model_extrapolated : list of str
        How the reduced model was used outside what it was trained on (``extrapolate=True``; the
        ``--json``'s ``model_extrapolated``); empty inside, and without a model.
    """

    @property
    def scenario(self) -> str:
        """The scenario's name."""
    @property
    def n_dof(self) -> int:
        """Generalized coordinates n."""
    @property
    def n_points(self) -> int:
        """Computational points p."""
    @property
    def u(self) -> _F:
        """Tendon tensions u [N]."""
    @property
    def slack(self) -> NDArray[np.bool_]:
        """Which displacement-driven tendons are slack, `(n_actuators,)` bool."""
    @property
    def drive_iterations(self) -> int:
        """Tension updates of a displacement-driven solve."""
    @property
    def q(self) -> _F:
        """Generalized coordinates at equilibrium."""
    @property
    def tip_position(self) -> _F:
        """Tip position in the world frame [m]."""
    @property
    def tip_rotation(self) -> _F:
        """Tip rotation matrix, section frame → world."""
    @property
    def centerline_x(self) -> _F:
        """Abscissae of the centreline samples [m]."""
    @property
    def centerline(self) -> _F:
        """Centreline positions [m] at `centerline_x`."""
    @property
    def strain_x(self) -> _F:
        """Abscissae of the computational points [m]."""
    @property
    def strain(self) -> _F:
        """ξ at the points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`."""
    @property
    def strain_reference(self) -> _F:
        """The reference strain ξ* at the points."""
    @property
    def tendon_paths(self) -> tuple[_F, ...]:
        """Each tendon's thread in the world frame [m], a `(m_k, 3)` array per tendon."""
    @property
    def tendon_lengths(self) -> _F:
        """Each tendon's length [m] along its thread."""
    @property
    def tendon_rest_lengths(self) -> _F:
        """Each tendon's length [m] at rest."""
    @property
    def body_positions(self) -> _F:
        """Each rigid body's section and centre of mass [m], `(n_bodies, 2, 3)`."""
    @property
    def iterations(self) -> int:
        """Dogleg iterations over all load stages."""
    @property
    def load_stages(self) -> int:
        """Load stages of the ramp."""
    @property
    def residual_evaluations(self) -> int:
        """Residual evaluations."""
    @property
    def jacobian_evaluations(self) -> int:
        """Jacobian evaluations."""
    @property
    def residual_norm(self) -> float:
        """`‖R(q)‖∞` at the solution."""
    @property
    def divergence(self) -> float | None:
        """`ω² < 0` [1/s²] if the equilibrium diverges, else `None`."""
    @property
    def buckled(self) -> float | None:
        """`ω² < 0` [1/s²] of the diverging equilibrium the rod was released from, if it buckled."""
    @property
    def continued(self) -> bool:
        """Reached by arc-length continuation from the straight rod."""
    @property
    def solve_time_s(self) -> float:
        """Wall-clock time of the solve [s]."""
    @property
    def model_extrapolated(self) -> list[str]:
        """How the reduced model was used outside what it was trained on (`--extrapolate`)."""
    def to_dict(self) -> dict[str, Any]:
        """The fields as a ``dict`` (the same read-only arrays, not copies)."""
    def __reduce__(self) -> tuple[Any, tuple[dict[str, Any]]]:
        """Pickling: every field (`to_dict`), as they are."""
    @staticmethod
    def _restore(state: dict[str, Any]) -> Statics:
        """The equilibrium `__reduce__` describes (for `pickle`; not part of the API)."""

@final
class StaticsBatch:
    """Many static equilibria (:meth:`Robot.statics_batch`): the arrays below, those of
    :class:`Statics` stacked along a first axis of length m. Of :class:`Statics`'s other fields it
    has none (the tendon paths, body positions, drives, load stages, ``to_dict``): solve the rows
    of interest with :meth:`Robot.statics` for those. A missing value is NaN here, where
    :class:`Statics` gives None.

    Attributes
    ----------
    u : numpy.ndarray, shape (m, n_actuators)
    q : numpy.ndarray, shape (m, n_dof)
    tip_position : numpy.ndarray, shape (m, 3)
    tip_rotation : numpy.ndarray, shape (m, 3, 3)
    centerline_x : numpy.ndarray, shape (c,)
    centerline : numpy.ndarray, shape (m, c, 3)
    strain_x : numpy.ndarray, shape (p,)
    strain : numpy.ndarray, shape (m, p, 6)
    tendon_lengths : numpy.ndarray, shape (m, n_actuators)
        Each tendon's length [m] along its thread (at rest: :attr:`Robot.tendon_rest_lengths`).
    iterations : numpy.ndarray of int64, shape (m,)
    residual_norm : numpy.ndarray, shape (m,)
    divergence : numpy.ndarray, shape (m,)
        ``ω² < 0`` [1/s²] of a row whose equilibrium is unstable (no stable one connected to the
        straight rod was found; a ``UserWarning`` names the rows), NaN for a stable one.
    buckled : numpy.ndarray, shape (m,)
        ``ω² < 0`` [1/s²] of the diverging equilibrium a row's rod was released from onto its
        stable one (:attr:`Statics.buckled`), NaN for a row that did not buckle. A row
        warm-started from a buckled neighbour starts on the buckled branch and is NaN too (its
        equilibrium is the same; ``warm_start=False`` releases every row from straight).
    solve_time_s : numpy.ndarray, shape (m,)
        Each solve's own wall-clock time [s] (the solves run in parallel).
    """

    @property
    def u(self) -> _F:
        """Tendon tensions u [N]."""
    @property
    def q(self) -> _F:
        """Generalized coordinates at equilibrium."""
    @property
    def tip_position(self) -> _F:
        """Tip position in the world frame [m]."""
    @property
    def tip_rotation(self) -> _F:
        """Tip rotation matrix, section frame → world."""
    @property
    def centerline_x(self) -> _F:
        """Abscissae of the centreline samples [m]."""
    @property
    def centerline(self) -> _F:
        """Centreline positions [m] at `centerline_x`."""
    @property
    def strain_x(self) -> _F:
        """Abscissae of the computational points [m]."""
    @property
    def strain(self) -> _F:
        """ξ at the points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`."""
    @property
    def tendon_lengths(self) -> _F:
        """Each tendon's length [m] along its thread."""
    @property
    def iterations(self) -> NDArray[np.int64]:
        """Dogleg iterations over all load stages."""
    @property
    def residual_norm(self) -> _F:
        """`‖R(q)‖∞` at the solution."""
    @property
    def divergence(self) -> _F:
        """`ω² < 0` [1/s²] of an unstable equilibrium, NaN for a stable one."""
    @property
    def buckled(self) -> _F:
        """`ω² < 0` [1/s²] of the equilibrium a buckled row left, NaN otherwise."""
    @property
    def solve_time_s(self) -> _F:
        """Wall-clock time of the solve [s]."""
    def __len__(self) -> int:
        """Return len(self)."""
    def __reduce__(self) -> tuple[Any, tuple[dict[str, Any]]]:
        """Pickling: every field (its arrays by name), as they are."""
    @staticmethod
    def _restore(state: dict[str, Any]) -> StaticsBatch:
        """The equilibria `__reduce__` describes (for `pickle`; not part of the API)."""

@final
class Model:
    """A reduced model directory (from ``gvsrom pod``, ``gvsrom train`` or :func:`pod`), checked
    against its recorded hashes when loaded. Pass it as ``model=`` to :meth:`Robot.statics` or to
    :meth:`Robot.with_model`.

    Attributes
    ----------
    path : pathlib.Path
        The model directory.
    kind : str
        ``"pod"`` or ``"autoencoder"``.
    latent : int
        Number of reduced coordinates r.
    extrapolate : bool
        Whether it may be used outside its training inputs (``--extrapolate``).
    arrays : dict of str to numpy.ndarray
        Its numbers as ``weights.safetensors`` stores them: POD ``modes`` (L × r) and
        ``singular_values``; an autoencoder's ``encoder.{k}.weight``/``.bias``,
        ``decoder.{k}.weight``/``.bias``, ``scaling.mean``, ``scaling.scale``; and
        ``anchors.inputs``, ``anchors.latent`` if it has anchors.
    latent_range : numpy.ndarray, shape (r, 2)
        Per reduced coordinate, the ``[min, max]`` of the training encodings.
    rest : numpy.ndarray, shape (r,)
        The reduced coordinates a run starts from at rest.
    meta : dict
        ``meta.json`` (layout, dataset, training, input ranges, …).
    """

    @property
    def path(self) -> Path:
        """The model directory."""
    @property
    def kind(self) -> str:
        """`"pod"` or `"autoencoder"`."""
    @property
    def latent(self) -> int:
        """Number of reduced coordinates r."""
    @property
    def extrapolate(self) -> bool:
        """Whether it may be used outside its training inputs (`--extrapolate`)."""
    @property
    def arrays(self) -> dict[str, _F]:
        """The numbers of ``weights.safetensors`` by name, as read-only arrays (a new dict at each
        access: editing it changes nothing).
        """
    @property
    def latent_range(self) -> _F:
        """`[min, max]` of the training encodings per reduced coordinate, shape (r, 2)."""
    @property
    def rest(self) -> _F:
        """Reduced coordinates of the rest state, shape (r,)."""
    @property
    def meta(self) -> dict[str, Any]:
        """``meta.json`` as a dict (a new one at each access: editing it changes nothing)."""
    @property
    def features(self) -> int:
        """Number of values of one snapshot: computational points × active strain components."""
    def encode(self, strain: ArrayLike, extrapolate: bool | None = None) -> _F:
        """Reduced coordinates of strain snapshots, ``q = E(x)``: POD ``Vᵀ x``, an autoencoder's
        encoder.

        Parameters
        ----------
        strain : array_like, shape (features,) or (rows, features)
            Snapshots as a dataset stores them (:attr:`Dataset.strain`): ``ξ − ξ*`` of the active
            components at the model's points, point-major.
        extrapolate : bool, optional
            Encode a snapshot whose code lies far outside the training encodings, or whose norm
            is over twice the largest training snapshot's (default: the model's own
            ``extrapolate``).

        Returns
        -------
        numpy.ndarray, shape (latent,) or (rows, latent)

        Raises
        ------
        GvsromError
            On a wrong shape or a non-finite value, or a code far outside the training encodings
            or a norm over twice the largest training snapshot's (the snapshot is unlike the
            training data) unless ``extrapolate``.
        """
    def decode(self, q: ArrayLike, extrapolate: bool | None = None) -> _F:
        """Strain snapshots of reduced coordinates, ``x̂ = D(q)``: POD ``V q``, an autoencoder's
        decoder.

        Parameters
        ----------
        q : array_like, shape (latent,) or (rows, latent)
        extrapolate : bool, optional
            Decode a code far outside the training encodings, where a decoder has no data (default:
            the model's own ``extrapolate``).

        Returns
        -------
        numpy.ndarray, shape (features,) or (rows, features)
            In the layout of :attr:`Dataset.strain`.
        """
    def reconstruct(self, strain: ArrayLike, extrapolate: bool | None = None) -> _F:
        """The model's reconstruction of strain snapshots, ``D(E(x))`` (Table I's ``x̂``).

        Parameters
        ----------
        strain : array_like, shape (features,) or (rows, features)
        extrapolate : bool, optional

        Returns
        -------
        numpy.ndarray, the shape of ``strain``
        """
    def reconstruction(self, dataset: Dataset | _Path) -> Reconstruction:
        """How closely the model reconstructs the solved snapshots of a dataset of its layout,
        ``x̂ = D(E(x))`` (``gvsrom reconstruct MODEL DATASET``): Table I's RMSE on any data, e.g. data
        the model was not trained on.

        Parameters
        ----------
        dataset : Dataset or str or os.PathLike
            A dataset (``load_dataset``) or its directory, of the model's points and components.

        Returns
        -------
        Reconstruction

        Raises
        ------
        ValueError
            If the dataset has another layout (naming both) or no solved snapshot.
        """
    def __copy__(self) -> Model:
        """The model itself (it holds nothing that changes)."""
    def __deepcopy__(self, memo: Any) -> Model:
        """The model itself (it holds nothing that changes; `memo` is not needed)."""
    def __reduce__(self) -> tuple[Any, tuple[Path, bool, str | None]]:
        """Pickling: the directory, `extrapolate` and the content it was read with."""
    @staticmethod
    def _restore(path: Path, extrapolate: bool, origin: str | None) -> Model:
        """The model `__reduce__` describes (for `pickle`; not part of the API)."""

@final
class Reconstruction:
    """A model's reconstruction errors on a dataset (``Model.reconstruction``).

    Attributes
    ----------
    rows : int
        Solved snapshots evaluated.
    rmse : float
        ``sqrt(mean (x̂ − x)²)`` over every entry of every snapshot (Table I), in strain units.
    relative : float
        ``‖X̂ − X‖_F / ‖X‖_F`` over the dataset.
    worst : tuple[int, float, float] or None
        The dataset row with the largest ``‖x̂ − x‖ / ‖x‖``, that ratio and ``‖x‖`` (None if every
        snapshot is zero).
    largest_norm : float
        The largest ``‖x‖``, for scale.
    outside : int
        Snapshots outside the training data: their code far outside the training encodings,
        or their norm over twice the largest training snapshot's.
    unseen_inputs : int or None
        Snapshots whose inputs lie outside what the model was trained on: an input outside its
        training range, or a combination far from the training inputs (as ``model=`` refuses
        them). None when the dataset does not sample the model's inputs (``inputs_note`` says why).
    inputs_note : str or None
        Why ``unseen_inputs`` is None.
    other_physics : str or None
        The first way the dataset's physics differs from the model's training scenario (then every
        snapshot is an extrapolation), or None.
    """

    @property
    def rows(self) -> int:
        """Solved snapshots evaluated."""
    @property
    def rmse(self) -> float:
        """``sqrt(mean (x̂ − x)²)`` over every entry of every snapshot (Table I)."""
    @property
    def relative(self) -> float:
        """``‖X̂ − X‖_F / ‖X‖_F`` over the dataset."""
    @property
    def worst(self) -> tuple[int, float, float] | None:
        """``(row, ‖x̂ − x‖ / ‖x‖, ‖x‖)`` of the worst snapshot, or None."""
    @property
    def largest_norm(self) -> float:
        """The largest ``‖x‖`` of the snapshots."""
    @property
    def outside(self) -> int:
        """Snapshots outside the training data: their code far outside the training encodings, or
        their norm over twice the largest training snapshot's.
        """
    @property
    def unseen_inputs(self) -> int | None:
        """Snapshots whose inputs lie outside what the model was trained on, or None."""
    @property
    def inputs_note(self) -> str | None:
        """Why ``unseen_inputs`` is None."""
    @property
    def other_physics(self) -> str | None:
        """The first way the dataset's physics differs from the model's, or None."""

@final
class Dataset:
    """A dataset directory read back (``gvsrom dataset`` or :func:`dataset`), its files checked
    against their recorded hashes. Arrays are as the ``.npy`` files hold them, one row per sample.

    Attributes
    ----------
    path : pathlib.Path
    kind : str
        ``"statics"`` or ``"dynamics"``.
    scenario : str
    parameters : list of str
        Names of the columns of ``inputs``.
    components : list of str
        The active strain components stored per point, in column order.
    inputs : numpy.ndarray, shape (N, len(parameters))
    strain : numpy.ndarray, shape (N, n_points * len(components))
        ``ξ − ξ*`` point-major (column ``j * len(components) + c``); NaN rows for failed samples.
    q : numpy.ndarray, shape (N, n_dof)
        HOM coordinates.
    tip_position : numpy.ndarray, shape (N, 3)
        [m]
    tip_rotation : numpy.ndarray, shape (N, 3, 3)
    status : numpy.ndarray of uint8, shape (N,)
        0 ok, 1 failed, 2 not computed.
    iterations : numpy.ndarray of int64, shape (N,)
        The statics solver's iterations per sample (0 in a dynamic dataset: no solve).
    residual : numpy.ndarray, shape (N,)
        ‖R‖∞ (generalized forces) at each equilibrium; NaN where nothing was solved (failed samples, and every row
        of a dynamic dataset: its snapshots are states of a motion, not equilibria).
    strain_x : numpy.ndarray, shape (n_points,)
        [m]
    t : numpy.ndarray or None
        Sample times [s] of a dynamic dataset.
    tendon_lengths : numpy.ndarray or None, shape (N, n_tendons)
        The tendons' lengths [m], what a position-controlled actuator reads (NaN rows for failed
        samples); ``None`` for a dataset written before they were recorded (compute them with
        ``Robot.tendon_lengths(q)``).
    complete : bool
        False for an interrupted dataset.
    meta : dict
        ``meta.json`` (manifest, scenario TOML, plan, seed, counts, failures, …).
    """

    @property
    def path(self) -> Path:
        """The dataset directory."""
    @property
    def kind(self) -> str:
        """``"statics"`` or ``"dynamics"``."""
    @property
    def scenario(self) -> str:
        """The scenario's name."""
    @property
    def parameters(self) -> list[str]:
        """Names of the columns of ``inputs``."""
    @property
    def components(self) -> list[str]:
        """The stored strain components, in column order within a point."""
    @property
    def n_dof(self) -> int:
        """Generalized coordinates of the HOM."""
    @property
    def n_points(self) -> int:
        """Computational points."""
    @property
    def complete(self) -> bool:
        """False for an interrupted dataset."""
    @property
    def seed(self) -> int:
        """The sampling plan's seed."""
    @property
    def inputs(self) -> _F:
        """Inputs, shape (N, len(parameters))."""
    @property
    def strain(self) -> _F:
        """Strain snapshots ``ξ − ξ*``, shape (N, n_points · len(components)), point-major."""
    @property
    def q(self) -> _F:
        """HOM coordinates, shape (N, n_dof)."""
    @property
    def tip_position(self) -> _F:
        """Tip positions [m], shape (N, 3)."""
    @property
    def tip_rotation(self) -> _F:
        """Tip rotations, shape (N, 3, 3)."""
    @property
    def status(self) -> NDArray[np.uint8]:
        """0 ok, 1 failed, 2 not computed (uint8), shape (N,)."""
    @property
    def iterations(self) -> NDArray[np.int64]:
        """Statics solver iterations (int64; the file holds them as uint32), shape (N,); 0 in a dynamic dataset."""
    @property
    def residual(self) -> _F:
        """‖R‖∞ at the equilibria, shape (N,); NaN where nothing was solved (failed samples, every row
        of a dynamic dataset).
        """
    @property
    def strain_x(self) -> _F:
        """Abscissae of the computational points [m], shape (n_points,)."""
    @property
    def t(self) -> _F | None:
        """Sample times [s] of a dynamic dataset, else ``None``."""
    @property
    def tendon_lengths(self) -> _F | None:
        """The tendons' lengths [m], shape (N, n_tendons); ``None`` for a dataset written before
        they were recorded.
        """
    @property
    def meta(self) -> dict[str, Any]:
        """``meta.json`` as a dict (a new one at each access: editing it changes nothing)."""
    def __len__(self) -> int:
        """Return len(self)."""
    def __copy__(self) -> Dataset:
        """The dataset itself (it holds nothing that changes)."""
    def __deepcopy__(self, memo: Any) -> Dataset:
        """The dataset itself (it holds nothing that changes; `memo` is not needed)."""
    def __reduce__(self) -> tuple[Any, tuple[Path, str]]:
        """Pickling: the directory and the content it was read with."""
    @staticmethod
    def _restore(path: Path, origin: str) -> Dataset:
        """The dataset `__reduce__` describes (for `pickle`; not part of the API)."""

def load_dataset(path: _Path) -> Dataset:
    """Reads a dataset directory (``gvsrom dataset`` or :func:`dataset`).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    Dataset

    Raises
    ------
    GvsromError
        If it is not a dataset, or a file is missing, truncated or edited (naming it).
    """
def dataset(
    scenario: Union[str, os.PathLike[str], Scenario],
    out: _Path,
    sweep: _Specs | None = None,
    grid: _Specs | None = None,
    random: _Specs | None = None,
    samples: int | None = None,
    seed: int | None = None,
    set: str | Sequence[str] | None = None,
    chunk_size: int = 128,
    threads: int | None = None,
    force: bool = False,
    resume: bool = False,
    duration: float | None = None,
    sample_rate: float | None = None,
    input: _Path | None = None,
    interpolate: bool = False,
    steps: Sequence[float] | None = None,
    babble: Sequence[float] | None = None,
    from_equilibrium: bool = False,
    rtol: float | None = None,
    atol: float | None = None,
) -> Dataset:
    """Generates a dataset as ``gvsrom dataset`` does (same files, bit-identical for the same plan
    and seed): the HOM solved over a sampling plan (static), or one simulation sampled (dynamic,
    with ``duration``). Ctrl-C stops it after the chunks under way, writes the finished ones
    (marked incomplete; ``resume=True`` continues) and raises ``KeyboardInterrupt``.

    Parameters
    ----------
    scenario : str, os.PathLike or Scenario
        A preset name, a scenario TOML file, or a :class:`Scenario` from a preset or a file (its
        overrides are applied before ``set``).
    out : str or os.PathLike
        The new dataset directory.
    sweep, grid, random : str, list of str or dict, optional
        ``"PATH=LO:HI"`` specs (or ``{path: (lo, hi)}``) as ``--sweep``, ``--grid``, ``--random``:
        an even 1-D sweep, a product grid, or uniform random values (seeded by ``seed``).
    samples : int, optional
        Number of samples (``--samples``).
    seed : int, optional
        Seed of ``random`` (and of a dynamic dataset's ``steps``/``babble``); default 0. Refused
        with a plan that draws nothing (``sweep``, ``grid``, ``input``).
    set : str or list of str, optional
        ``"PATH=VALUE"`` overrides (``--set``).
    chunk_size : int
        Samples per chunk (part of the plan).
    threads : int, optional
        Worker threads (default: one per core); the files do not depend on it.
    force : bool
        Replace ``out`` if it is an earlier gvsrom output.
    resume : bool
        Continue the incomplete dataset in ``out``.
    duration, sample_rate : float, optional
        A dynamic dataset: simulated time [s] and samples per second [Hz].
    input : str or os.PathLike, optional
        Dynamic: a CSV file ``t, u_1, …`` (``--input``), linear with ``interpolate``.
    steps : sequence of 3 floats, optional
        Dynamic: random steps ``(lo, hi, period)``.
    babble : sequence of 4 floats, optional
        Dynamic: actuator babbling ``(lo, hi, hold_min, hold_max)``.
    from_equilibrium : bool
        Dynamic: start at the static equilibrium.
    rtol, atol : float, optional
        Dynamic: integrator tolerances (default as ``Robot.simulate``; atol 1e-6).

    Returns
    -------
    Dataset
        The new dataset, read back.

    Raises
    ------
    GvsromError
        For a bad plan or option (the message of ``gvsrom dataset``).
    """
def reproduce(
    study: Union[str, Sequence[str]],
    out: _Path,
    quick: bool = False,
    jobs: int | None = None,
    noise: float = 0.02,
    test_sizes: bool = False,
) -> list[dict[str, Any]]:
    """Reproduces the paper's studies as ``gvsrom reproduce`` does: datasets, POD and autoencoder
    ROMs, tables beside the paper's, figures, one report directory per study and ``index.html``
    in ``out``. A run again with the same options reuses every finished step. Ctrl-C stops at the
    next step boundary, keeps the finished steps and raises ``KeyboardInterrupt``.

    Parameters
    ----------
    study : str or list of str
        ``"iv-a"``, ``"iv-b"``, ``"iv-c1"``, ``"iv-c2"``, ``"v"``, ``"noise"`` or ``"all"``.
    out : str or os.PathLike
        The run directory (created, or an earlier run's; the command line's default is
        ``results``).
    quick : bool
        Reduced sizes: every study in minutes, the paper's trends but not its numbers.
    jobs : int, optional
        Worker threads (default: one per core).
    noise : float
        The noise study's σ relative to each strain component's RMS.
    test_sizes : bool
        The smallest sizes that still run every step (implies ``quick``; for tests).

    Returns
    -------
    list of dict
        Per study done: ``study``, ``dir`` (its report directory), ``wall_time_s``, ``steps``,
        ``reused``.

    Raises
    ------
    GvsromError
        For an unknown study or a bad option (the message of ``gvsrom reproduce``).
    """
def compare(reference: _Path, run: _Path, allow_different: bool = False) -> dict[str, Any]:
    """Measures a trajectory against a reference one of the same scenario, input and sample times, as
    ``gvsrom compare`` does: e.g. a reduced model's run (``simulate(out=…)`` with a model
    attached) against the full model's. Both are run directories (``Robot.simulate(…, out=…)`` or
    ``gvsrom simulate --out``); nothing is written.

    Parameters
    ----------
    reference : str or os.PathLike
        The reference run's directory (e.g. the full model's).
    run : str or os.PathLike
        The run to measure (e.g. a reduced model's).
    allow_different : bool
        Compare them even if their scenario, physics, input or duration differ (or their
        ``meta.json`` cannot tell); the result's ``differ`` and ``unknown`` then say how. Without
        it such runs are refused, since one does not approximate the other.

    Returns
    -------
    dict
        What ``gvsrom compare --json`` writes: ``reference`` and ``run`` (each run's directory,
        scenario, sizes, samples, wall time), ``comparison`` (``samples``; the tip errors in % of
        the length: ``tip_mean``, ``tip_max``, ``tip_max_t``, ``tip_end``, ``tip_start``; the
        strain errors; the tendons' length errors in mm), ``speed_ratio`` (the run's simulated
        time per wall time over the reference's, ``None`` if it cannot be told), ``differ``,
        ``unknown``, ``warnings`` (a run written before gvsrom recorded content hashes, also
        raised as a ``UserWarning``) and ``provenance`` (both runs' hashes).

    Raises
    ------
    GvsromError
        For a directory that is not a trajectory (or was edited since it was written), runs that
        differ (unless ``allow_different``), or runs without common samples.
    """
def plot(
    output: _Path,
    out: _Path,
    formats: str | Sequence[str] | None = None,
    force: bool = False,
) -> dict[str, Any]:
    """Draws the figures of a gvsrom output into a new directory, as ``gvsrom plot`` does: a
    ``statics``, ``modes`` or ``linearize`` JSON file, or a trajectory, dataset or model
    directory. Each figure is written as SVG and/or PNG (fonts embedded), with ``meta.json``
    recording how they were made.

    Parameters
    ----------
    output : str or os.PathLike
        The gvsrom output to draw.
    out : str or os.PathLike
        New directory for the figures (an earlier gvsrom output there only with ``force``).
    formats : str or list of str, optional
        ``"svg"`` and/or ``"png"``; default (``None``) both.
    force : bool
        Replace ``out`` if it is an earlier gvsrom output (never anything else).

    Returns
    -------
    dict
        ``kind`` (what was drawn: ``"statics result"``, ``"trajectory"``, ``"dataset"``,
        ``"reduced model"``, ``"linearization"`` or ``"modes"``), ``out`` (the directory),
        ``figures`` (the files written), ``notes`` (figures left out and why), ``wall_time_s``.

    Raises
    ------
    GvsromError
        For an input that is not a gvsrom output with figures, an unknown format, or an ``out``
        that is not ours to replace.
    """
def load_model(path: _Path, extrapolate: bool = False) -> Model:
    """Loads a reduced model directory.

    Parameters
    ----------
    path : str or os.PathLike
        A model directory.
    extrapolate : bool
        Allow using it outside its training inputs (``--extrapolate``).

    Raises
    ------
    GvsromError
        If it is not a model directory, or its files were edited.
    """
def pod(
    dataset: Dataset | _Path | Sequence[Dataset | _Path],
    modes: int,
    out: _Path,
    force: bool = False,
    norm: str = "plain",
) -> Model:
    """POD of a dataset's strain snapshots (``gvsrom pod DATASET --modes K --out MODEL``).

    Parameters
    ----------
    dataset : Dataset or str or os.PathLike, or a sequence of them
        A dataset (``gvsrom dataset``, ``load_dataset``) or its directory, or several of one scenario
        (the same points, components, sampled inputs and physics) whose snapshots are combined in
        order.
    modes : int
        POD modes kept (reduced coordinates).
    out : str or os.PathLike
        The new model directory.
    force : bool
        Replace ``out`` if it is an earlier gvsrom output.
    norm : str
        ``"plain"`` (every strain value weighs 1: the paper's POD) or ``"energy"`` (each value weighted
        by the section stiffness, as ``train(loss="energy")``; ``gvsrom pod --norm``).

    Returns
    -------
    Model
        The new model.
    """
def train(
    dataset: Dataset | _Path | Sequence[Dataset | _Path],
    out: _Path,
    latent: int | None = None,
    hidden_layers: int | None = None,
    epochs: int = 2000,
    batch_size: int = 64,
    learning_rate: float = 0.001,
    lambda_: float = 0.0001,
    validation_fraction: float | None = None,
    patience: int = 50,
    lr_reductions: int = 4,
    lbfgs_iterations: int = 300,
    seed: int | None = None,
    loss: str | None = None,
    sample_weighting: str = "uniform",
    relative_floor: float | None = None,
    decoder: str | None = None,
    rate_weight: float = 0.0,
    lr_decay: float | None = None,
    kinetic_weight: float = 0.0,
    init: Model | _Path | None = None,
    force: bool = False,
) -> Model:
    """Trains a tanh autoencoder on a dataset's strain snapshots; its decoder becomes a nonlinear
    reduced model (``gvsrom train DATASET … --out MODEL``, with the same defaults). Ctrl-C stops
    training, saves the best weights so far and raises ``KeyboardInterrupt``.

    Parameters
    ----------
    dataset : Dataset or str or os.PathLike, or a sequence of them
        A dataset (``gvsrom dataset``, ``load_dataset``) or its directory, or several of one scenario
        (the same points, components, sampled inputs and physics) whose snapshots are combined in
        order.
    out : str or os.PathLike
        The new model directory.
    latent : int, optional
        Latent size r (reduced coordinates); default 1, or the ``init`` model's.
    hidden_layers : int, optional
        Hidden layers of the whole autoencoder (odd: 1, 3, 5, 7…, at most 63); default 7, or the ``init`` model's.
    epochs, batch_size, learning_rate, lambda_, patience, lr_reductions, lbfgs_iterations
        As the ``gvsrom train`` options of the same names (``lambda_`` is ``--lambda``; patience 0:
        never stop early).
    validation_fraction, seed : optional
        The fraction held out for validation (default 0.1) and the seed of the initialisation,
        split and shuffles (default 0); with ``init``, the model's, so that a continuation holds
        out the same rows (others are allowed, with a warning).
    loss : str, optional
        ``"energy"`` (default), ``"physical"`` or ``"standardized"``; with ``init``, the model's.
    sample_weighting : str
        ``"uniform"`` (eq. 15) or ``"relative"``: each snapshot's squared error over its own
        squared norm, so that small loads are fitted as closely as large ones.
    relative_floor : float, optional
        The relative weighting's floor, a fraction of the largest snapshot norm in (0, 1]
        (default 0.1); only with ``sample_weighting="relative"``.
    decoder : str, optional
        Default ``"plain"``, or the ``init`` model's: ``"plain"`` (the paper's, x̂ = D(z)) or ``"scaled"`` (x̂ = z₁ D(z): every code with z₁ = 0
        decodes to the straight rod, for snapshots that shrink to rest as their load vanishes).
    rate_weight : float
        Weight β ≥ 0 of the strain-rate term (``--rate-weight``): the autoencoder's tangent map must
        carry each trajectory sample's strain rate; 0 is eq. (15) alone. Needs trajectory data.
    lr_decay : float or None
        ``--lr-decay``: the Adam rate decays exponentially to this factor of it, in (0, 1], over
        ``epochs``; None keeps it constant between plateaus.
    kinetic_weight : float
        ``--kinetic-weight``: weight κ ≥ 0 of the kinetic-energy norm (errors weighed by each
        snapshot's mass matrix M(q)); needs ``rate_weight`` > 0. 0: none.
    init : Model or str or os.PathLike, optional
        ``--init``: start from this autoencoder model's weights and scaling (more epochs, or a
        fine-tuning on new snapshots of its scenario); its latent size, hidden layers, decoder and
        loss are kept (give none of them, or the model's).
    force : bool
        Replace ``out`` if it is an earlier gvsrom output.

    Returns
    -------
    Model
        The new model.
    """

@final
class Robot:
    """A built scenario: the engine's model of the rod with its loads, tendon tensions and solver
    options, and, if :meth:`with_model` attached one, a reduced model that replaces the scenario's
    strain basis in statics, dynamics and every model quantity.

    Made by :meth:`Scenario.build`.

    Units: SI throughout. The coordinates ``q`` are the strain basis's coefficients, in strain units
    (1/m for a torsion or bending coefficient, 1 for elongation or shear, with dimensionless basis
    functions; a reduced model's latent coordinates are in the units of its code). A generalized
    force is work-conjugate to ``q``: ``F · δq`` is a work [J], so each entry is in J per unit of
    its coordinate (N·m² for a bending coefficient, N·m for an elongation one). Then
    ``½ q̇ᵀ M q̇`` is a kinetic energy [J], ``½ δqᵀ K δq`` an elastic energy [J], ``q̇ᵀ D q̇`` a
    dissipated power [W], and ``B`` is in m per unit of q, so that ``B u`` [J per unit of q] is a
    generalized force for tensions ``u`` [N].
    """

    def __reduce__(self) -> tuple[Any, tuple[Scenario, Path | None, bool, str | None]]: ...
    @staticmethod
    def _restore(scenario: Scenario, model: Path | None, extrapolate: bool, origin: str | None) -> Robot:
        """The robot `__reduce__` describes (for `pickle`; not part of the API)."""

    @property
    def name(self) -> str:
        """The scenario's name."""
    @property
    def scenario(self) -> Scenario:
        """A copy of the scenario this robot was built from."""
    @property
    def model(self) -> Path | None:
        """The attached reduced model's directory, or ``None``."""
    @property
    def n_dof(self) -> int:
        """Generalized coordinates n of the model that runs (the reduced model's if attached)."""
    @property
    def n_actuators(self) -> int:
        """Number of tendons (actuators)."""
    @property
    def n_points(self) -> int:
        """Number of computational points."""
    @property
    def length(self) -> float:
        """Rod length L [m]."""
    @property
    def tensions(self) -> _F:
        """The scenario's tendon tensions u [N]; NaN for a tendon driven by its displacement (its
        tension is found by ``statics()``).
        """
    @property
    def displacements(self) -> _F:
        """The displacements [m] the scenario drives its tendons by (wound in from the rest length);
        NaN for a tendon driven by its tension.
        """
    @property
    def point_x(self) -> _F:
        """Abscissae X of the computational points [m], shape ``(n_points,)``."""
    @property
    def point_weights(self) -> _F:
        """Quadrature weights W of the computational points [m] (0 at the ends and extra points),
        shape ``(n_points,)``: integrals over the rod are ``Σ W_i f(X_i)``.
        """
    @property
    def section_inertia(self) -> _F:
        """Diagonal of the cross-section inertia ``Ms`` per unit length at each point
        ``[ρJ, ρI_y, ρI_z, ρA, ρA, ρA]``, shape ``(n_points, 6)``: kg·m for the first three, kg/m
        for the last three.
        """
    @property
    def section_stiffness(self) -> _F:
        """Diagonal of the cross-section stiffness ``Es`` at each point
        ``[GJ, EI_y, EI_z, EA, GA, GA]``, shape ``(n_points, 6)``: N·m² for the first three, N
        for the last three.
        """
    @property
    def body_points(self) -> NDArray[np.int64]:
        """The computational point of each rigid body (``[[bodies]]``), shape ``(n_bodies,)``, int64:
        ``point_x[body_points[k]]`` is body k's ``x``.
        """
    @property
    def body_inertia(self) -> _F:
        """The spatial inertia ``Mb = [I_c − m c̃c̃, m c̃; −m c̃, m I]`` of each rigid body at its
        section (angular first, body axes), shape ``(n_bodies, 6, 6)``: the mass matrix is
        ``Σ W_i J_iᵀ Ms_i J_i + Σ_b J_bᵀ Mb J_b`` with ``J_b`` the Jacobian at ``body_points[b]``.
        """
    @property
    def strain_reference(self) -> _F:
        """The reference strain ξ* at each point, shape ``(n_points, 6)`` in the order ``[torsion,
        bend-y, bend-z, elongation, shear-y, shear-z]`` (1/m, then dimensionless): the unloaded
        rod's strain, ``[0, 0, 0, 1, 0, 0]`` unless the scenario pre-strains a division
        (``divisions.N.reference_strain``). ``q = 0`` is this rod; strain deviations and a
        dataset's ``strain`` are ``ξ − ξ*``.
        """
    @property
    def tendon_rest_lengths(self) -> _F:
        """Each tendon's length [m] at rest (the reference strain; the straight rod's unless it is
        precurved), shape (n_actuators,).
        """
    def with_model(self, model: Model | _Path, extrapolate: bool | None = None) -> Robot:
        """This scenario with a reduced model in place of its strain basis (``--model DIR``).

        Parameters
        ----------
        model : Model or str or os.PathLike
            From :func:`load_model`, or a model directory (loaded as ``load_model(path)`` loads
            it).
        extrapolate : bool, optional
            Use the model where the scenario lies outside what it was trained on (``--extrapolate``);
            the reasons are then warned about. Default: the model's own setting
            (``load_model(…, extrapolate=…)``; ``False`` for a directory).

        Raises
        ------
        GvsromError
            If the model was not learned on this scenario's points, or the scenario lies outside
            its training (without ``extrapolate``); for a directory that is not a model, or whose
            files were edited.
        TypeError
            If ``model`` is neither a Model nor a path.
        """
    def statics(
        self,
        u: ArrayLike | None = None,
        model: Model | _Path | None = None,
        displacement: ArrayLike | None = None,
    ) -> Statics:
        """Static equilibrium under tendon tensions ``u``, as ``gvsrom statics`` solves it (same
        numbers as its ``--json``).

        Parameters
        ----------
        u : array_like of float, optional
            Tensions [N] (negative pulls): one per tendon, or one for all. Default: the scenario's
            drives (its tensions, or its ``displacement`` where a tendon has one).
        model : Model or str or os.PathLike, optional
            A reduced model to solve with (``--model``), or its directory, loaded as
            ``load_model(path)`` loads it; default: this robot's.
        displacement : array_like of float, optional
            Instead of ``u`` (``--displacement``): the length [m] each tendon's actuator has wound
            in from its rest length (negative pays out), one per tendon or one for all. The
            tensions are found (``Statics.u``); a tendon that would have to push goes slack
            (``Statics.slack``).

        Returns
        -------
        Statics
            ``q``, the tip pose, the centreline, the strains and the solver statistics.

        Raises
        ------
        GvsromError
            For tensions of the wrong count, not finite or implausible with the loads; for both
            ``u`` and ``displacement``, or a displacement not reached (with how far each tendon
            got).
        ConvergenceError
            If the solve does not converge (with its iterations and residual).
        TypeError
            If ``model`` is neither a Model nor a path.
        """
    def statics_batch(self, U: ArrayLike, warm_start: bool = True) -> StaticsBatch:
        """Static equilibria under many tensions, solved in parallel (all cores, the GIL released).

        As ``gvsrom dataset`` solves a plan of tensions: chunks of 128 consecutive rows in
        parallel, each along a chain of nearest neighbours, every solve starting from the nearest
        solution of its chunk (the scenario's load ramp from straight if that fails). Row ``k``
        equals ``statics(U[k])`` to the solver's tolerance, and the dataset's sample ``k`` of the
        same tensions exactly. With ``warm_start=False`` every row is solved from straight, as
        ``statics(U[k])`` solves it (the same numbers; 1.2–1.4× the time on IV-A's sweep). With a
        reduced model attached (``with_model``) every row is solved as ``statics(U[k])`` solves
        it, from the model's own initial guess, and checked against the model's training as it
        is (``warm_start`` does not apply).

        Parameters
        ----------
        U : array_like of float, shape (m, n_actuators)
            One row of tensions [N] per equilibrium. Every tendon is driven by its tension here,
            also one the scenario drives by its displacement (as ``statics(u)`` with ``u`` given).
        warm_start : bool
            Start each solve from a neighbouring row's solution (default).

        Returns
        -------
        StaticsBatch
            The solutions' arrays stacked along a first axis of length m.

        Raises
        ------
        GvsromError, ConvergenceError
            For the first row that fails, named ``U[k]``, or, with a reduced model attached, whose
            tensions lie outside its training (unless attached with ``extrapolate``: a
            ``UserWarning`` then names those rows).
        """
    def forward(self, q: ArrayLike) -> dict[str, _F]:
        """Forward kinematics: the poses of the cross-sections at the computational points.

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)

        Returns
        -------
        dict
            ``x`` (p,) abscissae [m], ``position`` (p, 3) [m], ``rotation`` (p, 3, 3) (section →
            world).
        """
    def jacobian(self, q: ArrayLike, point: int | None = None) -> _F:
        """Geometric (body) Jacobian ``J_i`` of point ``i``: the section's twist is
        ``η_i = J_i q̇`` (angular velocity first, then linear, both in the section frame): rows
        0–2 in rad/s and rows 3–5 in m/s per unit of ``q̇``.

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)
        point : int, optional
            Point index (negative counts from the tip); default: all points.

        Returns
        -------
        numpy.ndarray
            Shape (6, n_dof), or (n_points, 6, n_dof) for all points.
        """
    def position_jacobian(self, q: ArrayLike, x: float | ArrayLike) -> tuple[_F, _F]:
        """World position of the centreline at abscissa ``x`` and its Jacobian ``∂p/∂q`` (world
        axes): ``δp = J δq``, the output matrix of a position sensor or a task-space controller at
        ``x``. At a computational point ``J`` is ``R_i`` times rows 3–5 of ``jacobian(q, i)``;
        between points, the derivative of the centreline's cubic Hermite interpolant (the one
        ``statics`` samples). ``linearize(outputs=…)`` stacks the same rows into ``C``.

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)
        x : float or array_like of float
            Abscissa(e) [m] within [0, length].

        Returns
        -------
        tuple of numpy.ndarray
            ``(position, jacobian)``: shapes (3,) and (3, n_dof) for one ``x``, (k, 3) and
            (k, 3, n_dof) for k of them.
        """
    def point_velocities(self, q: ArrayLike, qd: ArrayLike) -> _F:
        """Section twists ``η_i`` at the points (angular then linear velocity, section frame) at
        ``(q, q̇)``, by the engine's velocity recursion.

        Returns
        -------
        numpy.ndarray
            Shape (n_points, 6): rad/s, then m/s.
        """
    def mass_matrix(self, q: ArrayLike) -> _F:
        """The mass matrix ``M(q)`` (symmetric positive definite), shape (n_dof, n_dof):
        ``½ q̇ᵀ M q̇`` is the kinetic energy [J] (units: see :class:`Robot`).
        """
    def statics_residual(self, q: ArrayLike, u: ArrayLike | None = None) -> _F:
        """The static residual ``R(q) = −K₁(q) + F(q) + B(q)u`` (paper eq. 9) under the scenario's
        loads: zero at an equilibrium. A generalized force [J per unit of q].

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)
        u : array_like of float, optional
            Tensions [N], one per tendon or one for all; default: the scenario's.
        """
    def statics_jacobian(self, q: ArrayLike, u: ArrayLike | None = None) -> _F:
        """The analytic Jacobian ``∂R/∂q`` of :meth:`statics_residual`, shape (n_dof, n_dof)
        [J per unit of q²: ``δqᵀ (∂R/∂q) δq`` is in J].
        """
    def snapshot(self, strain: ArrayLike) -> _F:
        """Snapshot rows of absolute strains: ``ξ − ξ*`` of the components the scenario's strain
        basis excites, point-major (``[point 0's components…, point 1's…, …]``) — the layout of a
        dataset's ``strain`` rows and of :meth:`Model.encode`'s input — from the strains ``ξ`` at
        the computational points as :attr:`Statics.strain` and ``simulate(…)["strain"]`` give
        them. So a result of this robot, or of another robot of the same scenario, can be encoded:
        ``model.encode(robot.snapshot(eq.strain))``.

        Parameters
        ----------
        strain : array_like of float, shape (n_points, 6) or (k, n_points, 6)
            ``[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`` at each point (1/m, then
            dimensionless; the unloaded rod's elongation is 1).

        Returns
        -------
        numpy.ndarray
            Shape (n_points · n_components,), or (k, n_points · n_components).
        """
    def elastic_force(self, q: ArrayLike) -> _F:
        """The elastic force ``K₁(q) = Σ W Ψ_qᵀ Es Ψ`` (gvs-spec §7.3): ``K q`` for the HOM's linear
        basis, the generalized elastic force of a reduced model. It enters the equations of motion
        as ``M q̈ + C q̇ + D₁ + K₁ = B u + F``.

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)

        Returns
        -------
        numpy.ndarray
            Shape (n_dof,) [J per unit of q; see :class:`Robot` for the units].
        """
    def stiffness_matrix(self, q: ArrayLike) -> _F:
        """The elastic stiffness ``K(q) = ∂K₁/∂q`` (the constant ``K`` of the HOM's linear basis; of
        a reduced model, its tangent), shape (n_dof, n_dof): ``½ δqᵀ K δq`` is an elastic energy
        [J].
        """
    def damping_force(self, q: ArrayLike, qd: ArrayLike) -> _F:
        """The damping force ``D₁ = D(q) q̇`` (Kelvin–Voigt, gvs-spec §7.4), shape (n_dof,)
        [J per unit of q].
        """
    def damping_matrix(self, q: ArrayLike) -> _F:
        """The damping matrix ``D(q) = Σ W Ψ_qᵀ Ds Ψ_q`` (constant for the HOM), shape
        (n_dof, n_dof): ``q̇ᵀ D q̇`` is the power the damping dissipates [W].
        """
    def coriolis_force(self, q: ArrayLike, qd: ArrayLike) -> _F:
        """The Coriolis and centrifugal force ``C(q, q̇) q̇ = Σ W Jᵀ (Ms J̇ q̇ + coad_η Ms η)``
        (gvs-spec §7.2), shape (n_dof,) [J per unit of q]. With a reduced model attached, whose
        strain is ``Φ c(q)``, ``J = J_HOM C_q`` and ``J̇ q̇`` holds the map's curvature: the force is
        ``C_qᵀ (C_HOM q̇_HOM + M_HOM Ċ_q q̇)`` at ``q̇_HOM = C_q q̇`` (``crates/rom/tests/reduced_identities.rs``).
        """
    def coriolis_matrix(self, q: ArrayLike, qd: ArrayLike) -> _F:
        """The Coriolis matrix ``C(q, q̇)`` with ``Ṁ − 2C`` skew-symmetric (gvs-spec §7.2), shape
        (n_dof, n_dof); ``C(q, q̇) @ q̇`` is :meth:`coriolis_force` [J per unit of q].
        """
    def external_force(self, q: ArrayLike) -> _F:
        """The external generalized force ``F(q) = Σ J_iᵀ w_i`` of gravity, the rigid bodies' weights
        and the scenario's point and distributed loads (gvs-spec §7.5), shape (n_dof,) [J per unit
        of q].
        """
    def actuation_matrix(self, q: ArrayLike) -> _F:
        """The actuation matrix ``B(q)``: column k is the generalized force of a unit tension in
        tendon k (routing and friction included), so the tendons' force is ``B(q) @ u``. Shape
        (n_dof, n_actuators), in m per unit of q (a work per unit of tension).
        """
    def tendon_lengths(self, q: ArrayLike) -> _F:
        """Each tendon's length along its routed thread at ``q``, ``ℓ_k = ∫ ‖t_u‖ dX`` over its span
        (``t_u = ν + k × d + d'``, gvs-spec §7.6): what an encoder on its actuator reads, up to a
        constant. Pulling a tendon shortens it: :attr:`tendon_rest_lengths` ``- ℓ`` is how far it
        has been pulled in.

        Parameters
        ----------
        q : array_like of float, shape (n_dof,)

        Returns
        -------
        numpy.ndarray
            Shape (n_actuators,) [m].
        """
    def tendon_length_jacobian(self, q: ArrayLike) -> _F:
        """The derivative of :meth:`tendon_lengths` in ``q``: row k is ``∇_q ℓ_k``. For a
        frictionless tendon it is the transpose of its column of :meth:`actuation_matrix` (the
        virtual work of its tension); with friction the actuation is attenuated along the tendon
        and differs. Shape (n_actuators, n_dof) [m per unit of q].
        """
    def accelerations(self, q: ArrayLike, qd: ArrayLike, u: ArrayLike | None = None) -> _F:
        """The accelerations ``q̈ = M⁻¹ (B u + F − K₁ − D₁ − C q̇)`` the integrators use (forward
        dynamics), shape (n_dof,), in units of q per s².

        Parameters
        ----------
        q, qd : array_like of float, shape (n_dof,)
        u : array_like of float, optional
            Tensions [N], one per tendon or one for all; default: the scenario's.
        """
    def energy(self, q: ArrayLike, qd: ArrayLike | None = None, u: ArrayLike | None = None) -> dict[str, float]:
        """Energies at ``(q, q̇)`` [J]: kinetic ``½ q̇ᵀ M q̇``, elastic ``½ Σ W Ψᵀ Es Ψ`` (whose
        gradient is :meth:`elastic_force`), gravitational ``−Σ W ρA g·r`` (and ``−m g·(r + R c)``
        of each rigid body), and their total.

        Parameters
        ----------
        u : array_like of float, shape (n_actuators,), optional
            Constant tendon tensions [N]: adds their potential ``tendons = −Σ u ℓ(q)`` (ℓ the
            lengths of :meth:`tendon_lengths`, whose gradient is the frictionless tendons' force
            ``B u``) to the total, which a conservative run under those tensions keeps (the
            ``energy_balance`` of :meth:`simulate`). Without it, no tendon term.

        Returns
        -------
        dict
            ``kinetic``, ``elastic``, ``gravitational``, ``total`` (floats), and ``tendons`` when
            ``u`` is given.
        """
    def modes(self, count: int = 10, u: ArrayLike | None = None) -> dict[str, Any]:
        """Natural frequencies and mode shapes linearized about the static equilibrium, as
        ``gvsrom modes`` computes them (the same numbers as its ``--json``): ``(K_T − ω² M) φ = 0``
        with the tangent stiffness ``K_T = −∂R/∂q`` (elastic, loads and tendons), undamped, shapes
        mass-normalized (``φᵀ M φ = 1``). With a reduced model attached, its modes.

        Parameters
        ----------
        count : int
            How many of the lowest modes to describe (≥ 1; more than n_dof gives all).
        u : array_like of float, optional
            Tensions [N] of the equilibrium (``--tension``), one per tendon or one for all; default:
            the scenario's.

        Returns
        -------
        dict
            ``frequency_hz`` (k,), ``period_s`` (k,) (``inf`` at 0 Hz), ``omega_squared`` (k,)
            [1/s²] (negative: unstable), ``shape`` (k, n_dof), ``strain`` (k, n_points, 6) the
            modal strain per unit modal coordinate, ``strain_energy_share`` (k, 6),
            ``dominant_strain`` (list of k names), ``tip_displacement`` and ``tip_rotation``
            (k, 3) world axes per unit modal coordinate (``tip_rotation`` a small-rotation vector
            [rad], not the (3, 3) matrix of a statics or a trajectory), ``centerline_x`` (c,) and ``centerline`` (c, 3) the equilibrium's
            centreline, ``centerline_shape`` (k, c, 3) its displacement per unit modal coordinate
            (world axes), ``all_frequencies_hz`` (n_dof,; one fewer per inextensible held
            tendon), ``q0`` (n_dof,), ``u`` (the tensions, those found for displacement drives),
            ``held_tendons`` (list of int: the taut tendons driven by displacement, held by their
            locked motors), ``held_by_threads`` (list of int: those of them held through an
            elastic thread, ``axial_stiffness``, a spring rather than a constraint),
            ``strain_x`` (n_points,), ``equilibrium_tip_position`` (3,),
            ``equilibrium_residual_norm``, ``model_extrapolated`` (list of str: how the reduced
            model was used outside its training, ``extrapolate=True``; empty otherwise).

        Raises
        ------
        GvsromError
            For a count < 1, bad tensions, or an equilibrium that fails (``ConvergenceError``).
        """
    def linearize(
        self,
        u: ArrayLike | None = None,
        q: ArrayLike | None = None,
        qd: ArrayLike | None = None,
        dt: float | None = None,
        outputs: float | ArrayLike | None = None,
        tip_orientation: bool = False,
        tendon_lengths: bool = False,
    ) -> dict[str, Any]:
        """The equations of motion linearized for control design, as ``gvsrom linearize`` computes
        them (the same numbers as its ``--json``): ``δẋ = A δx + B δu`` and ``δy = C δx`` with the
        state ``x = [q; q̇]``, the tendon tensions ``u`` [N] and the output ``y``, the tip position
        or the positions at ``outputs`` (world axes, m). ``A`` keeps every term of the dynamics
        (gvs-spec §9.3), the inertial ones that vanish at rest included. With a reduced model
        attached, its ``2r``-state linearization. About the equilibrium of a scenario that drives
        a tendon by its ``displacement`` through an elastic thread (``axial_stiffness``), that
        tendon's input is its motor's displacement [m] (the dict's ``displacement_channels``):
        ``A`` holds the thread's stiffness, ``B``'s column is per metre wound in.

        Parameters
        ----------
        u : array_like of float, optional
            Tensions [N] of the operating point, one per tendon or one for all; default: the
            scenario's.
        q : array_like of float, optional
            Linearize about this state instead of the static equilibrium under ``u`` (no solve);
            shape (n_dof,).
        qd : array_like of float, optional
            The state's velocities (with ``q`` only); default zero.
        dt : float, optional
            Also discretize with a zero-order hold of ``dt`` seconds (``--sample-time``):
            ``Ad`` = e^(A dt), ``Bd`` = ∫₀^dt e^(A s) ds B, ``spectral_radius`` max |e^(λ dt)|.
        outputs : float or array_like of float, optional
            Abscissae [m] along the rod whose world positions make ``y`` (``--output-at``), 3 rows
            of ``C`` each in this order, between the computational points by the centreline's
            interpolant; default: the tip.
        tip_orientation : bool
            Also output the tip's orientation (``--output-tip-orientation``): 3 rows of ``C`` after
            the positions, the tip section's small rotation in world axes [rad].
        tendon_lengths : bool
            Also output each tendon's length [m] along its thread (``--output-tendon-lengths``),
            one row of ``C`` each after the positions, for actuators under position control; the
            static gain's last rows are then the tendons' compliance ``∂ℓ/∂u``.

        Returns
        -------
        dict
            ``A`` (2n, 2n), ``B`` (2n, n_actuators), ``C`` (3k, 2n) for k outputs, ``D``
            (C's rows, n_actuators) zeros (no output depends on the tensions directly), ``outputs``
            (k,) their abscissae, ``output_positions`` (k, 3), ``output_tip_rotation`` (3, 3)
            the tip's rotation with ``tip_orientation`` (``None`` otherwise), ``output_tendon_lengths``
            (n_actuators,) with ``tendon_lengths`` (empty otherwise; ``C`` has 3k rows, 3 more
            with ``tip_orientation``, then n_actuators with ``tendon_lengths``), ``x0`` (2n,) the operating
            point, ``u`` (n_actuators,), ``xdot`` (2n,) ``f(x0, u)`` (≈ 0 about an equilibrium),
            ``tip_position`` (3,), ``poles`` (complex, the eigenvalues of A with ``Im ≥ 0``,
            conjugates once, slowest first), ``natural_frequency_hz`` and ``damping_ratio`` per pole,
            ``unstable_poles`` (count, conjugates counted), ``static_gain`` (C's rows, n_actuators) [m/N]
            ``−C A⁻¹ B`` about an equilibrium (``None`` about a given state), ``about``
            (``"equilibrium"`` or ``"state"``), ``damping_time_s``, ``relaxation_poles``,
            ``equilibrium_residual_norm`` (about an equilibrium), ``time_s`` (the linearization's
            wall time), ``model_extrapolated``; with ``dt``: ``Ad`` (2n, 2n), ``Bd``
            (2n, n_actuators), ``dt``, ``spectral_radius``.

        Raises
        ------
        GvsromError
            For bad tensions or states, ``qd`` without ``q``, a massless rod, or an equilibrium
            that fails (``ConvergenceError``).
        """
    def simulate(
        self,
        duration: float,
        sample_rate: float = 100.0,
        input: ArrayLike | Callable[[float], ArrayLike | float] | None = None,
        interpolate: bool = False,
        from_equilibrium: bool = False,
        q0: ArrayLike | None = None,
        qd0: ArrayLike | None = None,
        method: str = "auto",
        rtol: float | None = None,
        atol: float | None = None,
        fixed_step: float | None = None,
        load_schedule: _Path | None = None,
        steps: Sequence[float] | None = None,
        babble: Sequence[float] | None = None,
        seed: int = 1,
        max_order: int | None = None,
        error_norm: str | None = None,
        rho_inf: float | None = None,
        fd_jacobian: bool = False,
        controller: Callable[[float, _F, _F], ArrayLike | float] | None = None,
        control_rate: float | None = None,
        out: _Path | None = None,
        force: bool = False,
    ) -> dict[str, Any]:
        """Simulates the dynamics as ``gvsrom simulate`` does (stiff adaptive integrator), keeping the
        samples in memory. Ctrl-C interrupts it (``KeyboardInterrupt``).

        Parameters
        ----------
        duration : float
            Simulated time [s].
        sample_rate : float
            Output samples per second [Hz].
        input : array_like of float, shape (k, 1 + n_actuators), or callable, optional
            Rows ``t, u_1, …, u_na`` (times ascending from 0), held piecewise constant (each
            time once) or linear with ``interpolate`` (a time given twice is a step); or a callable ``u(t) -> array of n_actuators tensions`` (or one
            number for all), called by the integrator at every time it evaluates (in any order: a
            rejected step goes back in time); an exception it raises stops the run and propagates.
            Its values are checked as rows are: finite, and within the rod's elastic range (a
            tension far beyond it stops the run after the step it was returned in, naming it).
            Default: the scenario's tensions, constant. A tendon the scenario drives by its
            ``displacement`` (with the thread's ``axial_stiffness``) takes its displacement [m]
            in its column instead, and its tension follows from the thread's stretch.
        interpolate : bool
            Interpolate ``input`` rows linearly.
        from_equilibrium : bool
            Start at the static equilibrium under the scenario's tensions and displacements (else
            straight at rest).
        q0, qd0 : array_like of float, shape (n,), optional
            Start at this state instead (``qd0`` zeros if not given): the coordinates of the model
            that runs (the reduced model's with one attached; an autoencoder's inside its training
            encodings), e.g. ``tr["q"][-1], tr["qd"][-1]`` of an earlier run, to continue it under
            another input — a controller's loop, one control period per call with the tensions held.
        method : str
            ``"auto"``, ``"ndf"``, ``"sdirk"`` or ``"galpha"`` (``--method``).
        rtol, atol : float, optional
            Tolerances of the adaptive integrator (default rtol: chosen by ``method``; atol 1e-6);
            refused with ``fixed_step``, which controls no error.
        fixed_step : float, optional
            A fixed step [s]: the fixed-step BDF2 (``--fixed-step``) instead of an adaptive method;
            its cost is set by the number of steps, its accuracy by the step (not checked).
        load_schedule : str or os.PathLike, optional
            A CSV file of rows ``t, λ`` scaling every external load and gravity over time (linear
            between rows; ``--load-schedule``), e.g. a release: ``from_equilibrium=True`` with
            ``0,0``.
        steps : sequence of 3 floats, optional
            ``(lo, hi, period)``: new uniform random tensions in ``[lo, hi]`` [N] on every tendon
            every ``period`` seconds (``--steps``; the paper's IV-C2 test input).
        babble : sequence of 4 floats, optional
            ``(lo, hi, hold_min, hold_max)``: each tendon holds a uniform random tension in
            ``[lo, hi]`` for a uniform random time in ``[hold_min, hold_max]`` (``--babble``).
        seed : int
            Seed of ``steps`` and ``babble`` (same seed, same signal as the command line's; 1 by
            default, as ``gvsrom simulate --seed``).
        max_order : int, optional
            Highest order of the NDF, 1–5 (``--max-order``; default 5, or 2 for a lightly damped
            rod).
        error_norm : str, optional
            The adaptive methods' error test (``--error-norm``): ``"componentwise"`` (ode15s) or
            ``"mass"`` (positions and velocities in the norm of the mass matrix); default chosen
            by the method and the rod's damping.
        rho_inf : float, optional
            Generalized-α's spectral radius at infinite frequency in [0, 1] (``--rho-inf``; default
            0.8; only with ``method="galpha"``).
        fd_jacobian : bool
            Finite differences of the right-hand side for the integrator's Jacobian instead of the
            structured analytic one (``--fd-jacobian``; the NDF and the fixed step).
        controller : callable, optional
            A sampled-data controller ``controller(t, q, qd) -> tensions`` (a displacement [m] for a
            tendon the scenario drives by its displacement): called at ``t = 0`` and
            every ``1 / control_rate`` seconds with the state there (``q``, ``qd``: the coordinates
            of the model that runs, new arrays), its tensions held until the next call (a
            zero-order hold, as a digital controller drives a robot). The closed loop is one
            integration: the integrator restarts at each call as at a step of held rows, and keeps
            what a restart need not renew (the fixed step's Jacobian). Its values are checked as ``input``'s
            are; an exception it raises stops the run and propagates, with the samples computed
            before as its ``trajectory`` attribute. The tip from ``q``:
            ``robot.forward(q)["position"][-1]``. When the last sample falls
            on a control instant the controller is called there too (its value is the sample's
            ``u`` but drives no step). Instead of ``input``, ``steps`` and ``babble``.
        control_rate : float, optional
            The controller's calls per second [Hz]: ``sample_rate`` (default) or a whole fraction
            of it, so that every call is at an output sample.
        out : str or os.PathLike, optional
            Also write the trajectory to this new directory, the files ``gvsrom simulate --out``
            writes (``t.npy``, ``q.npy``, …, ``meta.json`` with how the run was made), for
            :func:`plot`, ``gvsrom compare`` or a later session; a run that ended early is written
            too, marked incomplete. An existing path is refused unless it is an earlier gvsrom
            output and ``force`` is given.
        force : bool
            Replace an earlier gvsrom output at ``out``.

        Returns
        -------
        dict
            ``t`` (k,), ``q``/``qd`` (k, n), ``u`` (k, n_a: the tensions, a displacement-driven
            tendon's found from its thread's stretch), ``tip_position`` (k, 3),
            ``tip_rotation`` (k, 3, 3), ``strain`` (k, p, 6), ``strain_x`` (p,),
            ``strain_reference`` (p, 6: the stress-free strain ξ*), ``centerline``
            (k, c, 3), ``centerline_x`` (c,), ``tendon_paths`` (k, n_a, c, 3: each tendon's thread
            at ``centerline_x`` clamped to its span), ``tendon_lengths`` (k, n_a: each tendon's
            length [m] along its thread; at rest :attr:`Robot.tendon_rest_lengths`), with a tendon
            driven by its displacement ``displacement`` (k, n_a: the displacements [m] its motor
            was commanded, NaN for a tendon driven by its tension),
            ``body_positions`` (k, n_b, 2, 3: each rigid body's section and centre of mass), ``steps``,
            ``failed_steps``, ``wall_time_s``, and
            ``model_extrapolated`` (list of str): how the reduced model was used outside what it
            was trained on (``extrapolate=True``; the scenario, a signal's tensions, the values a
            callable ``input`` returned), empty otherwise; for a conservative run (no damping,
            tendon friction, loads or schedule; constant tensions) ``energy_balance``, a dict of
            ``initial``, ``last``, ``largest_gain``, ``largest_loss``, ``kinetic_max`` [J] of
            ``T + U_e + U_g − Σ u ℓ`` over the samples (a thread held at a constant displacement
            counts its ``½ (ℓ − ℓ*)² / c`` in place of ``−u ℓ``), with a ``UserWarning`` when it rose by more
            than 1 % of the largest kinetic energy (the integration added energy); with ``out``,
            ``out``: the directory written. Started ``from_equilibrium`` at an equilibrium that
            diverges (no stable one found), the run warns (``UserWarning``) and the dict holds its
            ``start_divergence``, the eigenvalue ω² < 0 [1/s²].

        Raises
        ------
        IntegrationError
            When the integrator failed (a reduced model that left its training region, a step
            that could not converge), or a callable ``input`` or ``controller`` returned a value
            refused after the run began: its ``trajectory`` attribute is the dict above for the
            samples computed before (``energy_balance`` left out). An exception the callable
            raised propagates as it is, with that dict as its ``trajectory`` attribute, and so
            does ``KeyboardInterrupt`` (Ctrl-C).
        GvsromError
            For bad options or input.
        """
    def stepper(
        self,
        dt: float,
        horizon: float | None = None,
        q0: ArrayLike | None = None,
        qd0: ArrayLike | None = None,
        from_equilibrium: bool = False,
        method: str = "auto",
        rtol: float | None = None,
        atol: float | None = None,
        fixed_step: float | None = None,
    ) -> Stepper:
        """A run advanced one control period per :meth:`Stepper.step`, for a loop you drive (a
        reinforcement-learning environment's ``step(action)``, a controller elsewhere): each call
        holds its tensions for ``dt`` seconds and returns the state at the end. One integration
        on a thread of its own, as ``simulate(controller=…)`` runs it (the same numbers), so the
        integrator keeps what a restart need not renew between periods.

        Parameters
        ----------
        dt : float
            The control period [s].
        horizon : float, optional
            The longest the run may go [s]: the steps stop at its last whole period, and a step
            past it is an error. Default: an hour or 100 000 periods, whichever is shorter (the
            run's sample times are laid out up front: at most 10 000 000 periods).
        q0, qd0 : array_like of float, shape (n,), optional
            Start at this state (the coordinates of the model that runs); else straight at rest, or
            with ``from_equilibrium`` at the scenario's equilibrium.
        from_equilibrium : bool
            Start at the static equilibrium under the scenario's tensions.
        method, rtol, atol, fixed_step
            The integrator, as for :meth:`simulate` (``fixed_step=dt`` or a fraction of it for a
            fixed cost per period).

        Returns
        -------
        Stepper
            At ``t = 0`` (``stepper.q``, ``stepper.qd``); a context manager that ends the run.
        """

@final
class Stepper:
    """A run of a robot advanced one control period per :meth:`step`, its tensions held over each
    (a zero-order hold), from one integration: made by :meth:`Robot.stepper`.
    """

    def step(self, u: ArrayLike | float) -> tuple[_F, _F]:
        """Holds the tensions ``u`` [N] (one per tendon, or one number for all) for one period and
        returns the state ``(q, qd)`` at its end; :attr:`t` advances by :attr:`dt`. A tendon the
        scenario drives by its ``displacement`` takes its displacement [m] here instead (its
        tension follows from the thread's stretch).

        Raises
        ------
        GvsromError
            For tensions of the wrong count, not finite, beyond the rod's elastic range or outside
            a reduced model's training (without ``extrapolate``; for a displacement, the tension
            its thread pulls with as the period starts), or a displacement not below its tendon's
            rest length: checked before the run sees them, so the run stays where it was and the
            next ``step`` goes on from there. Also once the run has ended (closed, past its
            horizon, or its integration failed).
        """
    @property
    def t(self) -> float:
        """The time of the state [s]."""
    @property
    def dt(self) -> float:
        """The control period [s]."""
    @property
    def q(self) -> _F:
        """The coordinates ``q`` of the model that runs at :attr:`t`."""
    @property
    def qd(self) -> _F:
        """The velocities ``qd`` at :attr:`t`."""
    @property
    def running(self) -> bool:
        """Whether the run still takes steps (not closed, not ended)."""
    def close(self) -> None:
        """Ends the run (also when the stepper is garbage-collected, or leaves a ``with`` block)."""
    def __enter__(self) -> Stepper: ...
    def __exit__(self, ty: Any, value: Any, tb: Any) -> bool: ...
