"""dipper from Python: scenarios, runs and the simulation's state as NumPy arrays (docs/python.md).

    import dipper
    s = dipper.load("examples/scenarios/loading_quick.yaml", set={"shovel.rake_angle_deg": 58.0})
    result = dipper.run(s, "out/rake58", threads=2)          # what `dipper run` does, files and all
    sim = dipper.Simulation(s, threads=2)                     # or step the model yourself
    sim.advance(0.5)
    x = sim.spheres().position_m                              # (n, 3) view of the spheres' centres

A step taken here is the `dipper` command's step: the same scenario gives the same bits.
"""

import csv
import json
import os
import types

import numpy as np

from . import _dipper
from ._dipper import InputError, Scenario, SimulationError

__all__ = ["InputError", "SimulationError", "Scenario", "Simulation", "load", "from_dict", "read_keys", "run",
           "resume", "read_probes", "read_summary", "read_passes"]


def _yaml_value(value):
    """A Python value as YAML text (JSON is YAML): numbers keep every digit, NumPy scalars and arrays included."""
    def plain(o):
        if hasattr(o, "tolist"):
            return o.tolist()
        raise TypeError(f"{o!r} ({type(o).__name__}) is not a scenario value")
    return json.dumps(value, default=plain)


def _values(set):
    return [(str(key), _yaml_value(value)) for key, value in (set or {}).items()]


def load(path, set=None):
    """Reads and checks a scenario file. `set` maps keys, named as in sweep files (`shovel.rake_angle_deg`,
    `meshes[0].motion.velocity_m_per_s`), to the values that replace the file's. Raises InputError with the
    message `dipper check` prints."""
    return _dipper.load_scenario(os.fspath(path), _values(set))


def from_dict(keys, base_dir=".", source="<dict>", set=None):
    """A scenario from a dict with the keys of a scenario file; relative file names are taken from `base_dir`."""
    try:
        import yaml
        text = yaml.safe_dump(json.loads(_yaml_value(keys)), sort_keys=False)
    except ImportError:
        text = _yaml_value(keys)
    return _dipper.parse_scenario(text, source, os.path.abspath(os.fspath(base_dir)), _values(set))


def read_keys(path):
    """A scenario file's keys as a dict (to change and pass to from_dict with the file's folder as base_dir)."""
    import yaml
    with open(path) as f:
        return yaml.safe_load(f)


class RunResult(types.SimpleNamespace):
    """status ("completed", "interrupted" or "diverged"), message, time_s, steps, exit_code (the command's)."""


def run(scenario, out_dir, threads=None, stop_after=None, progress=None, every=100, echo=False):
    """Runs a scenario from t = 0 into out_dir, as `dipper run` does: the same files, checkpoints and bits.

    progress(time_s, steps) is called every `every` steps; returning False stops the run with a checkpoint (resume
    it later), as Ctrl-C does. stop_after: stop with a checkpoint at that simulated time. echo: the command's
    progress lines on stderr."""
    r = _dipper.run(scenario, os.fspath(out_dir), threads or -1, stop_after or 0.0, progress, every, echo)
    return RunResult(**r)


def resume(out_dir, threads=None, stop_after=None, progress=None, every=100, echo=False, checkpoint=None):
    """Continues the run in out_dir from its checkpoint (or the checkpoint file given), as `dipper resume` does."""
    r = _dipper.resume(os.fspath(out_dir), threads or -1, stop_after or 0.0, progress, every, echo,
                       os.fspath(checkpoint) if checkpoint else "")
    return RunResult(**r)


