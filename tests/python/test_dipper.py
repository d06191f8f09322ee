"""The Python module against the C++ library and the dipper command: the same state, the same messages, the
same bits. Run by CTest (python_module) with PYTHONPATH at the build tree's python/ folder and DIPPER_COMMAND
naming the command."""

import os
import subprocess

import numpy as np
import pytest

import dipper

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIOS = os.path.join(HERE, "..", "data", "scenarios")
POURS = os.path.join(SCENARIOS, "kill_resume.yaml")      # a ton of spheres, a pour and a turning paddle
MACHINE = os.path.join(SCENARIOS, "machine_small.yaml")  # spheres, 70 rocks, the digging shovel and wear
COMMAND = os.environ.get("DIPPER_COMMAND", "dipper")


def command(*args):
    return subprocess.run([COMMAND, *args], capture_output=True, text=True)


def fnv1a(data, h=14695981039346656037):
    """FNV-1a 64 over bytes, as core/state_io.cpp computes it."""
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def command_hash(scenario, stop_after, threads, out):
    r = command("run", scenario, "--stop-after", str(stop_after), "--threads", str(threads), "--out", str(out), "--quiet")
    assert r.returncode == 130, r.stderr  # stopped as asked
    return dipper.read_summary(out)["state_hash"]


def test_sphere_arrays_are_the_state_the_hash_is_taken_of():
    sim = dipper.Simulation(dipper.load(POURS), threads=2)
    filled = len(sim.spheres().id)
    sim.run_until(0.06)  # the pour has started: spheres were added and the arrays reordered by the neighbour search
    s = sim.spheres()
    n = len(s.id)
    assert n > filled
    assert not np.array_equal(s.id, np.sort(s.id))
    assert s.position_m.shape == (n, 3) and s.velocity_m_per_s.shape == (n, 3) and s.radius_m.shape == (n,)
    order = np.argsort(s.id, kind="stable")
    data = bytearray()
    for i in order:
        data += s.id[i].tobytes() + s.position_m[i].tobytes() + s.velocity_m_per_s[i].tobytes()
        data += s.angular_velocity_rad_per_s[i].tobytes()
    assert f"{fnv1a(data):016x}" == sim.state_hash()
    # views of the library's memory, not copies, and not writable
    assert not s.position_m.flags.owndata and not s.position_m.flags.writeable
    with pytest.raises(ValueError):
        s.position_m[0, 0] = 1.0
    # the masses are the material's density times the volume (ore 2,700 kg/m^3 in this file is checked by the C++
    # tests; here only that the arrays line up): every sphere's mass over its volume is one of the densities
    density = s.mass_kg / (4.0 / 3.0 * np.pi * s.radius_m ** 3)
    assert np.allclose(density, density[0], rtol=1e-12)
    assert abs(s.mass_kg.sum() - sim.total_mass_kg()) <= 1e-9 * sim.total_mass_kg()


def test_a_python_step_is_the_commands_step_bit_for_bit(tmp_path):
    # spheres with a pour and a moving mesh, on two threads
    sim = dipper.Simulation(dipper.load(POURS), threads=2)
    sim.run_until(0.1)
    assert sim.state_hash() == command_hash(POURS, 0.1, 2, tmp_path / "pours")
    # spheres, rocks in Bullet, the rope shovel and wear on the dipper
    sim = dipper.Simulation(dipper.load(MACHINE), threads=1)
    sim.run_until(0.05)
    assert sim.state_hash() == command_hash(MACHINE, 0.05, 1, tmp_path / "machine")
    # and a run started from Python writes what the command writes
    r = dipper.run(dipper.load(POURS), tmp_path / "python_run", threads=2, stop_after=0.1)
    assert r.status == "interrupted" and r.exit_code == 130
    assert dipper.read_summary(tmp_path / "python_run")["state_hash"] == dipper.read_summary(tmp_path / "pours")["state_hash"]


def test_a_bad_key_raises_the_message_the_command_prints(tmp_path):
    bad = tmp_path / "bad.yaml"
    with open(POURS) as f:
        bad.write_text(f.read().replace("duration_s: 0.6", "duration_s: -0.6"))
    r = command("check", str(bad))
    assert r.returncode != 0
    printed = r.stderr.strip().splitlines()[0]
    with pytest.raises(dipper.InputError) as e:
        dipper.load(bad)
    assert printed == f"dipper: {e.value}"
    assert "time.duration_s" in str(e.value)
    # a key set from Python is checked as a sweep's is
    with pytest.raises(dipper.InputError, match="time.duration_sx"):
        dipper.load(POURS, set={"time.duration_sx": 1.0})
    with pytest.raises(dipper.InputError, match="duration_s"):
        dipper.load(POURS, set={"time.duration_s": "long"})
    # and an InputError is a ValueError to code that knows nothing of dipper
    assert issubclass(dipper.InputError, ValueError)