class Simulation:
    """A scenario's model, stepped from Python the way `dipper run` steps it, without its output files.

    The arrays of spheres() and wear() are read-only views of dipper's own memory: they are valid until the
    next step (a step may reorder or grow them); take .copy() to keep them."""

    def __init__(self, scenario, threads=None, _model=None):
        self._model = _model if _model is not None else _dipper.Simulation(scenario, threads or 0)

    @classmethod
    def from_checkpoint(cls, out_dir, threads=None, checkpoint=None):
        """The model of a run's checkpoint (out_dir/checkpoint.bin, or the file given) as it was saved."""
        model = _dipper.Simulation.from_checkpoint(os.fspath(out_dir), threads or 0, os.fspath(checkpoint) if checkpoint else "")
        return cls(None, _model=model)

    # ---- stepping
    def step(self, n=1):
        """n steps: n coupling steps when the scenario has rocks, a shovel, wear or a pile; n DEM steps otherwise."""
        self._model.step(n)

    def run_until(self, t_s):
        """Steps until the simulated time reaches t_s (s), as a run stopped at t_s would."""
        self._model.run_until(t_s)

    def advance(self, seconds):
        """Steps on by this much simulated time (s)."""
        self._model.run_until(self._model.time_s + seconds)

    @property
    def scenario(self):
        return self._model.scenario

    @property
    def time_s(self):
        return self._model.time_s

    @property
    def step_count(self):
        """DEM steps taken since t = 0."""
        return self._model.step_count

    @property
    def step_s(self):
        """The DEM time step, s."""
        return self._model.step_s

    def state_hash(self):
        """The spheres' state hash, as summary.json's state_hash: equal hashes, equal states."""
        return self._model.state_hash()

    # ---- state
    @property
    def material_names(self):
        return self._model.material_names

    def spheres(self):
        """id, position_m, velocity_m_per_s, angular_velocity_rad_per_s (n, 3), radius_m, mass_kg, material (index
        into material_names): views, in dipper's own order (sort by id to compare two times)."""
        return types.SimpleNamespace(**self._model.spheres())

    def rocks(self):
        """position_m (centres of mass), rotation (n, 3, 3), velocity_m_per_s, angular_velocity_rad_per_s, mass_kg,
        equivalent_diameter_m: copies, in the order the rocks were made."""
        return types.SimpleNamespace(**self._model.rocks())

    def machine(self):
        """The rope shovel now (joint values, drive and interface forces, what the dipper holds) or None."""
        m = self._model.machine()
        return None if m is None else types.SimpleNamespace(**m)

    def passes(self, frame=False):
        """The passes done so far, one dict each (a pandas DataFrame with frame=True)."""
        p = self._model.passes()
        return _frame(p) if frame else p

    def wear(self):
        """Each wear surface: part, law, tonnage_t, vertices_m and triangles (views, the part's own frame; place them
        with rotation and origin_m), triangle_volume_m3 (view), triangle_depth_m, node_depth_m, volume_m3,
        volume_by_region_m3, and for the dipper and door plate_names with triangle_plate (view)."""
        return [types.SimpleNamespace(**w) for w in self._model.wear()]

    def wall_forces(self):
        """The force of the particles on each listed wall in the last step, N, by wall name."""
        return {k: np.array(v) for k, v in self._model.wall_forces().items()}

    def kinetic_energy_J(self):
        return self._model.kinetic_energy_J()

    def total_mass_kg(self):
        return self._model.total_mass_kg()


def _frame(rows):
    import pandas
    return pandas.DataFrame(rows)


def read_probes(out_dir, frame=False):
    """A run's probes.csv: a dict of NumPy arrays by column (a pandas DataFrame with frame=True)."""
    path = os.path.join(os.fspath(out_dir), "probes.csv")
    if frame:
        import pandas
        return pandas.read_csv(path)
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, values = rows[0], np.array(rows[1:], dtype=float).reshape(len(rows) - 1, len(rows[0]))
    return {name: values[:, k] for k, name in enumerate(header)}


def read_summary(out_dir):
    """A run's summary.json as a dict."""
    with open(os.path.join(os.fspath(out_dir), "summary.json"), encoding="utf-8") as f:
        return json.load(f)


def read_passes(out_dir, frame=False):
    """A run's passes from its summary.json (a pandas DataFrame with frame=True)."""
    p = read_summary(out_dir).get("passes", [])
    return _frame(p) if frame else p