def test_values_set_from_python_reach_the_model():
    s = dipper.load(MACHINE, set={"shovel.rake_angle_deg": 58.0, "seed": 5})
    assert s.seed == 5
    sim = dipper.Simulation(s, threads=1)
    sim.step()
    assert sim.machine().rake_angle_deg == pytest.approx(58.0, abs=0.05)  # the posed model's measured angle
    default = dipper.Simulation(dipper.load(MACHINE), threads=1)
    default.step()
    assert default.machine().rake_angle_deg == pytest.approx(61.8, abs=0.05)


def test_a_dict_gives_the_files_model():
    keys = dipper.read_keys(POURS)
    a = dipper.Simulation(dipper.from_dict(keys, base_dir=SCENARIOS), threads=2)
    b = dipper.Simulation(dipper.load(POURS), threads=2)
    a.step(200)
    b.step(200)
    assert a.state_hash() == b.state_hash()
    keys["time"]["duration_s"] = "soon"
    with pytest.raises(dipper.InputError, match="time.duration_s"):
        dipper.from_dict(keys, base_dir=SCENARIOS)


def test_progress_stops_a_run_and_resume_finishes_it_bit_for_bit(tmp_path):
    seen = []

    def stop_at_300(t, steps):
        seen.append((t, steps))
        return steps < 300

    r = dipper.run(dipper.load(POURS), tmp_path / "legs", threads=2, progress=stop_at_300, every=100)
    assert r.status == "interrupted" and r.steps == 300
    assert [s for _, s in seen] == [100, 200, 300]
    r = dipper.resume(tmp_path / "legs", stop_after=0.1)
    assert r.status == "interrupted"
    whole = command_hash(POURS, 0.1, 2, tmp_path / "whole")
    assert dipper.read_summary(tmp_path / "legs")["state_hash"] == whole
    # the checkpoint read back as a model is the state the run stopped in
    assert dipper.Simulation.from_checkpoint(tmp_path / "legs").state_hash() == whole

    # an exception in the callback stops the run with a checkpoint and reaches the caller
    def fail(t, steps):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        dipper.run(dipper.load(POURS), tmp_path / "fails", threads=2, progress=fail, every=50)
    assert dipper.read_summary(tmp_path / "fails")["steps"] == 50


def test_rocks_machine_wear_and_probes(tmp_path):
    sim = dipper.Simulation(dipper.load(MACHINE), threads=1)
    sim.run_until(0.05)
    rocks = sim.rocks()
    assert rocks.position_m.shape[0] == 70 and rocks.rotation.shape == (70, 3, 3)
    # rotations are rotations
    assert np.allclose(np.einsum("nij,nkj->nik", rocks.rotation, rocks.rotation), np.eye(3), atol=1e-9)
    assert np.all(rocks.mass_kg > 0) and np.all(np.isfinite(rocks.velocity_m_per_s))
    m = sim.machine()
    assert m.dig_force_N >= 0 and len(m.tooth_tip_m) == 3 and m.bucket_mass_kg >= 0
    [w] = sim.wear()
    assert w.part == "dipper"
    nv, nt = len(w.vertices_m), len(w.triangles)
    assert w.vertices_m.shape == (nv, 3) and w.triangles.shape == (nt, 3) and w.triangles.max() < nv
    assert len(w.triangle_volume_m3) == len(w.triangle_depth_m) == len(w.triangle_plate) == nt and len(w.node_depth_m) == nv
    assert w.volume_m3 > 0 and w.volume_m3 == pytest.approx(w.triangle_volume_m3.sum(), rel=1e-12)
    assert sum(w.volume_by_region_m3.values()) == pytest.approx(w.volume_m3, rel=1e-12)
    assert w.plate_names[:2] == ["bottom", "lip"] and w.triangle_plate.max() < len(w.plate_names)
    forces = sim.wall_forces()
    assert set(forces) >= {"ground", "dipper", "door"}
    assert sim.passes() == []

    dipper.run(dipper.load(MACHINE), tmp_path / "run", threads=1, stop_after=0.05)
    probes = dipper.read_probes(tmp_path / "run")
    assert probes["time_s"][-1] == pytest.approx(0.05, abs=1e-3) and len(probes["dig_force_N"]) == len(probes["time_s"])
    frame = dipper.read_probes(tmp_path / "run", frame=True)  # pandas (scripts/install-deps.sh installs it)
    assert list(frame.columns) == list(probes) and np.array_equal(frame["time_s"].to_numpy(), probes["time_s"])
